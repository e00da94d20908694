"""Matrices of our renderer: the camera as Helios computes it, and the sun's view for shadows."""

from __future__ import annotations

import math

import numpy as np

from davis_ag.scene.camera import Camera
from davis_ag.scene.view_grid import Viewpoint


def look_at_matrix(eye: np.ndarray, target: np.ndarray) -> np.ndarray:
    """World to camera (right, up, backward) with z up in the world, as gluLookAt."""
    forward = target - eye
    forward = forward / np.linalg.norm(forward)
    right = np.cross(forward, (0.0, 0.0, 1.0))
    right /= np.linalg.norm(right)
    up = np.cross(right, forward)
    m = np.eye(4)
    m[0, :3], m[1, :3], m[2, :3] = right, up, -forward
    m[:3, 3] = -m[:3, :3] @ eye
    return m


def camera_matrices(camera: Camera, view: Viewpoint) -> tuple[np.ndarray, np.ndarray]:
    """World to camera and camera to clip matrices of a view, float32, computed as Helios computes
    them (glm's lookAt and infinitePerspective in single precision, in glm's order of operations),
    so that both renderers put every vertex at the same place, to the last bit, and an edge falls
    on the same side of every pixel centre.

    Returns:
        (view, projection), each (4, 4) float32 acting on column vectors.
    """
    f32 = np.float32
    eye = np.asarray(view.position, dtype=f32)
    target = np.asarray(view.look_at(1.0), dtype=f32)

    def normalise(v: np.ndarray) -> np.ndarray:
        return (v * (f32(1.0) / np.sqrt(f32(np.dot(v, v))))).astype(f32)

    def cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
        return np.array([a[1] * b[2] - b[1] * a[2], a[2] * b[0] - b[2] * a[0], a[0] * b[1] - b[0] * a[1]], dtype=f32)

    def dot(a: np.ndarray, b: np.ndarray) -> np.float32:
        return f32(f32(a[0] * b[0] + a[1] * b[1]) + a[2] * b[2])

    forward = normalise((target - eye).astype(f32))
    side = normalise(cross(forward, np.array([0, 0, 1], dtype=f32)))
    up = cross(side, forward)
    view_matrix = np.eye(4, dtype=f32)
    view_matrix[0, :3], view_matrix[1, :3], view_matrix[2, :3] = side, up, -forward
    view_matrix[:3, 3] = (-dot(side, eye), -dot(up, eye), dot(forward, eye))
    offset = (target - eye).astype(f32)
    distance = np.sqrt(dot(offset, offset))
    near = max(f32(0.1), f32(f32(0.05) * distance))
    half = f32(np.tan(f32(f32(np.radians(f32(camera.vfov))) / f32(2.0))) * near)
    aspect = f32(f32(camera.width) / f32(camera.height))
    left, right = f32(-half * aspect), f32(half * aspect)
    projection = np.zeros((4, 4), dtype=f32)
    projection[0, 0] = f32(f32(2.0) * near) / f32(right - left)
    projection[1, 1] = f32(f32(2.0) * near) / f32(half - (-half))
    projection[2, 2], projection[3, 2] = -1.0, -1.0
    projection[2, 3] = f32(-2.0) * near
    return view_matrix, projection


def matmul32(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """4x4 product in single precision, summed term by term in glm's order."""
    a, b = a.astype(np.float32), b.astype(np.float32)
    out = np.zeros((4, 4), dtype=np.float32)
    for column in range(4):
        total = a[:, 0] * b[0, column]
        for k in range(1, 4):
            total = (total + a[:, k] * b[k, column]).astype(np.float32)
        out[:, column] = total
    return out


def light_matrix(
    direction: tuple[float, float, float],
    lo: np.ndarray,
    hi: np.ndarray,
    margin: float | None = None,
    exact: np.ndarray | None = None,
) -> np.ndarray:
    """World to the shadow map's [0, 1]^3 (x, y across the map, z depth from the sun), fitted to a
    box (or to the points ``exact``), enlarged by ``margin`` of its extent on every side."""
    towards = np.asarray(direction, dtype=np.float64)
    towards /= np.linalg.norm(towards)
    helper = np.array([0.0, 1.0, 0.0]) if abs(towards[1]) < 0.9 else np.array([1.0, 0.0, 0.0])
    u = np.cross(helper, towards)
    u /= np.linalg.norm(u)
    v = np.cross(towards, u)
    corners = np.array([[x, y, z] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])
    if exact is not None:
        corners = exact
    axes = np.stack([u, v, -towards])  # depth grows away from the sun
    projected = corners @ axes.T
    low, high = projected.min(axis=0), projected.max(axis=0)
    if margin is None:
        pad = 0.01 * (high - low).max() + 1e-3
    else:
        pad = margin * (high - low)
    low, high = low - pad, high + pad
    m = np.eye(4)
    m[:3, :3] = axes / (high - low)[:, None]
    m[:3, 3] = -low / (high - low)
    return m


def helios_shadow_box(camera: Camera, eye: np.ndarray, target: np.ndarray, sun) -> np.ndarray:
    """Where Helios computes shadows for a view: world to [0, 1]^3 of the box, seen from the sun,
    around its camera's view volume cut at max(5 x eye height, 2 x look distance) (1 % margin).
    Helios lights everything outside it."""
    distance = float(np.linalg.norm(target - eye))
    near, far = max(0.1, 0.05 * distance), max(5.0 * eye[2], 2.0 * distance)
    f = 1.0 / math.tan(math.radians(camera.vfov) / 2)
    aspect = camera.width / camera.height
    projection = np.zeros((4, 4))
    projection[0, 0], projection[1, 1] = f / aspect, f
    projection[2, 2], projection[2, 3] = -(far + near) / (far - near), -2 * far * near / (far - near)
    projection[3, 2] = -1.0
    inverse = np.linalg.inv(projection @ look_at_matrix(eye, target))
    corners = np.array([[x, y, z, 1.0] for z in (-1, 1) for y in (-1, 1) for x in (-1, 1)]) @ inverse.T
    corners = corners[:, :3] / corners[:, 3:]
    return light_matrix(sun, corners.min(axis=0), corners.max(axis=0), margin=0.01, exact=corners)


def gl_matrix(matrix: np.ndarray) -> bytes:
    """A matrix as GLSL reads it (column-major float32)."""
    return np.asarray(matrix, dtype=np.float32).T.tobytes()


def box_corners(points: np.ndarray) -> np.ndarray:
    """The eight corners of the axis-aligned box around ``points`` (N, 3), homogeneous (8, 4)."""
    points = np.asarray(points, dtype=np.float64).reshape(-1, 3)
    lo, hi = points.min(axis=0), points.max(axis=0)
    return np.array([[x, y, z, 1.0] for x in (lo[0], hi[0]) for y in (lo[1], hi[1]) for z in (lo[2], hi[2])])


def screen_rect(camera: Camera, view: Viewpoint, corners: np.ndarray) -> tuple[int, int, int, int] | None:
    """The framebuffer rectangle (x, y, width, height; y up, as OpenGL's) that holds every pixel
    centre a shape inside the box of ``corners`` can cover; the whole frame where a corner lies
    behind the eye (the near plane clips there); None where the box misses the frame.

    Args:
        camera: Image size and field of view.
        view: The pose.
        corners: Homogeneous corners (8, 4), e.g. from :func:`box_corners`.
    """
    width, height = camera.width, camera.height
    view_matrix, projection = camera_matrices(camera, view)
    clip = corners @ (projection.astype(np.float64) @ view_matrix.astype(np.float64)).T
    if (clip[:, 3] <= 1e-6).any():
        return (0, 0, width, height)
    x = (clip[:, 0] / clip[:, 3] * 0.5 + 0.5) * width
    y = (clip[:, 1] / clip[:, 3] * 0.5 + 0.5) * height
    # One pixel of margin on each side absorbs the float32 rounding of the GPU's transform.
    x0, x1 = max(int(np.floor(x.min())) - 1, 0), min(int(np.ceil(x.max())) + 1, width)
    y0, y1 = max(int(np.floor(y.min())) - 1, 0), min(int(np.ceil(y.max())) + 1, height)
    if x0 >= x1 or y0 >= y1:
        return None
    return (x0, y0, x1 - x0, y1 - y0)

"""Pictures of a USD stage and a nerfstudio set (``davis-ag export usd``, ``export nerfstudio``),
each drawn from the exported files alone, as another tool would read them (docs/worlds.md shows both).

- The stage, read back with pxr: every mesh prim in its ``displayColor`` and every
  ``UsdGeom.Camera`` of the grid as a small frustum, placed by its own world transform.
- The nerfstudio set: its cameras from ``transform_matrix`` in nerfstudio's OpenGL convention
  (looking down -z, +y up) around the scene's fruit, and one frame's image with every fruit centre
  of scene.json projected through that frame's matrix and intrinsics: the projection lands on the
  fruit where the convention is read right.

``python -m davis_ag.figures.export_pictures usd SCENE.usd OUT.png`` and
``python -m davis_ag.figures.export_pictures nerfstudio TRANSFORMS.json SCENE.json OUT.png``.
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.figures.canvas import new_figure, save_figure

#: A drawn camera's frustum depth and half-width, in metres.
FRUSTUM = (0.25, 0.12)


def read_stage(path: Path) -> dict[str, Any]:
    """The meshes and cameras of a stage, with pxr: ``corners`` (n, 3, 3, world metres) and ``rgb``
    (n, 3, sRGB 0-1) per triangle, and ``cameras``: each camera's 4x4 local-to-world matrix (USD's
    row-vector layout transposed to column vectors)."""
    from pxr import Usd, UsdGeom

    stage = Usd.Stage.Open(str(path))
    corners, colours, cameras = [], [], []
    for prim in stage.Traverse():
        if prim.IsA(UsdGeom.Camera):
            matrix = UsdGeom.Xformable(prim).ComputeLocalToWorldTransform(Usd.TimeCode.Default())
            cameras.append(np.array(matrix).T)
        elif prim.IsA(UsdGeom.Mesh):
            mesh = UsdGeom.Mesh(prim)
            to_world = np.array(mesh.ComputeLocalToWorldTransform(Usd.TimeCode.Default())).T
            points = np.asarray(mesh.GetPointsAttr().Get(), dtype=float) @ to_world[:3, :3].T + to_world[:3, 3]
            counts = np.asarray(mesh.GetFaceVertexCountsAttr().Get())
            indices = np.asarray(mesh.GetFaceVertexIndicesAttr().Get()).reshape(-1, 3)
            assert (counts == 3).all(), f"{prim.GetPath()}: not triangles"
            # displayColor is linear; the picture is sRGB (IEC 61966-2-1's transfer function).
            linear = np.clip(np.asarray(mesh.GetDisplayColorPrimvar().Get(), dtype=float), 0.0, 1.0)
            colour = np.where(linear <= 0.0031308, 12.92 * linear, 1.055 * linear ** (1 / 2.4) - 0.055)
            corners.append(points[indices])
            colours.append(colour if len(colour) == len(indices) else np.repeat(colour[:1], len(indices), axis=0))
    return {"corners": np.concatenate(corners), "rgb": np.concatenate(colours), "cameras": cameras}


def frustum_lines(camera_to_world: np.ndarray) -> list[np.ndarray]:
    """A camera looking down its -z (+y up, USD's and OpenGL's), as the lines of a small pyramid."""
    depth, half = FRUSTUM
    apex = camera_to_world[:3, 3]
    corners = [
        camera_to_world[:3, :3] @ np.array([sx * half, sy * half * 0.6, -depth]) + apex
        for sx, sy in ((-1, -1), (1, -1), (1, 1), (-1, 1))
    ]
    rim = [np.array([corners[i], corners[(i + 1) % 4]]) for i in range(4)]
    return [np.array([apex, corner]) for corner in corners] + rim


def _3d_axes(figure: Any, rect: tuple[float, float, float, float], lo: np.ndarray, hi: np.ndarray) -> Any:
    """A 3-D axes over the box ``lo``-``hi``, equal in metres, without its frame."""
    from mpl_toolkits.mplot3d import Axes3D

    ax = figure.add_axes(rect, projection="3d")
    assert isinstance(ax, Axes3D)  # matplotlib's stubs know only 2-D axes
    ax.set_xlim(lo[0], hi[0])
    ax.set_ylim(lo[1], hi[1])
    ax.set_zlim(lo[2], hi[2])
    ax.set_box_aspect(tuple(hi - lo), zoom=1.3)
    ax.view_init(elev=22, azim=-60)
    ax.set_axis_off()
    return ax


def draw_usd_stage(path: Path, out_path: Path, margin: float = 0.3) -> Path:
    """The stage's meshes in their display colours and its cameras as frusta.

    Args:
        path: A ``scene.usd`` written by ``davis-ag export usd``.
        out_path: The PNG.
        margin: Ground kept around the plants and cameras, m (the soil runs out to 30 m).
    """
    from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection

    stage = read_stage(path)
    corners, cameras = stage["corners"], stage["cameras"]
    raised = corners[:, :, 2].max(axis=1) > 1e-3  # the plants; the ground lies at z = 0
    where = np.concatenate([corners[raised].reshape(-1, 3), [c[:3, 3] for c in cameras]])
    lo, hi = where.min(axis=0) - margin, where.max(axis=0) + margin
    lo[2] = 0.0
    centroid = corners.mean(axis=1)
    keep = raised | np.all((centroid[:, :2] >= lo[:2]) & (centroid[:, :2] <= hi[:2]), axis=1)
    figure = new_figure(7.0, 5.6)
    ax = _3d_axes(figure, (0.0, 0.0, 1.0, 0.92), lo, hi)
    ax.add_collection3d(Poly3DCollection(corners[keep], facecolors=np.clip(stage["rgb"][keep], 0, 1), linewidths=0))
    lines = [line for camera in cameras for line in frustum_lines(camera)]
    ax.add_collection3d(Line3DCollection(lines, colors="#d62728", linewidths=0.6))
    ax.set_title(f"{path.name} read back with pxr: {int(keep.sum()):,} triangles, {len(cameras)} cameras", fontsize=10)
    return save_figure(figure, out_path)


def project(frame: dict[str, Any], meta: dict[str, Any], point: np.ndarray) -> tuple[float, float, float]:
    """A world point to (column, row, distance ahead) through nerfstudio's convention: camera-to-world
    with +x right, +y up, +z back, pixel centres at +0.5 (``cx`` is half the width)."""
    c2w = np.asarray(frame["transform_matrix"], dtype=float)
    camera = c2w[:3, :3].T @ (point - c2w[:3, 3])
    ahead = -camera[2]
    return meta["cx"] + meta["fl_x"] * camera[0] / ahead, meta["cy"] - meta["fl_y"] * camera[1] / ahead, ahead


def draw_nerfstudio(transforms_path: Path, scene_json: Path, out_path: Path, frame_index: int | None = None) -> Path:
    """The set's cameras around the scene's fruit, and one frame with every fruit centre projected.

    Args:
        transforms_path: A ``transforms.json`` written by ``davis-ag export nerfstudio``.
        scene_json: The scene's ``scene.json`` (its fruit centres, to project).
        out_path: The PNG.
        frame_index: The frame to draw (default: the one that sees the most fruit).
    """
    from matplotlib.image import imread
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    meta = json.loads(transforms_path.read_text())
    scene = json.loads(scene_json.read_text())
    centres = {int(f["id"]): np.asarray(f["center"], dtype=float) for f in scene["fruits"]}
    visible = scene.get("visible_fraction", {})
    frames = meta["frames"]
    if frame_index is None:
        frame_index = max(range(len(frames)), key=lambda i: len(visible.get(Path(frames[i]["file_path"]).name, {})))
    frame = frames[frame_index]
    poses = [np.asarray(f["transform_matrix"], dtype=float) for f in frames]
    points = np.array([*centres.values(), *(p[:3, 3] for p in poses)])
    lo, hi = points.min(axis=0) - 0.3, points.max(axis=0) + 0.3
    lo[2] = 0.0
    figure = new_figure(12.0, 4.6)
    ax = _3d_axes(figure, (0.0, 0.02, 0.42, 0.9), lo, hi)
    lines = [line for pose in poses for line in frustum_lines(pose)]
    colours = ["#d62728" if i == frame_index else "#1f77b4" for i in range(len(poses)) for _ in range(8)]
    ax.add_collection3d(Line3DCollection(lines, colors=colours, linewidths=0.6))
    fruit = np.array(list(centres.values()))
    ax.scatter(fruit[:, 0], fruit[:, 1], fruit[:, 2], s=4, c="#8c2d04")
    ax.set_title(f"{len(frames)} cameras from transform_matrix, fruit centres (scene.json)", fontsize=10)
    image = imread(transforms_path.parent / frame["file_path"])
    right = figure.add_axes((0.45, 0.06, 0.54, 0.84))
    right.imshow(image)
    seen = visible.get(Path(frame["file_path"]).name, {})
    for fruit_id, centre in centres.items():
        u, v, ahead = project(frame, meta, centre)
        if ahead <= 0 or not (0 <= u < meta["w"] and 0 <= v < meta["h"]):
            continue
        colour = "#ffff00" if str(fruit_id) in seen else "#ffffff"
        right.plot(u - 0.5, v - 0.5, marker="+", color=colour, markersize=7, markeredgewidth=1.2)
    right.set_axis_off()
    right.set_title(
        f"{frame['file_path'].rsplit('/', 1)[-1]} (red camera): each fruit centre projected "
        "(yellow: seen in the view, white: hidden)",
        fontsize=10,
    )
    return save_figure(figure, out_path)


def main(argv: list[str] | None = None) -> int:
    """``python -m davis_ag.figures.export_pictures usd|nerfstudio ...``."""
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    kinds = parser.add_subparsers(dest="kind", required=True)
    usd = kinds.add_parser("usd", help="a scene.usd's meshes and cameras")
    usd.add_argument("stage", type=Path)
    usd.add_argument("out", type=Path)
    usd.add_argument("--margin", type=float, default=0.3, help="ground kept around the plants and cameras, m")
    ns = kinds.add_parser("nerfstudio", help="a transforms.json's cameras and one frame's projected fruit")
    ns.add_argument("transforms", type=Path)
    ns.add_argument("scene_json", type=Path)
    ns.add_argument("out", type=Path)
    ns.add_argument("--frame", type=int, default=None, help="the frame to draw (default: the one seeing most fruit)")
    args = parser.parse_args(argv)
    if args.kind == "usd":
        print(draw_usd_stage(args.stage, args.out, args.margin))
    else:
        print(draw_nerfstudio(args.transforms, args.scene_json, args.out, args.frame))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

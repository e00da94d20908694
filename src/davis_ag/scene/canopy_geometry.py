"""Geometry helpers of the Canopy Generator plants, in numpy: Helios's conventions, our code.

Helios's angles (``helios::SphericalCoord``): elevation is measured up from the horizontal plane,
azimuth clockwise from +y, so ``sphere2cart(r, e, a) = r (cos e sin a, cos e cos a, sin e)``.
``rotatePrimitive(angle, axis)`` is a right-handed rotation about a world axis through the origin
(measured with pyhelios: +90 degrees about z takes +x to +y). ``rotatePoint(p, theta, phi)``
tilts a point by ``theta`` about y, then turns it by ``phi`` about z.

Leaves are built as triangle arrays ``(n, 3, 3)`` with texture coordinates ``(n, 3, 2)``, so a
whole plant's leaves reach the Helios Context in one call.
"""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np


def sphere2cart(radius: float, elevation: float, azimuth: float) -> np.ndarray:
    """Helios's ``sphere2cart``: a vector from its length, elevation and azimuth (radians)."""
    return radius * np.array(
        [math.cos(elevation) * math.sin(azimuth), math.cos(elevation) * math.cos(azimuth), math.sin(elevation)]
    )


def cart2sphere(vector: np.ndarray) -> tuple[float, float, float]:
    """Helios's ``cart2sphere``: (radius, elevation, azimuth in [0, 2 pi)) of a vector."""
    x, y, z = (float(v) for v in vector)
    radius = math.sqrt(x * x + y * y + z * z)
    elevation = math.asin(max(-1.0, min(1.0, z / radius))) if radius > 0 else 0.0
    return radius, elevation, math.atan2(x, y) % (2 * math.pi)


def rotation(angle: float, axis: str) -> np.ndarray:
    """Right-handed 3x3 rotation about the world ``x``, ``y`` or ``z`` axis."""
    c, s = math.cos(angle), math.sin(angle)
    if axis == "x":
        return np.array([[1, 0, 0], [0, c, -s], [0, s, c]])
    if axis == "y":
        return np.array([[c, 0, s], [0, 1, 0], [-s, 0, c]])
    return np.array([[c, -s, 0], [s, c, 0], [0, 0, 1]])


def rotate(points: np.ndarray, angle: float, axis: str) -> np.ndarray:
    """Points (..., 3) rotated about a world axis through the origin."""
    return points @ rotation(angle, axis).T


def rotate_point(point: np.ndarray, theta: float, phi: float) -> np.ndarray:
    """Helios's ``rotatePoint``: tilt by ``theta`` about y, then turn by ``phi`` about z."""
    return rotation(phi, "z") @ rotation(theta, "y") @ np.asarray(point, dtype=float)


def rotate_about_line(point: np.ndarray, base: np.ndarray, direction: np.ndarray, angle: float) -> np.ndarray:
    """Rotate a point by ``angle`` about the line through ``base`` along ``direction`` (Rodrigues)."""
    k = np.asarray(direction, dtype=float)
    k = k / np.linalg.norm(k)
    v = np.asarray(point, dtype=float) - base
    c, s = math.cos(angle), math.sin(angle)
    return base + v * c + np.cross(k, v) * s + k * np.dot(k, v) * (1 - c)


def interpolate_tube(nodes: np.ndarray, fraction: float) -> np.ndarray:
    """The point a ``fraction`` of the way along a polyline, by arc length (Helios's ``interpolateTube``)."""
    nodes = np.asarray(nodes, dtype=float)
    lengths = np.linalg.norm(np.diff(nodes, axis=0), axis=1)
    total = lengths.sum()
    if total <= 0:
        return nodes[0].copy()
    cumulative = np.concatenate([[0.0], np.cumsum(lengths)]) / total
    i = int(np.clip(np.searchsorted(cumulative, fraction, side="right") - 1, 0, len(lengths) - 1))
    step = (fraction - cumulative[i]) / max(cumulative[i + 1] - cumulative[i], 1e-12)
    return nodes[i] + step * (nodes[i + 1] - nodes[i])


def bent_shoot(base: np.ndarray, direction: np.ndarray, length: float, bend: float, subdivisions: int) -> np.ndarray:
    """Nodes of a shoot that leaves ``base`` along ``direction`` and bends down by ``bend`` radians.

    The Canopy Generator's strawberry stem and tomato shoot: ``round(2 * length * subdivisions)``
    nodes; each segment keeps the shoot's azimuth and is ``bend / (nodes - 1)`` lower in elevation
    than the one before.

    Returns:
        (nodes, 3) positions, the first at ``base``.
    """
    count = max(2, round(2 * length * subdivisions))
    _, theta, azimuth = cart2sphere(direction)
    nodes = [np.asarray(base, dtype=float)]
    for _ in range(1, count):
        nodes.append(nodes[-1] + length / (count - 1) * sphere2cart(1.0, theta, azimuth))
        theta -= bend / (count - 1)
    return np.array(nodes)


def final_elevation(direction: np.ndarray, bend: float) -> float:
    """Elevation a :func:`bent_shoot` would turn to after its last node (the leaves' tilt)."""
    return cart2sphere(direction)[1] - bend


@dataclass
class LeafMesh:
    """Textured triangles of one leaf prototype or leaf.

    Attributes:
        triangles: (n, 3, 3) vertex positions.
        uvs: (n, 3, 2) texture coordinates.
    """

    triangles: np.ndarray
    uvs: np.ndarray

    def transformed(self, scale: np.ndarray, steps: list[tuple[float, str]], offset: np.ndarray) -> LeafMesh:
        """A copy scaled per axis, rotated by each (angle, axis) in turn, then moved by ``offset``."""
        points = self.triangles * np.asarray(scale, dtype=float)
        for angle, axis in steps:
            points = rotate(points, angle, axis)
        return LeafMesh(points + np.asarray(offset, dtype=float), self.uvs)

    def diameter(self) -> float:
        """Largest distance between two of its vertices (m): its size, whatever its orientation."""
        return diameter(self.triangles.reshape(-1, 3))

    def point_at(self, uv: tuple[float, float]) -> np.ndarray:
        """Where a texture coordinate lies on the leaf: a texel (its stalk, its tip) in space.

        Args:
            uv: Texture coordinate inside the leaf's texture.

        Returns:
            (3,) position, interpolated inside the first triangle whose texture coordinates hold it.
        """
        target = np.asarray(uv, dtype=float)
        for corners, uvs in zip(self.triangles, self.uvs):
            edges = np.array([uvs[1] - uvs[0], uvs[2] - uvs[0]]).T
            if abs(np.linalg.det(edges)) < 1e-12:
                continue
            b1, b2 = np.linalg.solve(edges, target - uvs[0])
            if min(b1, b2, 1.0 - b1 - b2) >= -1e-9:
                return corners[0] + b1 * (corners[1] - corners[0]) + b2 * (corners[2] - corners[0])
        raise ValueError(f"texture coordinate {tuple(uv)} lies on none of the leaf's triangles")


def diameter(points: np.ndarray) -> float:
    """Largest distance between two of the points (m)."""
    points = np.unique(np.round(points, 7), axis=0)
    return float(np.sqrt(((points[:, None, :] - points[None, :, :]) ** 2).sum(-1)).max())


def cupped_leaflet(columns: int = 4, rows: int = 4, rise: float = 0.6, knee: float = 0.4) -> LeafMesh:
    """The Canopy Generator's strawberry leaflet: unit length along +x from its base, unit width.

    The blade is cupped: a point at (x, y) rises to ``rise * m / (knee + m)`` with
    ``m = sqrt(x^2 + 2 y^2)``. Texture u runs along the midrib from the base (the pyhelios3d
    strawberry leaf texture has its base at u = 0), v across.
    """
    half_rows = math.ceil(rows * 0.5)
    dx, dy = 1.0 / columns, 0.5 / half_rows

    def vertex(x: float, y: float) -> list[float]:
        m = math.sqrt(x * x + 2 * y * y)
        return [x, y, rise * m / (knee + m)]

    triangles, uvs = [], []
    for i in range(columns):
        for j in range(half_rows):
            x, y = i * dx, j * dy
            corners = [vertex(x, y), vertex(x + dx, y), vertex(x + dx, y + dy), vertex(x, y + dy)]
            uv = [[x, 0.5 + y], [x + dx, 0.5 + y], [x + dx, 0.5 + y + dy], [x, 0.5 + y + dy]]
            for a, b, c in ((0, 1, 2), (0, 2, 3)):
                triangles.append([corners[a], corners[b], corners[c]])
                uvs.append([uv[a], uv[b], uv[c]])
            mirrored = [[p[0], -p[1], p[2]] for p in corners]
            uv_m = [[u, 1.0 - v] for u, v in uv]
            for a, b, c in ((0, 2, 1), (0, 3, 2)):  # reversed winding keeps the normal up
                triangles.append([mirrored[a], mirrored[b], mirrored[c]])
                uvs.append([uv_m[a], uv_m[b], uv_m[c]])
    return LeafMesh(np.array(triangles, dtype=float), np.array(uvs, dtype=float))


def flat_tile(length: float, width: float, columns: int = 1, rows: int = 1, flip: bool = False) -> LeafMesh:
    """A flat textured rectangle centred on the origin in the xy plane (Helios's ``addTile``).

    Args:
        length, width: Extent along x and y, m.
        columns, rows: Patches along x and y (each drawn as two triangles).
        flip: Turn it half a turn about z (the Canopy Generator's tomato leaves, azimuth pi).
    """
    xs = np.linspace(-0.5, 0.5, columns + 1)
    ys = np.linspace(-0.5, 0.5, rows + 1)
    triangles, uvs = [], []
    for i in range(columns):
        for j in range(rows):
            corners = [[xs[i], ys[j]], [xs[i + 1], ys[j]], [xs[i + 1], ys[j + 1]], [xs[i], ys[j + 1]]]
            for a, b, c in ((0, 1, 2), (0, 2, 3)):
                triangles.append([[corners[k][0] * length, corners[k][1] * width, 0.0] for k in (a, b, c)])
                uvs.append([[corners[k][0] + 0.5, corners[k][1] + 0.5] for k in (a, b, c)])
    mesh = LeafMesh(np.array(triangles, dtype=float), np.array(uvs, dtype=float))
    return LeafMesh(rotate(mesh.triangles, math.pi, "z"), mesh.uvs) if flip else mesh


@dataclass
class Tube:
    """A tube through ``nodes`` with a radius per node: a stem, shoot, trunk, cane or strawberry.

    Attributes:
        nodes: (n, 3) centre line, m.
        radii: (n,) radius at each node, m.
        organ: Organ class (:mod:`davis_ag.scene.organs`).
        subdivisions: Facets around the tube.
        colour: RGB colour in [0, 1], when not textured.
        texture: Texture file, when textured.
    """

    nodes: np.ndarray
    radii: np.ndarray
    organ: int
    subdivisions: int
    colour: tuple[float, float, float] | None = None
    texture: str | None = None


@dataclass
class Sphere:
    """A sphere: a tomato or one grape berry."""

    centre: np.ndarray
    radius: float
    colour: tuple[float, float, float]
    subdivisions: int


@dataclass
class PlantParts:
    """Everything one Canopy Generator plant is made of, before it enters the Context.

    Attributes:
        tubes: Stems, shoots, trunk and canes.
        leaves: One mesh per leaf (strawberry: per leaflet).
        leaf_texture: The leaves' texture file.
        fruits: One entry per labelled fruit: its tubes or spheres (a grape cluster: its berries).
    """

    tubes: list[Tube] = field(default_factory=list)
    leaves: list[LeafMesh] = field(default_factory=list)
    leaf_texture: str = ""
    fruits: list[Sequence[Tube | Sphere]] = field(default_factory=list)

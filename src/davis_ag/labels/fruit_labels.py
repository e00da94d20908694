"""Fruit labels of one view from the renderer's primitive-id image: masks, boxes, visibility.

Box convention (the published one): ``[xmin, ymin, width, height, fruit_id, 0]`` where xmin, ymin
is the fruit's leftmost column and topmost row and width, height its inclusive pixel extent.
The segmentation image holds, per pixel, the id of the fruit seen there if that fruit has a box
in this view, else no fruit: 255 in the uint8 masks of a scene of at most 255 fruit, 65535 in the
uint16 masks of a larger one (the rule of :mod:`davis_ag.formats.masks`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from davis_ag.formats.masks import mask_dtype, no_fruit_value
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import MAX_FRUIT, NO_FRUIT  # noqa: F401 - part of this module's interface
from davis_ag.scene.view_grid import Viewpoint


@dataclass(frozen=True)
class ViewLabels:
    """Labels of one view.

    Attributes:
        segmentation: (height, width) fruit id per pixel, no fruit where no labelled fruit: the
            lookup's type, uint8 (255) or uint16 (65535).
        boxes: Published boxes ``[xmin, ymin, width, height, fruit_id, 0]``, sorted by fruit id.
        visible_pixels: Visible pixels of each boxed fruit.
    """

    segmentation: np.ndarray
    boxes: list[list[int]]
    visible_pixels: dict[int, int]


def fruit_lookup(fruit_primitives: dict[int, np.ndarray], uuid_count: int) -> np.ndarray:
    """Table from primitive-id pixel value (UUID + 1, 0 = nothing) to fruit id, no fruit for the rest.

    Its type is the scene's mask type (:func:`davis_ag.formats.masks.mask_dtype`): uint8 with 255
    for non-fruit up to 255 fruit, uint16 with 65535 above; the labels of :func:`label_view` keep it.

    Args:
        fruit_primitives: Primitive UUIDs of each fruit id (ids 0..n-1 for n fruit).
        uuid_count: One more than the largest UUID in the scene.
    """
    fruit_count = max(len(fruit_primitives), max(fruit_primitives, default=-1) + 1)
    dtype = mask_dtype(fruit_count)
    table = np.full(uuid_count + 1, no_fruit_value(dtype), dtype=dtype)
    for fruit_id, uuids in fruit_primitives.items():
        table[np.asarray(uuids, dtype=np.int64) + 1] = fruit_id
    return table


def label_view(primitive_ids: np.ndarray, lookup: np.ndarray, min_pixels: int) -> ViewLabels:
    """Boxes and segmentation of the fruit seen in a view.

    Args:
        primitive_ids: The renderer's id image (UUID + 1 per pixel, 0 = nothing).
        lookup: :func:`fruit_lookup` of the scene.
        min_pixels: Visible pixels a fruit needs for a box (section III-C).
    """
    no_fruit = no_fruit_value(lookup)
    fruit_map = lookup[np.minimum(primitive_ids, len(lookup) - 1)]
    flat = np.flatnonzero(fruit_map != no_fruit)
    ids = fruit_map.ravel()[flat]
    counts = np.bincount(ids, minlength=no_fruit)
    kept = np.flatnonzero(counts >= min_pixels)
    width = fruit_map.shape[1]
    rows, cols = np.divmod(flat, width)
    boxes: list[list[int]] = []
    for fruit_id in kept:
        mine = ids == fruit_id
        r, c = rows[mine], cols[mine]
        x0, y0 = int(c.min()), int(r.min())
        boxes.append([x0, y0, int(c.max()) - x0 + 1, int(r.max()) - y0 + 1, int(fruit_id), 0])
    keep = np.zeros(no_fruit + 1, dtype=bool)
    keep[kept] = True
    segmentation = np.where(keep[fruit_map], fruit_map, no_fruit).astype(lookup.dtype)
    return ViewLabels(segmentation, boxes, {int(f): int(counts[f]) for f in kept})


def silhouette_pixels(camera: Camera, view: Viewpoint, polygons: list[np.ndarray]) -> int:
    """Pixels a fruit would cover in the image with nothing in front of it.

    The fruit's primitives are projected with the pinhole model and a pixel counts when its
    centre lies inside one of them: the rule the renderer rasterises by, so the count compares
    with the visible pixels (filling with OpenCV counted every pixel an edge touched, about half a
    pixel too much all round). Only pixels within the image frame count.

    Args:
        camera: The camera.
        view: The pose.
        polygons: The fruit's primitives, grouped by vertex count: arrays of (n, k, 3).
    """
    triangles: list[np.ndarray] = []
    for group in polygons:
        uv, depth = camera.project(view, group)
        uv = uv[(depth > 0.01).all(axis=1)]
        triangles.extend(uv[:, [0, i, i + 1]] for i in range(1, uv.shape[1] - 1))  # fans
    if not triangles:
        return 0
    # Pixel (column u, row v) has its centre at (u + 0.5, v + 0.5).
    tri = np.concatenate(triangles) - 0.5
    lo = np.maximum(np.ceil(tri.min(axis=1)), 0).astype(np.int64)
    hi = np.minimum(np.floor(tri.max(axis=1)), (camera.width - 1, camera.height - 1)).astype(np.int64)
    spans = np.maximum(hi - lo + 1, 0)
    counts = spans[:, 0] * spans[:, 1]
    if counts.sum() == 0:
        return 0
    # Every pixel centre in each triangle's bounding box, then the inside test by edge functions.
    which = np.repeat(np.arange(len(tri)), counts)
    offset = np.arange(counts.sum()) - np.repeat(np.cumsum(counts) - counts, counts)
    px = lo[which, 0] + offset % spans[which, 0]
    py = lo[which, 1] + offset // spans[which, 0]
    corners = tri[which]
    sides = np.stack(
        [
            (corners[:, j, 0] - corners[:, i, 0]) * (py - corners[:, i, 1])
            - (corners[:, j, 1] - corners[:, i, 1]) * (px - corners[:, i, 0])
            for i, j in ((0, 1), (1, 2), (2, 0))
        ]
    )
    inside = ((sides >= 0).all(axis=0) | (sides <= 0).all(axis=0)) & sides.any(axis=0)
    return len(np.unique(py[inside] * camera.width + px[inside]))


def visible_fractions(
    camera: Camera,
    view: Viewpoint,
    labels: ViewLabels,
    fruit_polygons: dict[int, list[np.ndarray]],
    silhouette=None,
) -> dict[int, float]:
    """Visible pixels over unoccluded pixels for every boxed fruit, rounded to 4 digits.

    Args:
        camera, view, labels: The view and its labels.
        fruit_polygons: Each fruit's primitives, for :func:`silhouette_pixels`.
        silhouette: Optional ``silhouette(fruit_id) -> pixels`` that counts the unoccluded pixels
            faster (our renderer draws them); :func:`silhouette_pixels` otherwise.
    """
    fractions = {}
    for fruit_id, visible in labels.visible_pixels.items():
        whole = silhouette(fruit_id) if silhouette else silhouette_pixels(camera, view, fruit_polygons[fruit_id])
        fractions[fruit_id] = round(min(1.0, visible / max(whole, visible, 1)), 4)
    return fractions

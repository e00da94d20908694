"""Fruit labels from primitive-id images: boxes, segmentation, silhouettes, visible fractions."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from hypothesis.extra.numpy import arrays

from davis_ag.labels.fruit_labels import (
    NO_FRUIT,
    ViewLabels,
    fruit_lookup,
    label_view,
    silhouette_pixels,
    visible_fractions,
)
from davis_ag.scene.camera import Camera
from davis_ag.scene.view_grid import Viewpoint

#: Synthetic scene: fruit id -> its primitive UUIDs; UUIDs 0..9 are leaves and soil.
FRUIT_PRIMITIVES = {0: np.array([10, 11]), 1: np.array([12]), 3: np.array([20, 21, 22]), 7: np.array([30])}
UUID_COUNT = 40
LOOKUP = fruit_lookup(FRUIT_PRIMITIVES, UUID_COUNT)

CAMERA = Camera(160, 90)
#: Camera 1 m above the ground looking along +x, level.
VIEW = Viewpoint(0, 0, 0, 0, 0, (0.0, 0.0, 1.0), (0.0, 0.0, 1.0), 0.0, 0.0)


def paint(shape: tuple[int, int], *patches: tuple[int, slice, slice]) -> np.ndarray:
    """A primitive-id image (UUID + 1, 0 = nothing) with rectangles of the given UUIDs."""
    image = np.zeros(shape, dtype=np.uint32)
    for uuid, rows, cols in patches:
        image[rows, cols] = uuid + 1
    return image


def test_lookup_maps_pixel_values_to_fruit_ids() -> None:
    assert LOOKUP.dtype == np.uint8 and len(LOOKUP) == UUID_COUNT + 1
    assert LOOKUP[0] == NO_FRUIT  # nothing drawn
    assert LOOKUP[5 + 1] == NO_FRUIT  # a leaf
    for fruit_id, uuids in FRUIT_PRIMITIVES.items():
        assert (LOOKUP[uuids + 1] == fruit_id).all()


def test_box_convention_is_xmin_ymin_inclusive_width_height() -> None:
    # Fruit 0 covers rows 2..4 and columns 5..9 with its two primitives; fruit 3 a single pixel.
    ids = paint(
        (20, 30), (10, slice(2, 5), slice(5, 8)), (11, slice(2, 5), slice(8, 10)), (21, slice(15, 16), slice(29, 30))
    )
    labels = label_view(ids, LOOKUP, min_pixels=1)
    assert labels.boxes == [[5, 2, 5, 3, 0, 0], [29, 15, 1, 1, 3, 0]]
    assert labels.visible_pixels == {0: 15, 3: 1}


def test_threshold_drops_small_fruit_from_boxes_and_segmentation() -> None:
    ids = paint(
        (20, 30), (10, slice(0, 4), slice(0, 4)), (12, slice(10, 13), slice(10, 13)), (3, slice(15, 20), slice(0, 30))
    )
    labels = label_view(ids, LOOKUP, min_pixels=10)  # fruit 0: 16 pixels, fruit 1: 9 pixels
    assert [box[4] for box in labels.boxes] == [0]
    assert set(np.unique(labels.segmentation)) == {0, NO_FRUIT}
    assert (labels.segmentation[10:13, 10:13] == NO_FRUIT).all()
    labels = label_view(ids, LOOKUP, min_pixels=9)
    assert [box[4] for box in labels.boxes] == [0, 1]


def test_occluded_fruit_split_in_two_gets_one_box_spanning_both_parts() -> None:
    ids = paint(
        (20, 30), (20, slice(5, 10), slice(2, 6)), (22, slice(5, 10), slice(12, 16)), (4, slice(0, 20), slice(6, 12))
    )
    labels = label_view(ids, LOOKUP, min_pixels=1)
    assert labels.boxes == [[2, 5, 14, 5, 3, 0]]
    assert labels.visible_pixels == {3: 40}


@st.composite
def fruit_maps(draw: st.DrawFn) -> np.ndarray:
    """Per pixel: a fruit id of FRUIT_PRIMITIVES, or NO_FRUIT."""
    shape = (draw(st.integers(1, 24)), draw(st.integers(1, 24)))
    return draw(arrays(np.uint8, shape, elements=st.sampled_from([*FRUIT_PRIMITIVES, NO_FRUIT])))


@settings(max_examples=150, deadline=None)
@given(fruit_maps(), st.integers(1, 30), st.integers(0, 2**32 - 1))
def test_boxes_and_masks_agree(fruit_map: np.ndarray, min_pixels: int, seed: int) -> None:
    # Any of a fruit's primitives may be drawn on a pixel; other pixels show soil, leaves or nothing.
    pick = np.random.default_rng(seed).integers(0, 6, size=fruit_map.shape)
    ids = (pick % 5).astype(np.uint32)  # 0 = nothing, else a non-fruit UUID + 1
    for fruit_id, uuids in FRUIT_PRIMITIVES.items():
        here = fruit_map == fruit_id
        ids[here] = uuids[pick[here] % len(uuids)] + 1
    labels = label_view(ids, LOOKUP, min_pixels)

    counts = {f: int((fruit_map == f).sum()) for f in FRUIT_PRIMITIVES}
    kept = sorted(f for f, n in counts.items() if n >= min_pixels)
    assert [box[4] for box in labels.boxes] == kept
    assert labels.visible_pixels == {f: counts[f] for f in kept}
    expected_mask = np.where(np.isin(fruit_map, kept), fruit_map, NO_FRUIT)
    assert labels.segmentation.dtype == np.uint8 and labels.segmentation.shape == fruit_map.shape
    assert np.array_equal(labels.segmentation, expected_mask)
    for x, y, w, h, fruit_id, zero in labels.boxes:
        assert zero == 0 and w >= 1 and h >= 1
        rows, cols = np.nonzero(labels.segmentation == fruit_id)
        assert (x, y, x + w - 1, y + h - 1) == (cols.min(), rows.min(), cols.max(), rows.max())


def test_a_scene_of_more_than_255_fruit_labels_ids_above_255_in_a_16_bit_mask() -> None:
    # 400 fruit, fruit k on UUID 100 + k; UUIDs 0..99 are leaves and soil.
    many = {k: np.array([100 + k]) for k in range(400)}
    lookup = fruit_lookup(many, 600)
    assert lookup.dtype == np.uint16 and lookup[0] == lookup[50 + 1] == 65535 and lookup[100 + 300 + 1] == 300
    assert fruit_lookup(dict(list(many.items())[:255]), 600).dtype == np.uint8  # 255 fruit: as before
    ids = paint(
        (20, 30),
        (100 + 300, slice(2, 6), slice(3, 9)),  # fruit 300: 24 pixels
        (100 + 255, slice(10, 12), slice(0, 2)),  # fruit 255 (no fruit in a uint8 mask): 4 pixels
        (100 + 256, slice(15, 16), slice(20, 21)),  # fruit 256 (0 in uint8): 1 pixel, under the threshold
        (7, slice(18, 20), slice(0, 30)),  # a leaf
    )
    labels = label_view(ids, lookup, min_pixels=4)
    assert labels.boxes == [[0, 10, 2, 2, 255, 0], [3, 2, 6, 4, 300, 0]]
    assert labels.visible_pixels == {255: 4, 300: 24}
    seg = labels.segmentation
    assert seg.dtype == np.uint16 and seg.shape == (20, 30)
    assert (seg[2:6, 3:9] == 300).all() and (seg[10:12, 0:2] == 255).all()
    assert int((seg != 65535).sum()) == 28 and seg[15, 20] == 65535


# ---------------------------------------------------------------------------------------------
# Silhouettes and visible fractions


def unproject(u: float, v: float, depth: float) -> np.ndarray:
    """The world point VIEW sees at pixel coordinates (u, v) and the given depth."""
    return np.array(
        [depth, -(u - CAMERA.width / 2) * depth / CAMERA.fy, 1.0 + (CAMERA.height / 2 - v) * depth / CAMERA.fy]
    )


def polygon(corners: list[tuple[float, float]], depth: float = 2.0) -> np.ndarray:
    """One world polygon, shaped (1, k, 3), that projects onto the given pixel corners."""
    return np.array([[unproject(u, v, depth) for u, v in corners]])


def shoelace(corners: list[tuple[float, float]]) -> tuple[float, float]:
    """Area and perimeter of a pixel polygon."""
    pts = np.asarray(corners)
    x, y = pts[:, 0], pts[:, 1]
    area = 0.5 * abs(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))
    perimeter = float(np.linalg.norm(pts - np.roll(pts, -1, axis=0), axis=1).sum())
    return area, perimeter


def test_pixel_aligned_square_covers_exactly_its_pixels() -> None:
    # Integer pixel coordinates are pixel corners: a 20 x 20 square on them covers 400 pixels.
    assert silhouette_pixels(CAMERA, VIEW, [polygon([(40, 20), (60, 20), (60, 40), (40, 40)])]) == 400
    # The same square as two triangles, with the triangles grouped together.
    a, b, c, d = (unproject(u, v, 2.0) for u, v in [(40, 20), (60, 20), (60, 40), (40, 40)])
    assert silhouette_pixels(CAMERA, VIEW, [np.array([[a, b, c], [a, c, d]])]) == 400


@settings(max_examples=60, deadline=None)
@given(
    st.floats(10, 120),
    st.floats(10, 60),  # first corner
    st.floats(4, 30),
    st.floats(4, 25),  # square/rectangle size
    st.floats(0.5, 6.0),  # depth: the silhouette depends only on the projection
    st.booleans(),
)
def test_projected_shapes_match_their_analytic_area_within_a_pixel_border(
    u: float,
    v: float,
    w: float,
    h: float,
    depth: float,
    triangle: bool,
) -> None:
    corners = [(u, v), (u + w, v), (u + w, v + h)] if triangle else [(u, v), (u + w, v), (u + w, v + h), (u, v + h)]
    area, perimeter = shoelace(corners)
    assert CAMERA.project(VIEW, polygon(corners, depth))[0][0] == pytest.approx(np.array(corners), abs=1e-6)
    pixels = silhouette_pixels(CAMERA, VIEW, [polygon(corners, depth)])
    assert abs(pixels - area) <= perimeter / 2 + 2


def test_overlapping_primitives_count_once() -> None:
    # A closed fruit mesh projects its front and back over each other: the union counts, once.
    a = polygon([(40, 20), (60, 20), (60, 40), (40, 40)])
    b = polygon([(50, 20), (70, 20), (70, 40), (50, 40)])
    assert silhouette_pixels(CAMERA, VIEW, [np.concatenate([a, b])]) == 600
    assert silhouette_pixels(CAMERA, VIEW, [np.concatenate([a, a, a])]) == 400
    # Groups of triangles and of quads add up.
    p, q, r, t = (unproject(u, v, 2.0) for u, v in [(80, 20), (100, 20), (100, 40), (80, 40)])
    assert silhouette_pixels(CAMERA, VIEW, [a, np.array([[p, q, r], [p, r, t]])]) == 800


def test_silhouette_counts_only_pixels_inside_the_frame() -> None:
    # Half of a 20 x 20 square hangs over the left edge; a square behind the camera covers nothing.
    assert silhouette_pixels(CAMERA, VIEW, [polygon([(-10, 20), (10, 20), (10, 40), (-10, 40)])]) == 200
    behind = polygon([(40, 20), (60, 20), (60, 40), (40, 40)], depth=-2.0)
    assert silhouette_pixels(CAMERA, VIEW, [behind]) == 0
    assert silhouette_pixels(CAMERA, VIEW, []) == 0


@settings(max_examples=100, deadline=None)
@given(st.integers(1, 2000), st.floats(4, 40))
def test_visible_fraction_is_at_most_one(visible: int, side: float) -> None:
    square = polygon([(40, 20), (40 + side, 20), (40 + side, 20 + side), (40, 20 + side)])
    whole = silhouette_pixels(CAMERA, VIEW, [square])
    labels = ViewLabels(np.full((CAMERA.height, CAMERA.width), NO_FRUIT, np.uint8), [], {5: visible})
    fraction = visible_fractions(CAMERA, VIEW, labels, {5: [square]})[5]
    assert 0 < fraction <= 1
    if visible <= whole:
        assert fraction == round(visible / whole, 4)
    else:  # more visible than the silhouette (rounding at its edge): counts as wholly visible
        assert fraction == 1.0

"""The Canopy Generator plants: built geometry against the phenotype drawn (section III-A), where
the plug-in puts fruit, organ labels, and the geometry helpers' conventions."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.scene.canopy import GRAPE_LEAF_STALK_UV, GRAPE_LEAF_TIP_UV, goblet_vine_parts, strawberry_parts
from davis_ag.scene.canopy_geometry import (
    bent_shoot,
    cart2sphere,
    flat_tile,
    interpolate_tube,
    rotate,
    rotation,
    sphere2cart,
)
from davis_ag.scene.organs import FRUIT, LEAF, ORGAN_DATA
from davis_ag.scene.plants import Phenotype
from davis_ag.scene.specs import CROPS, PHENOTYPE_SPREAD

pytest.importorskip("pyhelios")


def _grow(crop_name: str, factors: tuple[float, float, float], seed: int = 7):
    from pyhelios import Context

    from davis_ag.scene.canopy_plants import grow_canopy_plant

    crop = CROPS[crop_name]
    target = Phenotype(crop.plant_height * factors[0], crop.fruit_radius * factors[1], crop.leaf_length * factors[2])
    context = Context()
    return context, grow_canopy_plant(context, crop, 0, (0.0, 0.0), target, seed)


# The extremes of section III-A's spread: height +-15 %, fruit and leaf +-20 %.
LOW = (1 - PHENOTYPE_SPREAD["plant_height"], 1 - PHENOTYPE_SPREAD["fruit_radius"], 1 - PHENOTYPE_SPREAD["leaf_length"])
HIGH = (1 + PHENOTYPE_SPREAD["plant_height"], 1 + PHENOTYPE_SPREAD["fruit_radius"], 1 + PHENOTYPE_SPREAD["leaf_length"])


@pytest.mark.parametrize("crop_name", ["strawberry", "tomato", "vine"])
@pytest.mark.parametrize("factors", [LOW, HIGH], ids=["low", "high"])
def test_built_geometry_matches_the_drawn_phenotype(crop_name, factors):
    _, plant = _grow(crop_name, factors)
    target, measured = plant.target, plant.measured
    # Fruit (vine: berries) are built at the drawn radius, read in Table 1's terms.
    assert measured.fruit_radius == pytest.approx(target.fruit_radius, rel=0.03)
    if crop_name == "vine":  # leaves grow along a cane towards the drawn width and stay just below it
        assert 0.93 * target.leaf_length <= measured.leaf_length <= target.leaf_length * 1.001
        assert measured.plant_height == pytest.approx(target.plant_height, rel=0.01)  # the trunk
    else:  # the tip leaf is built at the drawn length
        assert measured.leaf_length == pytest.approx(target.leaf_length, rel=0.01)
    if crop_name == "tomato":  # the main stem
        assert measured.plant_height == pytest.approx(target.plant_height, rel=0.01)
    if crop_name == "strawberry":  # the longest stems are 0.9-1.1 H and nearly upright
        assert 0.85 * target.plant_height <= measured.plant_height <= 1.12 * target.plant_height


def test_taller_drawn_plants_are_built_taller():
    low = _grow("strawberry", LOW)[1].measured.plant_height
    high = _grow("strawberry", HIGH)[1].measured.plant_height
    assert high / low == pytest.approx(HIGH[0] / LOW[0], rel=0.12)


def test_strawberry_fruit_float_out_from_the_crown_low():
    """strawberry.cpp: a fruit 0.1-0.3 m out from the point 35 % along its stem, most stems 54-81 degrees up."""
    context, plant = _grow("strawberry", (1.0, 1.0, 1.0))
    from davis_ag.scene.plant_geometry import primitive_vertices

    centres = np.array([np.concatenate(primitive_vertices(context, body)).mean(axis=0) for body in plant.fruit_bodies])
    distance = np.hypot(centres[:, 0], centres[:, 1])
    assert 15 <= len(centres) <= 45  # 50 stems, each with a fruit at probability 0.6
    assert distance.min() >= 0.05 and distance.max() <= 0.36
    assert 0.1 <= np.median(distance) <= 0.3
    assert centres[:, 2].max() < 0.5 * plant.target.plant_height  # low: below half the plant
    assert centres[:, 2].min() > 0.0  # above the soil


def test_tomato_fruit_hang_along_its_single_stem():
    context, plant = _grow("tomato", (1.0, 1.0, 1.0))
    from davis_ag.scene.plant_geometry import primitive_vertices

    centres = np.array([np.concatenate(primitive_vertices(context, body)).mean(axis=0) for body in plant.fruit_bodies])
    height = plant.target.plant_height
    assert np.hypot(centres[:, 0], centres[:, 1]).max() < 0.35 * height  # close to the stem
    # From the lowest shoots (40 % of the stem) to the top, hung 4 radii below the shoots.
    assert centres[:, 2].min() > 0.3 * height and centres[:, 2].max() < 1.1 * height
    assert centres[:, 2].max() - centres[:, 2].min() > 0.2 * height  # spread along it, not in one truss


def test_every_primitive_carries_its_organ():
    context, plant = _grow("vine", (1.0, 1.0, 1.0))
    organs = np.asarray(context.getPrimitiveDataArray(plant.uuids, ORGAN_DATA))
    fruit = {u for body in plant.fruit_bodies for u in body}
    assert set(np.unique(organs)) == {FRUIT, LEAF, 5}  # berries, leaves, and trunk and canes
    assert all(o == FRUIT for u, o in zip(plant.uuids, organs) if u in fruit)
    assert sum(o == FRUIT for o in organs) == len(fruit)


def test_same_seed_same_plant_other_seed_other_plant():
    a = strawberry_parts(Phenotype(0.4, 0.025, 0.1), np.zeros(3), np.random.default_rng(3))
    b = strawberry_parts(Phenotype(0.4, 0.025, 0.1), np.zeros(3), np.random.default_rng(3))
    c = strawberry_parts(Phenotype(0.4, 0.025, 0.1), np.zeros(3), np.random.default_rng(4))
    assert np.array_equal(a.leaves[10].triangles, b.leaves[10].triangles)
    assert not np.allclose(a.leaves[10].triangles, c.leaves[10].triangles)


def _distance_to_polyline(point: np.ndarray, nodes: np.ndarray) -> float:
    a, b = nodes[:-1], nodes[1:]
    t = np.clip(((point - a) * (b - a)).sum(1) / np.maximum(((b - a) ** 2).sum(1), 1e-18), 0.0, 1.0)
    return float(np.linalg.norm(a + t[:, None] * (b - a) - point, axis=1).min())


@pytest.mark.parametrize("seed", [0, 1, 2])
def test_vine_leaves_hang_from_their_stalks_next_to_the_cane(seed):
    """grapevine.cpp (2023): the leaf prototype is a tile turned half a turn (make_SphericalCoord(0,
    M_PI)), tilted by -Rtheta about y, turned by Rphi about z with a rotate that turns by -Rphi, and
    placed at pos_leaf - leaf_offset: every leaf hangs with its stalk end above its tip and nearer
    the cane it grows on than its tip is."""
    parts = goblet_vine_parts(Phenotype(0.7, 0.0075, 0.18), np.zeros(3), np.random.default_rng(seed))
    canes = [tube.nodes for tube in parts.tubes[1:]]  # the trunk first, then one tube per cane
    assert len(canes) == 20 and len(parts.leaves) > 100
    stalk_up = nearer = 0
    for leaf in parts.leaves:
        stalk, tip = leaf.point_at(GRAPE_LEAF_STALK_UV), leaf.point_at(GRAPE_LEAF_TIP_UV)
        stalk_up += stalk[2] > tip[2]
        cane_distance = [(_distance_to_polyline(stalk, c), _distance_to_polyline(tip, c)) for c in canes]
        nearest = min(cane_distance)  # the cane the stalk is closest to
        nearer += nearest[0] < nearest[1]
    # Rtheta is 0.4 pi +- 10 %: every leaf hangs stalk up, whatever its turn about z.
    assert stalk_up == len(parts.leaves)
    assert nearer >= 0.9 * len(parts.leaves)


def test_leaf_points_follow_their_texture_coordinates():
    tile = flat_tile(2.0, 1.0)  # x from -1 to 1, u from 0 to 1
    assert np.allclose(tile.point_at((0.25, 0.5)), [-0.5, 0.0, 0.0])
    assert np.allclose(flat_tile(2.0, 1.0, flip=True).point_at((0.25, 0.5)), [0.5, 0.0, 0.0])
    with pytest.raises(ValueError):
        tile.point_at((1.5, 0.5))


# ---------------------------------------------------------------------------------------------
# Helios's conventions


def test_rotation_is_right_handed_as_helios_rotates_primitives():
    # Measured with pyhelios: rotatePrimitive by +90 degrees about z takes +x to +y, about y +x to -z.
    assert np.allclose(rotate(np.array([1.0, 0, 0]), math.pi / 2, "z"), [0, 1, 0])
    assert np.allclose(rotate(np.array([1.0, 0, 0]), math.pi / 2, "y"), [0, 0, -1])
    assert np.allclose(rotate(np.array([0, 1.0, 0]), math.pi / 2, "x"), [0, 0, 1])


angles = st.floats(-2 * math.pi, 2 * math.pi, allow_nan=False)


@given(angles, st.sampled_from("xyz"))
def test_rotations_are_proper(angle, axis):
    matrix = rotation(angle, axis)
    assert np.allclose(matrix @ matrix.T, np.eye(3)) and np.linalg.det(matrix) == pytest.approx(1.0)


@given(st.floats(0.01, 10), st.floats(-1.5, 1.5), st.floats(0, 2 * math.pi - 1e-6))
def test_spherical_round_trip(radius, elevation, azimuth):
    back = cart2sphere(sphere2cart(radius, elevation, azimuth))
    assert back[0] == pytest.approx(radius, rel=1e-9)
    assert back[1] == pytest.approx(elevation, abs=1e-9)
    assert math.cos(back[2] - azimuth) == pytest.approx(1.0, abs=1e-9)  # the same direction about z


@settings(max_examples=50)
@given(st.lists(st.tuples(*[st.floats(-1, 1)] * 3), min_size=2, max_size=8, unique=True), st.floats(0, 1))
def test_interpolate_tube_walks_the_polyline(points, fraction):
    nodes = np.array(points)
    if np.linalg.norm(np.diff(nodes, axis=0), axis=1).min() < 1e-3:
        return
    assert np.allclose(interpolate_tube(nodes, 0.0), nodes[0])
    assert np.allclose(interpolate_tube(nodes, 1.0), nodes[-1])
    point = interpolate_tube(nodes, fraction)
    # On some segment of the polyline.
    gaps = []
    for a, b in itertools.pairwise(nodes):
        t = np.clip(np.dot(point - a, b - a) / np.dot(b - a, b - a), 0, 1)
        gaps.append(np.linalg.norm(a + t * (b - a) - point))
    assert min(gaps) < 1e-9


@given(st.floats(0.05, 2.0), st.floats(0.0, 2.0), st.floats(-0.5, 1.5), st.floats(0, 6.2))
def test_a_bent_shoot_is_as_long_as_asked(length, bend, elevation, azimuth):
    nodes = bent_shoot(np.zeros(3), sphere2cart(1.0, elevation, azimuth), length, bend, 10)
    assert np.linalg.norm(np.diff(nodes, axis=0), axis=1).sum() == pytest.approx(length, rel=1e-9)

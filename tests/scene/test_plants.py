"""Plants grown with Helios: phenotypes within the paper's ranges, enough fruit, distinct seeds."""

from __future__ import annotations

import itertools
from dataclasses import asdict

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.scene.plants import (
    HELIOS_SEED_RANGE,
    MAX_BUILDS,
    TOLERANCE,
    GrownPlant,
    Phenotype,
    fruit_body_uuids,
    helios_seed,
    in_table_range,
    leaf_groups,
    primitive_vertices,
    principal_extents,
    quiet_stdout,
    relative_error,
    require_native_helios,
    sample_phenotype,
)
from davis_ag.scene.specs import CROPS, PHENOTYPE_SPREAD, CropSpec

#: Seeds Helios 0.1.38 maps to one and the same plant (checked below for 0 and 1).
SAME_PLANT_SEEDS = (0, 1, 2**31 - 1, 2**32 - 1)


def nominal(crop: CropSpec) -> dict[str, float]:
    return {"plant_height": crop.plant_height, "fruit_radius": crop.fruit_radius, "leaf_length": crop.leaf_length}


# ---------------------------------------------------------------------------------------------
# Without Helios


@settings(max_examples=200, deadline=None)
@given(st.sampled_from(sorted(CROPS)), st.integers(0, 2**64 - 1))
def test_sampled_phenotype_lies_within_table_1_and_its_spread(crop: str, seed: int) -> None:
    spec = CROPS[crop]
    phenotype = sample_phenotype(spec, np.random.default_rng(seed))
    for name, value in nominal(spec).items():
        assert abs(getattr(phenotype, name) / value - 1.0) <= PHENOTYPE_SPREAD[name]
    assert in_table_range(phenotype, spec)


def test_sampled_phenotypes_spread_uniformly_around_table_1() -> None:
    # Table 1 +- 15 % (height) and +- 20 % (fruit radius, leaf length), uniformly.
    assert PHENOTYPE_SPREAD == {"plant_height": 0.15, "fruit_radius": 0.20, "leaf_length": 0.20}
    rng = np.random.default_rng(0)
    crop = CROPS["tomato"]
    samples = [sample_phenotype(crop, rng) for _ in range(4000)]
    for name, value in nominal(crop).items():
        ratios = np.array([getattr(s, name) for s in samples]) / value - 1.0
        spread = PHENOTYPE_SPREAD[name]
        assert abs(ratios.mean()) < 0.01
        assert ratios.min() > -spread and ratios.max() < spread
        assert ratios.min() < -0.95 * spread and ratios.max() > 0.95 * spread
        assert ratios.std() == pytest.approx(2 * spread / np.sqrt(12), rel=0.05)


@settings(max_examples=300, deadline=None)
@given(st.integers(0, 2**64 - 1))
def test_helios_seeds_avoid_the_seeds_helios_confuses(seed: int) -> None:
    drawn = helios_seed(np.random.default_rng(seed))
    assert isinstance(drawn, int)
    assert HELIOS_SEED_RANGE[0] <= drawn <= HELIOS_SEED_RANGE[1]
    assert drawn not in SAME_PLANT_SEEDS


def test_helios_seed_range_excludes_every_confused_seed() -> None:
    low, high = HELIOS_SEED_RANGE
    assert all(not low <= s <= high for s in SAME_PLANT_SEEDS)
    assert high < 2**31 - 1  # stays a positive C int


def test_leaf_groups_cut_runs_of_consecutive_blades() -> None:
    # Strawberry: three leaflets per petiole, numbered consecutively; other objects in between.
    assert leaf_groups([12, 10, 11, 13, 14, 15, 20, 21], 3) == [[10, 11, 12], [13, 14, 15], [20, 21]]
    assert leaf_groups([4, 6, 8], 3) == [[4], [6], [8]]
    assert leaf_groups([1, 2, 3], 1) == [[1], [2], [3]]
    assert leaf_groups([], 7) == []


@settings(max_examples=200, deadline=None)
@given(st.sets(st.integers(0, 60), max_size=40), st.integers(1, 7))
def test_leaf_groups_partition_blades_into_short_consecutive_runs(blades: set[int], per_leaf: int) -> None:
    groups = leaf_groups(list(blades), per_leaf)
    assert [b for g in groups for b in g] == sorted(blades)
    for group in groups:
        assert 1 <= len(group) <= per_leaf
        assert group == list(range(group[0], group[0] + len(group)))
    for first, second in itertools.pairwise(groups):
        # A leaf ends at a gap in the numbering or when it has all its blades.
        assert second[0] != first[-1] + 1 or len(first) == per_leaf


def test_relative_error_treats_missing_fruit_as_infinitely_wrong() -> None:
    target = Phenotype(1.0, 0.03, 0.2)
    errors = relative_error(Phenotype(1.1, float("nan"), 0.2), target)
    assert errors["plant_height"] == pytest.approx(0.1)
    assert errors["fruit_radius"] == float("inf")
    assert errors["leaf_length"] == 0.0


# ---------------------------------------------------------------------------------------------
# With Helios


def test_native_helios_is_loaded() -> None:
    require_native_helios()  # pyhelios would otherwise silently run in mock mode


def grow(crop: CropSpec, seed: int, position: tuple[float, float]) -> tuple[object, object, GrownPlant]:
    """Grow one plant the way build_scene does, from a generator seeded with ``seed``."""
    from pyhelios import Context

    from davis_ag.scene.architecture_plants import grow_architecture_plant, load_architecture_model

    rng = np.random.default_rng(seed)
    model = load_architecture_model(Context(), crop, rng)
    target = sample_phenotype(crop, rng)
    plant = grow_architecture_plant(model, 0, position, target, helios_seed(rng))
    return model.context, model.plant_architecture, plant


# One plant per crop (tomato and vine builds take seconds each); generator seeds picked among the
# first few for plants that reach their target in few builds.
@pytest.mark.parametrize(("crop", "seed"), [("strawberry", 2), ("tomato", 0), ("vine", 2)])
def test_grown_plant_matches_its_target_within_table_1(crop: str, seed: int) -> None:
    spec = CROPS[crop]
    position = (0.3, -0.2)
    context, plant_architecture, plant = grow(spec, seed, position)

    # The target is Table 1 +- the paper's spread; a plant is only kept when its measured
    # phenotype lies in that range too (and is on target, or every build allowed was spent).
    assert in_table_range(plant.target, spec)
    for name, value in nominal(spec).items():
        assert abs(getattr(plant.measured, name) / value - 1.0) <= PHENOTYPE_SPREAD[name]
    errors = relative_error(plant.measured, plant.target)
    assert max(errors.values()) <= TOLERANCE or plant.builds >= MAX_BUILDS, errors
    assert max(errors.values()) <= 0.2, errors

    # Enough fruit, each a Helios object of the plant.
    assert len(plant.fruit_objects) >= spec.min_fruit
    assert len(set(plant.fruit_objects)) == len(plant.fruit_objects)
    uuids = set(plant.uuids)
    for fruit in plant.fruit_objects:
        fruit_uuids = context.getObjectPrimitiveUUIDs(fruit)
        assert fruit_uuids and set(fruit_uuids) <= uuids

    # It stands on the ground at its position and is as tall as measured.
    points = np.concatenate(primitive_vertices(context, plant.uuids))
    assert points[:, 2].min() >= -0.01
    assert (points.min(axis=0)[:2] < position).all() and (points.max(axis=0)[:2] > position).all()
    assert np.hypot(*(np.median(points[:, :2], axis=0) - position)) < 0.2
    if crop != "vine":  # the vine's height is its trunk's; its shoots grow above it
        assert points[:, 2].max() == pytest.approx(plant.measured.plant_height, rel=1e-6)
    else:
        assert points[:, 2].max() > plant.measured.plant_height
        # Goblet: free standing, no trellis wires along a row.
        assert np.ptp(points[:, 0]) < 2.0 and np.ptp(points[:, 1]) < 2.0

    if crop == "strawberry":
        # A compact crown with the fruit hanging low under a broader canopy of leaves, as in the
        # original's bush (the library's 4 mm internodes made a 20 cm column hung with fruit).
        (plant_id,) = plant_architecture.getAllPlantIDs()
        assert plant_architecture.getPlantStemHeight(plant_id) < 0.08
        fruit = np.array(
            [
                np.concatenate(primitive_vertices(context, context.getObjectPrimitiveUUIDs(f))).mean(axis=0)
                for f in plant.fruit_objects
            ]
        )
        leaves = np.concatenate(
            [
                primitive_vertices(context, context.getObjectPrimitiveUUIDs(b))[0]
                for b in plant_architecture.getPlantLeafObjectIDs(plant_id)
            ]
        )
        assert fruit[:, 2].max() < plant.measured.plant_height / 2
        fruit_reach = np.hypot(*(fruit[:, :2] - position).T).max()
        assert np.percentile(np.hypot(*(leaves[:, :2] - position).T), 90) > fruit_reach + 0.05
        # Table 1's 2.5 cm "fruit radius" is the Canopy Generator's parameter, whose strawberry is
        # a tube half that radius at its widest: fruit about as wide as the radius (+- 20 %), half
        # the width a sphere of that radius would have.
        widths = [
            np.median(principal_extents(np.concatenate(primitive_vertices(context, fruit_body_uuids(context, f))))[1:])
            for f in plant.fruit_objects
        ]
        assert 0.75 * spec.fruit_radius < np.median(widths) < 1.3 * spec.fruit_radius

    summary = plant.summary()
    assert summary["phenotype_measured"] == asdict(plant.measured)
    assert summary["fruit_count"] == len(plant.fruit_objects) and summary["seed"] == plant.seed
    assert HELIOS_SEED_RANGE[0] <= plant.seed <= HELIOS_SEED_RANGE[1]


def test_distinct_helios_seeds_give_distinct_plants() -> None:
    from pyhelios import Context
    from pyhelios.types import vec3

    from davis_ag.scene.architecture_plants import load_architecture_model

    crop = CROPS["strawberry"]
    model = load_architecture_model(Context(), crop, np.random.default_rng(0))
    context, plant_architecture = model.context, model.plant_architecture

    def build(seed: int) -> np.ndarray:
        context.seedRandomGenerator(seed)
        with quiet_stdout():
            plant_id = plant_architecture.buildPlantInstanceFromLibrary(vec3(0.0, 0.0, 0.0), crop.age_days)
        points = np.concatenate(primitive_vertices(context, plant_architecture.getAllPlantUUIDs(plant_id)))
        plant_architecture.deletePlantInstance(plant_id)
        return points

    def same(a: np.ndarray, b: np.ndarray) -> bool:
        return a.shape == b.shape and np.allclose(a, b)

    # The trap helios_seed avoids: Helios grows the very same plant from seeds 0 and 1.
    assert same(build(0), build(1))
    rng = np.random.default_rng(0)
    first, second = helios_seed(rng), helios_seed(rng)
    assert not same(build(first), build(second))

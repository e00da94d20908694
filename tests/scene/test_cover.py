"""The floor between the rows: the cover crop's spots stay in the alleys, off the bare strip under
the plants; Helios grows it labelled ``cover``; it draws nothing from the scene's own seed; a
greenhouse row stands on its floor cover."""

from __future__ import annotations

import dataclasses

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.scene.cover import (
    FLOOR_SYSTEMS,
    GRASS,
    SPACING,
    WEEDS,
    FloorSystem,
    cover_length,
    cover_spots,
    covered_strips,
    floor_system,
)
from davis_ag.scene.crop_spec import RowSpec
from davis_ag.scene.organs import COVER, ORGAN_NAMES, SOIL
from davis_ag.scene.specs import CROPS, scenario_spec

ROW_SPACINGS = st.floats(1.5, 8.0)


def _row(row_spacing: float, in_row: float, plants: int) -> RowSpec:
    base = CROPS["vsp-vine"].row
    assert base is not None
    return dataclasses.replace(base, row_spacing=row_spacing, in_row_spacing=in_row, plants=plants)


@settings(max_examples=40, deadline=None)
@given(
    row_spacing=ROW_SPACINGS,
    in_row=st.floats(0.3, 6.0),
    plants=st.integers(1, 8),
    strip=st.floats(0.3, 1.4),
    seed=st.integers(0, 2**32 - 1),
)
def test_every_spot_lies_in_an_alley_clear_of_the_bare_strip_under_each_row(
    row_spacing: float, in_row: float, plants: int, strip: float, seed: int
) -> None:
    row = _row(row_spacing, in_row, plants)
    system = FloorSystem("test", strip, "test")
    spots = cover_spots(row, system, np.random.default_rng(seed))
    if row_spacing - strip >= SPACING:  # an alley narrower than a tuft's cell stays bare
        assert spots, "a covered alley with no tuft"
    half = cover_length(row)
    rows_y = np.array([-2, -1, 0, 1, 2]) * row_spacing
    for spot in spots:
        assert -half - 1e-9 <= spot.x <= half + 1e-9
        # no tuft in the strip kept bare along any row (the three rows and the next ones out)
        assert np.min(np.abs(rows_y - spot.y)) >= strip / 2 - 1e-9, spot
        assert 0.0 <= spot.yaw < 360.0
        assert 0 <= spot.prototype < len(GRASS) + len(WEEDS)


def test_the_cover_is_a_grid_at_its_spacing_mostly_grass_and_the_same_from_the_same_seed() -> None:
    crop = CROPS["vsp-vine"]
    assert crop.row is not None
    system = FLOOR_SYSTEMS["vsp-vine"]
    spots = cover_spots(crop.row, system, np.random.default_rng(1))
    area = sum(high - low for low, high in covered_strips(crop.row, system)) * 2 * cover_length(crop.row)
    assert len(spots) == pytest.approx(area / SPACING**2, rel=0.15)
    weeds = np.mean([s.prototype >= len(GRASS) for s in spots])
    assert 0.0 < weeds < 0.15
    assert spots == cover_spots(crop.row, system, np.random.default_rng(1))
    assert spots != cover_spots(crop.row, system, np.random.default_rng(2))


@pytest.mark.parametrize(
    ("scenario", "crop", "setting", "covered"),
    [
        ("row", "vsp-vine", "default", True),
        ("row", "apple", "default", True),
        ("row", "vine", "default", True),
        ("row", "vsp-vine", "none", False),
        ("mp", "vsp-vine", "default", False),
        ("sp", "apple", "default", False),
        ("row", "capsicum", "default", False),  # a greenhouse: its floor is covered, not sown
        ("row", "strawberry", "default", False),
    ],
)
def test_only_orchard_and_vineyard_rows_with_structures_grow_a_cover(
    scenario: str, crop: str, setting: str, covered: bool
) -> None:
    assert (floor_system(scenario, CROPS[crop], setting) is not None) is covered


def test_helios_grows_the_cover_labelled_cover_at_its_spots() -> None:
    from pyhelios import Context

    from davis_ag.scene.cover import add_cover
    from davis_ag.scene.organs import ORGAN_DATA
    from davis_ag.scene.plants import primitive_vertices

    row = _row(3.0, 1.0, 1)
    system = FloorSystem("test", 2.0, "test")  # one 1 m strip per alley: few tufts
    context = Context()
    uuids = add_cover(context, row, system, np.random.default_rng(4))
    assert sorted(uuids) == sorted(int(u) for u in context.getAllUUIDs()), "a prototype was left behind"
    assert set(np.asarray(context.getPrimitiveDataArray(uuids, ORGAN_DATA)).tolist()) == {COVER}
    points = np.concatenate(primitive_vertices(context, uuids))
    assert points[:, 2].min() > -0.05 and points[:, 2].max() < 0.6, "a tuft off the ground or taller than a cover"
    spots = cover_spots(row, system, np.random.default_rng(4))
    assert len(uuids) >= 300 * len(spots)
    # every tuft's vertices are near a spot (a tuft is at most a 0.35 m runner, turned about its foot)
    ys = np.array([s.y for s in spots])
    assert np.all(np.min(np.abs(points[:, 1:2] - ys[None, :]), axis=1) < 0.45)


def test_the_cover_draws_nothing_from_the_scenes_seed(monkeypatch: pytest.MonkeyPatch) -> None:
    """A strawberry row (the quickest row to grow) given a covered floor, both ways: the same
    plants, fruit and sun."""
    from davis_ag.scene import cover
    from davis_ag.scene.build import build_scene
    from davis_ag.seeds import COVER_STREAM, stream_rng

    monkeypatch.setitem(cover.FLOOR_SYSTEMS, "strawberry", FloorSystem("test", 0.5, "test"))
    base = CROPS["strawberry"]
    assert base.row is not None
    crop = dataclasses.replace(base, row=dataclasses.replace(base.row, plants=1))  # nine plants
    scenario = scenario_spec("row", crop)
    models = {
        setting: build_scene(
            scenario, crop, np.random.default_rng(7), structures=setting, cover_rng=stream_rng(7, COVER_STREAM)
        )
        for setting in ("none", "default")
    }
    bare, covered = models["none"], models["default"]
    assert bare.lighting == covered.lighting
    assert [f.center for f in bare.fruits] == [f.center for f in covered.fruits]
    assert covered.structures == "default" and bare.structures is None
    assert np.count_nonzero(covered.organ_of_uuid() == COVER) > 0
    assert np.count_nonzero(bare.organ_of_uuid() == COVER) == 0
    assert ORGAN_NAMES[COVER] == "cover"


def test_a_greenhouse_row_stands_on_white_floor_cover_labelled_soil() -> None:
    from pyhelios import Context

    from davis_ag.scene.organs import ORGAN_DATA
    from davis_ag.scene.plants import primitive_vertices
    from davis_ag.scene.structures import add_greenhouse_floor, greenhouse_floor

    crop = CROPS["capsicum"]
    assert crop.row is not None
    assert greenhouse_floor(CROPS["vsp-vine"]) is None
    sides = greenhouse_floor(crop)
    assert sides is not None
    hx, hy = sides
    assert hy > 1.5 * crop.row.row_spacing + 0.275  # past the outer alleys' rails
    context = Context()
    uuids = add_greenhouse_floor(context, sides)
    points = np.concatenate(primitive_vertices(context, uuids))
    assert np.allclose(points[:, 2], 0.0008, atol=1e-5)
    assert points[:, 0].max() == pytest.approx(hx, abs=1e-3) and points[:, 1].min() == pytest.approx(-hy, abs=1e-3)
    assert set(np.asarray(context.getPrimitiveDataArray(uuids, ORGAN_DATA)).tolist()) == {SOIL}
    colour = context.getPrimitiveColor(uuids[0])
    assert min(colour.r, colour.g, colour.b) > 0.8


def test_the_sward_covers_each_alleys_strip_with_grass_labelled_cover_at_ground_level() -> None:
    from pyhelios import Context

    from davis_ag.render.scene_geometry import GROUND_TOLERANCE
    from davis_ag.scene.build import helios_texture
    from davis_ag.scene.cover import SWARD_TEXTURE, add_sward
    from davis_ag.scene.organs import ORGAN_DATA
    from davis_ag.scene.plants import primitive_vertices

    crop = CROPS["vsp-vine"]
    assert crop.row is not None
    system = FLOOR_SYSTEMS["vsp-vine"]
    context = Context()
    uuids = add_sward(context, crop.row, system, helios_texture(SWARD_TEXTURE))
    assert set(np.asarray(context.getPrimitiveDataArray(uuids, ORGAN_DATA)).tolist()) == {COVER}
    points = np.concatenate(primitive_vertices(context, uuids))
    assert np.all((points[:, 2] > 0) & (points[:, 2] < GROUND_TOLERANCE)), "the sward must lie on the ground"
    strips = covered_strips(crop.row, system)
    inside = np.zeros(len(points), bool)
    for low, high in strips:
        inside |= (points[:, 1] >= low - 1e-4) & (points[:, 1] <= high + 1e-4)
    assert inside.all(), "sward on the bare strip under a row"
    area = sum(high - low for low, high in strips) * 2 * cover_length(crop.row)
    covered = sum(
        np.ptp(p[:, 0]) * np.ptp(p[:, 1]) for p in primitive_vertices(context, uuids)
    )  # each patch a rectangle
    assert covered == pytest.approx(area, rel=1e-3)

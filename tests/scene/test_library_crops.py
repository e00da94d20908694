"""The plant-library crops' settings and every crop's row: pure data and geometry, no Helios."""

from __future__ import annotations

from dataclasses import replace

import pytest

from davis_ag.errors import UserError
from davis_ag.formats.models import MAX_VIEWS_PER_SCENE
from davis_ag.scene.library_crops import LIBRARY_CROPS, LIBRARY_RECIPES
from davis_ag.scene.scene_size import check_scene_size, scene_bytes
from davis_ag.scene.specs import CROPS, camera_altitudes, crop_spec, group_name, parse_group_name, scenario_spec
from davis_ag.scene.view_grid import views_per_scene

#: Table 3 of the paper, tomato: 45,240 images in 130 SP scenes and 203,400 in 113 MP scenes.
TOMATO_SP_VIEWS = 45_240 // 130
TOMATO_MP_VIEWS = 203_400 // 113
#: Table 1 of the paper, tomato: plant height 100 cm, camera altitudes 70, 110 and 150 cm.
TOMATO_HEIGHT = 1.00
TOMATO_ALTITUDES = (0.70, 1.10, 1.50)
#: The crops issue #43 names, each with one name on the command line.
NEW_CROPS = (
    "apple",
    "apple-wall",
    "almond",
    "olive",
    "pistachio",
    "walnut",
    "capsicum",
    "cherry-tomato",
    "vsp-vine",
    "wye-vine",
)


def test_every_new_crop_is_offered_after_the_papers_three() -> None:
    # Appended, so the paper's crops keep their index in every scene seed.
    assert list(CROPS)[:3] == ["strawberry", "tomato", "vine"]
    assert tuple(CROPS)[3:] == NEW_CROPS
    assert set(LIBRARY_RECIPES) == set(LIBRARY_CROPS) == set(NEW_CROPS)
    for name in NEW_CROPS:
        assert crop_spec(name).source == "library"
        assert crop_spec(LIBRARY_RECIPES[name].model).name == name  # the library's own name works too


def test_an_unknown_crop_gets_one_line_naming_every_crop() -> None:
    with pytest.raises(UserError) as caught:
        crop_spec("banana")
    assert "\n" not in str(caught.value)
    assert all(name in str(caught.value) for name in NEW_CROPS)


@pytest.mark.parametrize("name", NEW_CROPS)
def test_library_grids_are_the_tomatos_scaled_to_the_plant(name: str) -> None:
    crop = CROPS[name]
    assert views_per_scene(scenario_spec("sp", crop), crop) == TOMATO_SP_VIEWS
    assert views_per_scene(scenario_spec("mp", crop), crop) == TOMATO_MP_VIEWS
    scale = crop.grid_scale
    assert scale == pytest.approx(crop.plant_height / TOMATO_HEIGHT, abs=0.005)
    assert crop.altitudes == pytest.approx([a * scale for a in TOMATO_ALTITUDES], abs=1e-3)
    assert crop.min_fruit_pixels >= 10


@pytest.mark.parametrize("name", list(CROPS))
def test_every_crop_has_a_row_whose_cameras_stay_in_the_alleys(name: str) -> None:
    crop = CROPS[name]
    row = crop.row
    assert row is not None and row.source
    # The camera lines lie on the lattice: the standoff is a whole number of half steps.
    assert (row.standoff / (row.step / 2)) == pytest.approx(round(row.standoff / (row.step / 2)))
    # The outer line stays out of the neighbouring row's band, the inner one out of this row's.
    assert row.exclusion_band > 0
    assert row.standoff + row.step < row.row_spacing - row.exclusion_band
    scenario = scenario_spec("row", crop)
    assert (scenario.headings, scenario.tau, scenario.altitude_levels) == (12, 5, (0, 2))
    assert 0 < views_per_scene(scenario, crop) <= MAX_VIEWS_PER_SCENE
    assert camera_altitudes(scenario, crop) == [row.altitudes[0], row.altitudes[2]]
    parsed = parse_group_name(group_name(scenario, crop))
    assert parsed is not None and (parsed[0].name, parsed[1]) == ("row", crop)


def test_a_crop_without_a_row_refuses_the_row_scenario() -> None:
    with pytest.raises(UserError, match="no row scenario"):
        scenario_spec("row", replace(CROPS["tomato"], row=None))


def test_the_scene_size_check_refuses_what_does_not_fit_before_growing() -> None:
    crop = CROPS["vsp-vine"]
    row = scenario_spec("row", crop)
    needed = scene_bytes(row, crop)
    check_scene_size(row, crop, memory=2 * needed)
    with pytest.raises(UserError) as caught:
        check_scene_size(row, crop, memory=needed)
    assert "\n" not in str(caught.value) and "vsp-vine" in str(caught.value)


@pytest.mark.parametrize("name", list(CROPS))
@pytest.mark.parametrize("scenario", ["sp", "mp", "row"])
def test_every_crop_and_scenario_fits_a_24_gb_machine(name: str, scenario: str) -> None:
    crop = CROPS[name]
    check_scene_size(scenario_spec(scenario, crop), crop, memory=24 * 2**30)

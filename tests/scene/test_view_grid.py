"""The viewpoint grid and its action graph: pure geometry, no renderer."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.scene.specs import CROPS, INVERSE_ACTION, SCENARIOS, SLIP_SIGMA, CropSpec, ScenarioSpec, plant_centres
from davis_ag.scene.view_grid import MP_AIM_DISTANCE, ViewGrid, build_view_grid, grid_axis

#: Views per scene with the real Table 1/Table 2 settings, as documented in the README ("Images
#: per scene"). The paper reports 285-348 views per single-plant scene and 1,128-1,800 per
#: multi-plant scene (Tables 2-3). Our grid is cell-centred with a 3-D exclusion sphere around
#: each plant's centre (view_grid's docstring), which gives these exact counts; single-plant
#: strawberry has 352, 4 views (1 %) above the paper's largest single-plant count: on a 25 cm
#: lattice that sphere admits no count between 336 and 352.
EXPECTED_VIEWS = {
    ("sp", "strawberry"): 352,
    ("sp", "tomato"): 348,
    ("sp", "vine"): 296,
    ("mp", "strawberry"): 1776,
    ("mp", "tomato"): 1776,
    ("mp", "vine"): 1152,
}
#: Single-plant moves as (dx, dy) grid steps; rotations and altitude moves are checked apart.
SP_MOVES = {"forward": (0, 1), "backward": (0, -1), "right": (1, 0), "left": (-1, 0)}


def make_grid(scenario: ScenarioSpec, crop: CropSpec, seed: int = 0) -> ViewGrid:
    return build_view_grid(scenario, crop, plant_centres(scenario, crop), crop.centre_height,
                           np.random.default_rng(seed))


@st.composite
def grids(draw: st.DrawFn) -> tuple[ScenarioSpec, CropSpec, ViewGrid]:
    """A grid of either scenario and any crop, often with a reduced extent and step."""
    scenario = SCENARIOS[draw(st.sampled_from(sorted(SCENARIOS)))]
    crop = CROPS[draw(st.sampled_from(sorted(CROPS)))]
    if draw(st.booleans()):
        step = draw(st.sampled_from([0.25, 0.5, 0.75, 1.0]))
        extent = (draw(st.integers(1, 10)) * step, draw(st.integers(1, 10)) * step)
        levels = draw(st.sampled_from([(0,), (0, 1), (1, 2), (0, 2), (0, 1, 2)]))
        scenario = replace(scenario, extent=extent, step=step, altitude_levels=levels)
    seed = draw(st.integers(0, 2**32 - 1))
    return scenario, crop, make_grid(scenario, crop, seed)


def axes(scenario: ScenarioSpec) -> tuple[np.ndarray, np.ndarray]:
    return grid_axis(scenario.extent[0], scenario.step), grid_axis(scenario.extent[1], scenario.step)


@settings(max_examples=60, deadline=None)
@given(grids())
def test_inverse_moves_return_to_start(case: tuple[ScenarioSpec, CropSpec, ViewGrid]) -> None:
    scenario, _, grid = case
    for view in grid.viewpoints:
        for action in scenario.actions:
            target = grid.pointer(view.index, action)
            if target is not None:
                # The way back is always valid: exclusion and bounds use the nominal grid.
                assert grid.pointer(target, INVERSE_ACTION[action]) == view.index, (view, action)


@settings(max_examples=60, deadline=None)
@given(grids())
def test_every_view_and_pointer_is_inside_the_grid_and_outside_exclusion(
    case: tuple[ScenarioSpec, CropSpec, ViewGrid],
) -> None:
    scenario, crop, grid = case
    xs, ys = axes(scenario)
    centres = np.asarray(plant_centres(scenario, crop))
    altitudes = [crop.altitudes[i] for i in scenario.altitude_levels]
    for view in grid.viewpoints:
        x, y, z = view.nominal
        assert abs(x) <= scenario.extent[0] / 2 and abs(y) <= scenario.extent[1] / 2
        assert x == pytest.approx(xs[view.ix]) and y == pytest.approx(ys[view.iy])
        assert z == altitudes[view.level]
        assert np.linalg.norm(centres - view.nominal, axis=1).min() >= crop.exclusion_radius
        for action in scenario.actions:
            target = grid.pointer(view.index, action)
            assert target is None or 0 <= target < len(grid.viewpoints)
    # Every allowed grid cell holds a view: nothing outside the exclusion zone is left out.
    stations = {(v.ix, v.iy, v.level) for v in grid.viewpoints}
    for level, z in enumerate(altitudes):
        for iy, y in enumerate(ys):
            for ix, x in enumerate(xs):
                free = np.linalg.norm(centres - (x, y, z), axis=1).min() >= crop.exclusion_radius
                assert ((ix, iy, level) in stations) == free


@settings(max_examples=40, deadline=None)
@given(grids())
def test_moves_go_one_step_the_documented_way(case: tuple[ScenarioSpec, CropSpec, ViewGrid]) -> None:
    scenario, _, grid = case
    views = grid.viewpoints
    for view in views:
        for action in scenario.actions:
            target = grid.pointer(view.index, action)
            if target is None:
                continue
            to = views[target]
            if action in ("up", "down"):
                assert (to.ix, to.iy, to.heading) == (view.ix, view.iy, view.heading)
                assert to.level == view.level + (1 if action == "up" else -1)
                assert to.nominal[2] > view.nominal[2] if action == "up" else to.nominal[2] < view.nominal[2]
            elif action.startswith("rotate"):
                assert (to.ix, to.iy, to.level) == (view.ix, view.iy, view.level)
            elif scenario.headings == 1:
                assert (to.ix - view.ix, to.iy - view.iy) == SP_MOVES[action]
                assert to.level == view.level
            else:
                # Forward goes along the grid axis nearest the heading; left is 90 deg CCW of it.
                turn = {"forward": 0, "left": 90, "backward": 180, "right": 270}[action]
                direction = math.radians(view.yaw + turn)
                step = np.subtract(to.nominal[:2], view.nominal[:2]) / scenario.step
                assert np.linalg.norm(step) == pytest.approx(1.0)
                assert step @ (math.cos(direction), math.sin(direction)) > math.cos(math.radians(45))
                assert (to.level, to.heading) == (view.level, view.heading)


@pytest.mark.parametrize(("scenario", "crop"), sorted(EXPECTED_VIEWS))
def test_views_per_scene(scenario: str, crop: str) -> None:
    grid = make_grid(SCENARIOS[scenario], CROPS[crop])
    assert len(grid.viewpoints) == EXPECTED_VIEWS[scenario, crop]
    paper_range = (285, 348) if scenario == "sp" else (1128, 1800)
    # Within the paper's range, allowing our strawberry convention's 1 % (see EXPECTED_VIEWS).
    assert paper_range[0] <= len(grid.viewpoints) <= paper_range[1] * 1.02


def test_slip_is_gaussian_with_the_papers_sigma_and_shared_by_headings() -> None:
    offsets = []
    for seed in range(8):
        for scenario in SCENARIOS.values():
            grid = make_grid(scenario, CROPS["tomato"], seed)
            by_station: dict[tuple[int, int, int], tuple[float, ...]] = {}
            for view in grid.viewpoints:
                slip = tuple(np.subtract(view.position, view.nominal))
                assert slip[2] == 0.0  # altitude does not slip
                # Turning in place does not slip: every heading of a station shares its offset.
                assert by_station.setdefault((view.ix, view.iy, view.level), slip) == slip
            offsets.extend(s[:2] for s in by_station.values())
    offsets = np.asarray(offsets)
    assert len(offsets) > 3500
    assert np.abs(offsets.mean(axis=0)).max() < 0.003
    assert offsets.std(axis=0) == pytest.approx([SLIP_SIGMA, SLIP_SIGMA], rel=0.06)


def test_slip_follows_the_seed() -> None:
    scenario, crop = SCENARIOS["sp"], CROPS["strawberry"]
    same = [make_grid(scenario, crop, 7).viewpoints, make_grid(scenario, crop, 7).viewpoints]
    assert same[0] == same[1]
    other = make_grid(scenario, crop, 8).viewpoints
    assert [v.position for v in other] != [v.position for v in same[0]]
    assert [v.nominal for v in other] == [v.nominal for v in same[0]]


@pytest.mark.parametrize("crop", sorted(CROPS))
def test_single_plant_cameras_aim_at_the_plant(crop: str) -> None:
    spec = CROPS[crop]
    aim = np.array([0.0, 0.0, spec.centre_height])
    grid = make_grid(SCENARIOS["sp"], spec, seed=3)
    for view in grid.viewpoints:
        assert view.heading == 0
        to_plant = aim - view.position
        distance = np.linalg.norm(to_plant)
        # The optical axis passes through the aim point (yaw and pitch are rounded to 1e-4 deg).
        assert np.allclose(view.look_at(distance), aim, atol=distance * math.radians(2e-4))
        assert view.pitch < 0 or view.position[2] <= aim[2]


@pytest.mark.parametrize("crop", sorted(CROPS))
def test_multi_plant_headings_are_30_degrees_apart_and_rotation_only_turns(crop: str) -> None:
    spec = CROPS[crop]
    grid = make_grid(SCENARIOS["mp"], spec, seed=5)
    views = grid.viewpoints
    for view in views:
        assert view.yaw == pytest.approx(30.0 * view.heading)
        expected_pitch = math.degrees(math.atan2(spec.centre_height - view.position[2], MP_AIM_DISTANCE))
        assert view.pitch == pytest.approx(expected_pitch, abs=1e-4)
        for action, turn in (("rotate_ccw", 30.0), ("rotate_cw", -30.0)):
            target = grid.pointer(view.index, action)
            assert target is not None  # turning in place is always possible
            to = views[target]
            assert (to.yaw - view.yaw - turn) % 360.0 == pytest.approx(0.0, abs=1e-6) or \
                (to.yaw - view.yaw - turn) % 360.0 == pytest.approx(360.0, abs=1e-6)
            assert (to.position, to.nominal, to.pitch, to.level) == (view.position, view.nominal, view.pitch, view.level)
    # Twelve rotations in one direction come back to the start.
    index = 0
    for _ in range(12):
        index = grid.pointer(index, "rotate_ccw")
    assert index == 0


@settings(max_examples=30, deadline=None)
@given(grids())
def test_image_names_are_unique_and_numbered_from_0001(case: tuple[ScenarioSpec, CropSpec, ViewGrid]) -> None:
    _, _, grid = case
    names = [v.image_name for v in grid.viewpoints]
    assert names == [f"{i:04d}.jpeg" for i in range(1, len(names) + 1)]
    assert [v.index for v in grid.viewpoints] == list(range(len(names)))
    # Altitude first, then y, then x, then heading.
    order = [(v.level, v.iy, v.ix, v.heading) for v in grid.viewpoints]
    assert order == sorted(order) and len(set(order)) == len(order)


@settings(max_examples=30, deadline=None)
@given(grids())
def test_pointers_name_images_and_give_empty_string_for_invalid_moves(
    case: tuple[ScenarioSpec, CropSpec, ViewGrid],
) -> None:
    scenario, _, grid = case
    names = {v.image_name for v in grid.viewpoints}
    for view in grid.viewpoints:
        pointers = grid.pointers(view.index)
        assert tuple(pointers) == scenario.actions
        for action, name in pointers.items():
            target = grid.pointer(view.index, action)
            if target is None:
                assert name == ""
            else:
                assert name in names and name == grid.viewpoints[target].image_name


def test_grid_edges_and_exclusion_give_empty_pointers() -> None:
    grid = make_grid(SCENARIOS["sp"], CROPS["strawberry"])
    pointers = [grid.pointers(v.index) for v in grid.viewpoints]
    for action in ("forward", "backward", "left", "right", "up", "down"):
        assert any(p[action] == "" for p in pointers), action
        assert any(p[action] != "" for p in pointers), action
    # Next to the exclusion zone a move towards the plant is invalid although the grid goes on.
    columns = len(grid_axis(SCENARIOS["sp"].extent[0], SCENARIOS["sp"].step))
    blocked = [v for v in grid.viewpoints if v.ix + 1 < columns and grid.pointer(v.index, "right") is None]
    assert blocked and all(v.nominal[0] < 0 for v in blocked)

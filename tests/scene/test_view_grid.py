"""The viewpoint grid and its action graph: pure geometry, no renderer."""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.formats.layout import published_pointers, view_name
from davis_ag.scene.specs import (
    CROPS,
    INVERSE_ACTION,
    SCENARIOS,
    SLIP_SIGMA,
    CropSpec,
    ScenarioSpec,
    camera_altitudes,
    plant_centres,
    scenario_spec,
)
from davis_ag.scene.view_grid import (
    MP_AIM_DISTANCE,
    ViewGrid,
    build_view_grid,
    lattice_point,
    lattice_shape,
)

#: Table 3 of the paper: images / scenes per crop and scenario, each an exact whole number.
TABLE_3 = {
    ("sp", "strawberry"): (24_510, 86),
    ("sp", "tomato"): (45_240, 130),
    ("sp", "vine"): (63_336, 182),
    ("mp", "strawberry"): (86_856, 77),
    ("mp", "tomato"): (203_400, 113),
    ("mp", "vine"): (79_200, 44),
}
#: Single-plant moves as (dx, dy) grid steps; rotations and altitude moves are checked apart.
SP_MOVES = {"forward": (0, 1), "backward": (0, -1), "right": (1, 0), "left": (-1, 0)}


def make_grid(scenario: ScenarioSpec, crop: CropSpec, seed: int = 0) -> ViewGrid:
    return build_view_grid(
        scenario, crop, plant_centres(scenario, crop), crop.centre_height, np.random.default_rng(seed)
    )


@st.composite
def grids(draw: st.DrawFn) -> tuple[ScenarioSpec, CropSpec, ViewGrid]:
    """A grid of either scenario and any crop, the crop's own or with a reduced extent and step."""
    crop = CROPS[draw(st.sampled_from(sorted(CROPS)))]
    scenario = scenario_spec(draw(st.sampled_from(sorted(SCENARIOS))), crop)
    if draw(st.booleans()):
        step = draw(st.sampled_from([0.25, 0.5, 0.75, 1.0]))
        extent = (draw(st.integers(1, 10)) * step, draw(st.integers(1, 10)) * step)
        levels = draw(st.sampled_from([(0,), (0, 1), (1, 2), (0, 2), (0, 1, 2)]))
        scenario = replace(scenario, extent=extent, step=step, altitude_levels=levels)
    seed = draw(st.integers(0, 2**32 - 1))
    return scenario, crop, make_grid(scenario, crop, seed)


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
    shape = lattice_shape(scenario)
    stems = np.asarray(plant_centres(scenario, crop))[:, :2]
    altitudes = camera_altitudes(scenario, crop)
    half_x, half_y = scenario.extent[0] / 2, scenario.extent[1] / 2

    def free(x: float, y: float) -> bool:
        """No camera within a plant's exclusion radius, nor inside a row (its band)."""
        if scenario.name == "row":
            return abs(y) > crop.row.exclusion_band + 1e-9
        return bool(np.hypot(*(stems - (x, y)).T).min() > crop.exclusion_radius + 1e-9)

    for view in grid.viewpoints:
        x, y, z = view.nominal
        # Even rows lie within the extent; odd rows reach half a step further east.
        assert -half_x - 1e-9 <= x <= half_x + (scenario.step / 2 if view.iy % 2 else 0.0) + 1e-9
        assert abs(y) <= half_y + 1e-9
        assert (x, y) == pytest.approx(lattice_point(view.ix, view.iy, shape, scenario.step))
        assert z == altitudes[view.level]
        assert free(x, y)
        for action in scenario.actions:
            target = grid.pointer(view.index, action)
            if target is not None:
                to = grid.viewpoints[target].nominal
                assert 0 <= target < len(grid.viewpoints)
                assert free(*to[:2])
                if scenario.name == "row":  # no move crosses the row
                    assert np.sign(to[1]) == np.sign(y)
    # Every allowed lattice position holds a view at every altitude: nothing else is left out.
    stations = {(v.ix, v.iy, v.level) for v in grid.viewpoints}
    for level in range(len(altitudes)):
        for iy in range(shape[1]):
            for ix in range(shape[0]):
                x, y = lattice_point(ix, iy, shape, scenario.step)
                assert ((ix, iy, level) in stations) == free(x, y)


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
            else:
                assert (to.level, to.heading) == (view.level, view.heading)
                step = np.subtract(to.nominal[:2], view.nominal[:2]) / scenario.step
                if to.iy == view.iy:
                    # Along a row: exactly one step east or west.
                    assert abs(step[0]) == pytest.approx(1.0) and step[1] == 0.0
                else:
                    # To the next row at the same column index: the zigzag of the staggered
                    # lattice, half a step east from an even row, west from an odd one.
                    assert to.ix == view.ix and abs(step[1]) == pytest.approx(1.0)
                    assert step[0] == pytest.approx(0.5 if view.iy % 2 == 0 else -0.5)
                if scenario.headings == 1:
                    assert (to.ix - view.ix, to.iy - view.iy) == SP_MOVES[action]
                else:
                    # Forward goes along the lattice axis nearest the heading; left is 90 deg CCW
                    # of it: the move is within 45 deg of that axis plus the zigzag's 26.6 deg.
                    turn = {"forward": 0, "left": 90, "backward": 180, "right": 270}[action]
                    direction = math.radians(view.yaw + turn)
                    cosine = step @ (math.cos(direction), math.sin(direction)) / np.linalg.norm(step)
                    assert cosine > math.cos(math.radians(45 + math.degrees(math.atan(0.5))) + 1e-9)


@pytest.mark.parametrize(("scenario", "crop"), sorted(TABLE_3))
def test_views_per_scene_are_table_3s(scenario: str, crop: str) -> None:
    images, scenes = TABLE_3[scenario, crop]
    assert images % scenes == 0
    spec = CROPS[crop]
    grid = make_grid(scenario_spec(scenario, spec), spec)
    assert len(grid.viewpoints) == images // scenes
    # Table 2: 285-348 images per single-plant scene, 1,128-1,800 per multi-plant scene.
    low, high = (285, 348) if scenario == "sp" else (1128, 1800)
    assert low <= len(grid.viewpoints) <= high


def test_single_plant_strawberry_positions_are_the_originals_fig_2() -> None:
    """The original's Fig. 2 (shared/ref): 95 positions per altitude, x and y from -1.25 to
    1.25 m every 0.25 m, every other row shifted 0.125 m east, nothing within 0.75 m of the
    plant, (0, +-0.75) missing, the same positions at every altitude."""
    crop = CROPS["strawberry"]
    grid = make_grid(scenario_spec("sp", crop), crop)
    per_level = [{v.nominal[:2] for v in grid.viewpoints if v.level == level} for level in range(3)]
    assert per_level[0] == per_level[1] == per_level[2] and len(per_level[0]) == 95
    xs, ys = (sorted({round(p[axis], 6) for p in per_level[0]}) for axis in (0, 1))
    assert ys == pytest.approx(np.arange(-1.25, 1.26, 0.25))
    assert xs[0] == pytest.approx(-1.25) and xs[-1] == pytest.approx(1.375)
    for y in ys:
        row = sorted(p[0] for p in per_level[0] if round(p[1], 6) == y)
        shifted = round((y + 1.25) / 0.25) % 2 == 1
        assert row[0] == pytest.approx(-1.25 + (0.125 if shifted else 0.0))
    assert (0.0, 0.75) not in per_level[0] and (0.0, -0.75) not in per_level[0]
    assert min(math.hypot(*p) for p in per_level[0]) > 0.75


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
            assert (to.yaw - view.yaw - turn) % 360.0 == pytest.approx(0.0, abs=1e-6) or (
                to.yaw - view.yaw - turn
            ) % 360.0 == pytest.approx(360.0, abs=1e-6)
            assert (to.position, to.nominal, to.pitch, to.level) == (
                view.position,
                view.nominal,
                view.pitch,
                view.level,
            )
    # Twelve rotations in one direction come back to the start.
    index = 0
    for _ in range(12):
        index = grid.pointer(index, "rotate_ccw")
    assert index == 0


@settings(max_examples=30, deadline=None)
@given(grids())
def test_image_names_are_unique_and_numbered_from_0001(case: tuple[ScenarioSpec, CropSpec, ViewGrid]) -> None:
    _, _, grid = case
    names = [view_name(v.number) for v in grid.viewpoints]
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
    names = {view_name(v.number) for v in grid.viewpoints}
    for view in grid.viewpoints:
        pointers = published_pointers(grid, view.index)
        assert tuple(pointers) == scenario.actions
        for action, name in pointers.items():
            target = grid.pointer(view.index, action)
            if target is None:
                assert name == ""
            else:
                assert name in names and name == view_name(grid.viewpoints[target].number)


def test_grid_edges_and_exclusion_give_empty_pointers() -> None:
    grid = make_grid(scenario_spec("sp", CROPS["strawberry"]), CROPS["strawberry"])
    pointers = [published_pointers(grid, v.index) for v in grid.viewpoints]
    for action in ("forward", "backward", "left", "right", "up", "down"):
        assert any(p[action] == "" for p in pointers), action
        assert any(p[action] != "" for p in pointers), action
    # Next to the exclusion zone a move towards the plant is invalid although the grid goes on.
    columns = lattice_shape(scenario_spec("sp", CROPS["strawberry"]))[0]
    blocked = [v for v in grid.viewpoints if v.ix + 1 < columns and grid.pointer(v.index, "right") is None]
    assert blocked and all(v.nominal[0] < 0 for v in blocked)


def test_the_view_shown_in_the_docs_faces_the_plants_from_their_middle() -> None:
    from davis_ag.scene.view_grid import view_facing

    for name in ("strawberry", "apple-wall"):
        crop = CROPS[name]
        for scenario_name, level in (("sp", 1), ("row", 1)):
            scenario = scenario_spec(scenario_name, crop)
            grid = make_grid(scenario, crop)
            view = grid.viewpoints[view_facing(scenario, crop, level, 90.0) - 1]
            assert view.level == level and abs(view.yaw - 90.0) < 10.0
            assert view.nominal[1] < 0 and abs(view.nominal[0]) <= scenario.step

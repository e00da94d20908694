"""The growers' structures of a row: where their posts and wires stand, and that Helios labels them."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from davis_ag.errors import UserError
from davis_ag.scene.build import NEAR_SIZE
from davis_ag.scene.crop_spec import RowSpec
from davis_ag.scene.organs import BARE_ORGAN_NAMES, ORGAN_NAMES, STRUCTURE, scene_organ_names
from davis_ag.scene.specs import CROPS
from davis_ag.scene.structures import (
    SYSTEMS,
    check_structures,
    structure_parts,
    support_positions,
)

#: Parts that stand on the ground between the plants (strings run up each plant's stem on purpose).
STANDING = ("post", "stake")


@pytest.mark.parametrize("name", sorted(SYSTEMS))
def test_supports_stand_between_the_plants_never_on_a_stem(name: str) -> None:
    crop = CROPS[name]
    assert crop.row is not None
    stems = np.array(crop.row.stems())
    parts = structure_parts("row", crop, "default")
    assert parts, f"{name} has a system but built nothing"
    for part in parts:
        if part.kind in STANDING:
            x, y, _ = part.nodes[0]
            nearest = np.min(np.hypot(stems[:, 0] - x, stems[:, 1] - y))
            assert nearest >= crop.row.in_row_spacing / 2 - 1e-6, (name, part)


@pytest.mark.parametrize("name", sorted(SYSTEMS))
def test_wires_span_the_planted_stretch_and_end_on_supports(name: str) -> None:
    crop = CROPS[name]
    row = crop.row
    assert row is not None
    half = (row.plants + 2) * row.in_row_spacing / 2
    parts = structure_parts("row", crop, "default")
    stems_x = sorted({x for x, _ in row.stems()})
    assert -half < stems_x[0] and stems_x[-1] < half  # every plant lies within the wires
    supports = {round(p.nodes[0][0], 6) for p in parts if p.kind in STANDING}
    for part in parts:
        xs = [n[0] for n in part.nodes]
        assert min(xs) >= -half - 1e-9 and max(xs) <= half + 1e-9
        if part.kind in ("wire", "string", "pipe") and len({round(x, 6) for x in xs}) > 1:
            assert math.isclose(min(xs), -half) and math.isclose(max(xs), half), (name, part.kind)
            if supports:  # trellises tie their wires off on the end posts (greenhouse wires hang from the roof)
                assert {round(-half, 6), round(half, 6)} <= supports


@pytest.mark.parametrize("name", sorted(SYSTEMS))
def test_every_part_lies_on_or_above_the_near_soil(name: str) -> None:
    for part in structure_parts("row", CROPS[name], "default"):
        points = np.array(part.nodes)
        assert points[:, 2].min() >= 0.0 and part.radius > 0 and len(points) >= 2
        assert np.abs(points[:, :2]).max() <= NEAR_SIZE / 2
        assert all(0.0 <= c <= 1.0 for c in part.colour)


def test_the_vsp_trellis_has_its_fruiting_and_catch_wires_and_a_post_in_front_of_the_cameras() -> None:
    parts = structure_parts("row", CROPS["vsp-vine"], "default")
    centre_wires = sorted(round(p.nodes[0][2], 2) for p in parts if p.kind == "wire" and abs(p.nodes[0][1]) < 0.1)
    assert centre_wires == [0.36, 0.8, 1.22, 1.22, 1.52, 1.52]  # drip, fruiting, two pairs of catch wires
    assert any(p.kind == "post" and p.nodes[0][:2] == (0.0, 0.0) for p in parts)


def test_the_greenhouse_row_has_a_string_per_plant_and_a_pipe_rail_in_every_alley() -> None:
    crop = CROPS["capsicum"]
    assert crop.row is not None
    parts = structure_parts("row", crop, "default")
    assert sum(p.kind == "string" for p in parts) == len(crop.row.stems())
    pipes = sorted(p.nodes[0][1] for p in parts if p.kind == "pipe")
    assert len(pipes) == 8  # four alleys (between and beside the three rows), two pipes each
    gauges = {round(b - a, 3) for a, b in zip(pipes[::2], pipes[1::2], strict=True)}
    assert gauges == {0.55}


@pytest.mark.parametrize(
    ("scenario", "crop", "setting"),
    [
        ("sp", "vsp-vine", "default"),
        ("mp", "capsicum", "default"),
        ("row", "vsp-vine", "none"),
        ("row", "almond", "default"),
    ],
)
def test_no_structure_outside_a_row_with_a_system_or_when_asked_for_none(
    scenario: str, crop: str, setting: str
) -> None:
    assert structure_parts(scenario, CROPS[crop], setting) == []


def test_an_unknown_setting_is_one_clear_line() -> None:
    with pytest.raises(UserError, match="unknown structures 'some': choose none or default"):
        check_structures("some")


def test_a_scene_without_structures_records_the_class_table_of_before() -> None:
    assert scene_organ_names(False) == BARE_ORGAN_NAMES == ORGAN_NAMES[:STRUCTURE]
    assert scene_organ_names(True)[STRUCTURE] == "structure" == ORGAN_NAMES[STRUCTURE]
    assert scene_organ_names(True)[-1] == "cover"


@given(
    plants=st.integers(1, 12),
    spacing=st.floats(0.2, 6.0),
    every=st.integers(1, 10),
)
def test_support_positions_hold_the_ends_and_a_support_near_the_middle(plants: int, spacing: float, every: int) -> None:
    row = RowSpec("test", spacing, 3.0, plants, 1.0, (0.5, 1.0, 1.5), "test")
    xs = support_positions(row, every)
    half = (plants + 2) * spacing / 2
    assert (
        xs == sorted(set(xs)) and math.isclose(xs[0], -half, abs_tol=1e-8) and math.isclose(xs[-1], half, abs_tol=1e-8)
    )
    assert min(abs(x) for x in xs) <= spacing / 2 + 1e-9  # the cameras' stretch sees one
    interior = xs[1:-1]
    for a, b in itertools.pairwise(interior):
        assert math.isclose(b - a, every * spacing, rel_tol=1e-6)


def test_helios_draws_every_part_as_primitives_labelled_structure() -> None:
    from davis_ag.scene.plants import require_native_helios

    try:
        require_native_helios()
    except UserError as error:
        pytest.skip(str(error))
    from pyhelios import Context

    from davis_ag.scene.organs import ORGAN_DATA
    from davis_ag.scene.structures import add_structures

    context = Context()
    parts = structure_parts("row", CROPS["vsp-vine"], "default")
    uuids = add_structures(context, parts)
    assert sorted(uuids) == sorted(int(u) for u in context.getAllUUIDs())
    assert set(np.asarray(context.getPrimitiveDataArray(uuids, ORGAN_DATA)).tolist()) == {STRUCTURE}
    top = max(max(context.getPrimitiveVertices(u), key=lambda v: v.z).z for u in uuids)
    assert top == pytest.approx(1.83, abs=0.01)  # the posts' tops, the highest part

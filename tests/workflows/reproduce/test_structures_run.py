"""The ``structures`` run: its rows bare and with their structures, each a cell scored on its own
dataset, and the page that sets them side by side."""

from __future__ import annotations

import json
import shutil
from dataclasses import asdict, replace
from pathlib import Path

import pytest

from davis_ag.workflows.reproduce.cells import evaluate_cell
from davis_ag.workflows.reproduce.configs import CONFIGS
from davis_ag.workflows.reproduce.pages.structures import write_structures_page
from davis_ag.workflows.reproduce.run import stage_recorder
from davis_ag.workflows.reproduce.state import RunState
from davis_ag.workflows.reproduce.structure_cells import structure_cells
from real_scenes import ROBOT_VINE, generate_config

PAIRS = [("sp", "vine")]


def test_the_configuration_makes_four_rows_bare_and_with_structures() -> None:
    config = CONFIGS["structures"]
    assert config.page == "structures" and config.structures == "default" and config.robots == ()
    assert [crop for _, crop in config.pairs] == ["apple-wall", "vsp-vine", "capsicum", "wye-vine"]
    cells = structure_cells(Path("run"), config, config.pairs)
    assert [heading for heading, _ in cells[:1]] == ["bare"] and cells[-1][0] == "with structures"
    assert {cell.root.name for _, cell in cells} == {"dataset-bare", "dataset"}
    assert len({cell.key for _, cell in cells}) == 2 * len(config.pairs)


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory):
    # One real scene stands in for both variants: what is tested here is the run's bookkeeping
    # (each cell on its own dataset, its own results file, the page), not what structures change.
    out = tmp_path_factory.mktemp("structures-run")
    source = generate_config(tmp_path_factory, "vine", ROBOT_VINE)
    for folder in ("dataset-bare", "dataset"):
        shutil.copytree(source, out / folder)
    config = replace(CONFIGS["structures"], episodes=12, sessions=1, learners=("a2c",))
    state = RunState(config=json.loads(json.dumps(asdict(replace(config, pairs=tuple(PAIRS))))))
    record = stage_recorder(state, out / "state.json")
    found = {
        cell.key: evaluate_cell(config, out, cell, state, record) for _, cell in structure_cells(out, config, PAIRS)
    }
    return out, config, state, found


def test_each_variant_is_scored_on_its_own_dataset(run) -> None:
    out, _, _, found = run
    assert set(found) == {"sp-vine-bare", "sp-vine-structures"} and all(found.values())
    assert (out / "results" / "sp-vine-bare.json").is_file() and (out / "results" / "sp-vine-structures.json").is_file()
    assert found["sp-vine-bare"].protocol.dataset != found["sp-vine-structures"].protocol.dataset


def test_the_page_sets_the_structures_beside_the_bare_row(run, tmp_path: Path) -> None:
    out, config, state, found = run
    page = tmp_path / "crops.md"
    page.write_text("# Crops\n\n<!-- structures-run:start -->\nold\n<!-- structures-run:end -->\n\ntail\n")
    write_structures_page(page, config, state, out, PAIRS)
    text = page.read_text()
    assert "\nold\n" not in text and "tail" in text
    assert "| method | bare | with structures |" in text
    starts = found["sp-vine-structures"].protocol.starts
    assert f"| eligible test starts | {starts:,} | {starts:,} |" in text
    assert "A2C not yet trained" in text and "split rule `scenes`" in text


def test_the_status_lists_both_variants(run) -> None:
    from davis_ag.workflows.reproduce.status import run_status

    out, _, state, _ = run
    state.save(out / "state.json")
    _, stages = run_status(out)
    names = [s.stage for s in stages]
    assert "sp-vine-bare: baselines" in names and "sp-vine-structures: train A2C" in names
    assert next(s for s in stages if s.stage == "sp-vine-structures: baselines").done

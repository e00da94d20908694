"""The ``robot`` run: every cell (a row without a robot and with each robot) evaluated, a robot
that reaches no start recorded, cells reused, learners trained under the robot, and the page."""

from __future__ import annotations

import os
import shutil
from dataclasses import replace
from pathlib import Path

import pytest

from davis_ag.workflows.reproduce.cells import evaluate_cell, results_path
from davis_ag.workflows.reproduce.configs import CONFIGS
from davis_ag.workflows.reproduce.pages.robot import write_robot_page
from davis_ag.workflows.reproduce.robot_cells import robot_cell
from davis_ag.workflows.reproduce.run import stage_recorder
from davis_ag.workflows.reproduce.state import RunState
from real_scenes import ROBOT_VINE, generate_config

PAIRS = [("sp", "vine")]


def _tall_robot(folder: Path) -> str:
    """The UR5 trolley mounted 4 m up: it reaches no view of the vine."""
    text = (Path(__file__).parents[3] / "src/davis_ag/robot/robots/ur5-trolley.yaml").read_text()
    path = folder / "tall.yaml"
    path.write_text(
        text.replace("name: ur5-trolley", "name: tall").replace("mount_height_m: 0.69", "mount_height_m: 4.0")
    )
    return str(path)


@pytest.fixture(scope="module")
def run(tmp_path_factory: pytest.TempPathFactory):
    out = tmp_path_factory.mktemp("robot-run")
    shutil.copytree(generate_config(tmp_path_factory, "vine", ROBOT_VINE), out / "dataset")
    config = replace(
        CONFIGS["robot"], episodes=12, sessions=1, learners=("a2c",), robots=("ur10-lift", _tall_robot(out))
    )
    state = RunState()
    record = stage_recorder(state, out / "state.json")
    cells = {
        robot: evaluate_cell(config, out, robot_cell(out, "sp", "vine", robot), state, record)
        for robot in (None, *config.robots)
    }
    return out, config, state, record, cells


def test_the_configuration_plays_three_rows_with_each_robot() -> None:
    config = CONFIGS["robot"]
    assert config.page == "robot" and config.learners == ("a2c", "ppo")
    assert [crop for _, crop in config.pairs] == ["apple-wall", "vsp-vine", "capsicum"]
    assert {"ur5-trolley", "ur10-lift", "panda-trolley"} <= set(config.robots)
    assert config.mp_scenes >= 2  # one scene trains, one tests


def test_every_cell_is_evaluated_under_its_robot_and_an_unreached_one_is_recorded(run) -> None:
    out, config, state, _, cells = run
    bare, lift, tall = (cells[r] for r in (None, *config.robots))
    assert bare is not None and bare.protocol.robot is None
    assert lift is not None and lift.protocol.robot["name"] == "ur10-lift"
    assert lift.policies["Oracle"].seconds.mean > 0 and bare.policies["Oracle"].seconds is None
    assert tall is None and "reaches no eligible start" in state.stages["sp-vine-tall: unreached"].note
    assert not results_path(out, robot_cell(out, "sp", "vine", config.robots[1])).exists()


def test_a_cell_of_the_same_protocol_is_reused(run) -> None:
    out, config, state, record, _ = run
    path = results_path(out, robot_cell(out, "sp", "vine", "ur10-lift"))
    before = os.stat(path).st_mtime_ns
    again = evaluate_cell(config, out, robot_cell(out, "sp", "vine", "ur10-lift"), state, record)
    assert again is not None and os.stat(path).st_mtime_ns == before


def test_the_page_sets_each_robot_beside_none_between_its_markers(run, tmp_path: Path) -> None:
    out, config, state, _, cells = run
    page = tmp_path / "robot.md"
    page.write_text("# A robot\n\nprose\n\n<!-- robot-run:start -->\nold\n<!-- robot-run:end -->\n\ntail\n")
    write_robot_page(page, config, state, out, PAIRS)
    text = page.read_text()
    assert "prose" in text and "tail" in text and "\nold\n" not in text
    assert "| method | no robot | ur10-lift | tall |" in text
    oracle = next(line for line in text.splitlines() if line.startswith("| Oracle |"))
    drop = cells["ur10-lift"].policies["Oracle"].oer_tau.mean - cells[None].policies["Oracle"].oer_tau.mean
    assert f"({'+' if drop >= 0 else ''}{drop:.3f})".replace("0.", ".") in oracle
    assert "tall: " in text and "reaches no eligible start" in text
    assert "A2C not yet trained" in text


@pytest.mark.slow
def test_a_learner_trained_under_the_robot_joins_its_cell(run) -> None:
    from davis_ag.workflows.reproduce.learners import model_path, train_learner

    out, config, state, record, _ = run
    model = model_path(out, "sp-vine-ur10-lift", "a2c")
    short = replace(config, n_envs=2)
    train_learner("a2c", out / "dataset", "sp", "vine", model, 32, short, robot="ur10-lift", arch="pooled")
    results = evaluate_cell(short, out, robot_cell(out, "sp", "vine", "ur10-lift"), state, record)
    assert results is not None and "A2C" in results.policies and results.policies["A2C"].seconds.mean >= 0


def test_the_status_lists_every_cell_and_an_unreached_robot(run) -> None:
    import json
    from dataclasses import asdict

    from davis_ag.workflows.reproduce.status import run_status

    out, config, state, _, _ = run
    state.config = json.loads(json.dumps(asdict(replace(config, pairs=tuple(PAIRS)))))
    state.save(out / "state.json")
    _, stages = run_status(out)
    by_name = {s.stage: s for s in stages}
    assert by_name["sp-vine-none: baselines"].done and by_name["sp-vine-ur10-lift: baselines"].done
    assert by_name["sp-vine-tall: baselines"].done and "reaches no" in by_name["sp-vine-tall: baselines"].progress
    assert "sp-vine-tall: train A2C" not in by_name and "sp-vine-tall: evaluate" not in by_name
    assert {"sp-vine-none: train A2C", "sp-vine-ur10-lift: train A2C", "sp-vine-ur10-lift: evaluate"} <= set(by_name)

"""A run's state.json as a typed model: none yet is an empty run, a damaged one is one line, a
state round-trips without episodes, and a state written before the model (each evaluation kept
as a reduced summary) is read again from the run's results files, so a run in progress resumes."""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path
from typing import Any

import numpy as np
import pytest

from davis_ag.benchmark.exact import BEST_FIXED
from davis_ag.benchmark.results import EvaluationResults, load_results
from davis_ag.errors import UserError
from davis_ag.workflows.reproduce.configs import CONFIGS
from davis_ag.workflows.reproduce.state import RunState, StageRecord, without_episodes


class Wanderer:
    """A stand-in learner: seeded random moves, under a learner's row name."""

    def __init__(self, name: str) -> None:
        self.name = name
        self.rng = np.random.default_rng(0)

    def reset(self, seed: int | None = None) -> None:
        self.rng = np.random.default_rng(seed)

    def act(self, observation: Any, info: dict[str, Any]) -> int:
        return int(self.rng.integers(7))


@pytest.fixture(scope="module")
def evaluated(sp_root: Path) -> EvaluationResults:
    """A real evaluation on both scenes (split ``all``) of A2C and PPO stand-ins beside Rand and the
    Best fixed action, episodes kept, as the run writes it to ``results/GROUP.json``."""
    from davis_ag.benchmark import evaluate

    return evaluate(
        [Wanderer("A2C"), Wanderer("PPO")], sp_root, "sp", split="all", sessions=2, episodes=6, baselines=["Rand"]
    )


def old_summary(results: EvaluationResults) -> dict[str, Any]:
    """An evaluation as state.json kept it before the typed state: metrics without their sessions,
    no episodes, each learner's gap to the Best fixed action under a key of its own."""
    data = results.as_json()
    policies = {
        name: {
            **{
                key: {s: row[key][s] for s in ("mean", "std", "sem")}
                for key in ("oer_tau", "reward", "length", "oer_0")
            },
            **{key: row[key] for key in ("exact", "action_counts", "play", "action") if key in row},
        }
        for name, row in data["policies"].items()
    }
    summary = {"protocol": data["protocol"], "policies": policies}
    for learner in ("A2C", "PPO"):
        summary[f"{learner.lower()}_vs_best_fixed"] = data["policies"][learner]["paired"][BEST_FIXED]
    return summary


def test_a_folder_without_a_state_is_a_run_not_started(tmp_path: Path) -> None:
    state = RunState.load(tmp_path / "state.json")
    assert state == RunState() and state.config is None and not state.results
    assert not (tmp_path / "state.json").exists()  # reading writes nothing


@pytest.mark.parametrize(
    "text",
    [
        "{not json",
        "[1, 2]",
        '{"config": "small"}',
        '{"stages": {"sp-strawberry: generate": {"note": "no seconds"}}}',
        '{"results": [1]}',
        '{"scene_folders": {"sp-strawberry": "Single-Strawberry/000"}}',
    ],
)
def test_a_damaged_state_is_one_line_and_left_alone(tmp_path: Path, text: str) -> None:
    path = tmp_path / "state.json"
    path.write_text(text)
    with pytest.raises(UserError) as refused:
        RunState.load(path)
    message = str(refused.value)
    assert message.startswith(f"{path}: not a reproduce state file (damaged or not JSON): move it aside")
    assert "\n" not in message and path.read_text() == text


def test_a_state_from_before_0_2_0_keeps_its_stages_without_its_scene_timings(tmp_path: Path) -> None:
    """Runs before the clock (clock.json) timed each scene under ``scenes``; their state still reads."""
    path = tmp_path / "state.json"
    stage = {"seconds": 61.5, "note": "2 scenes", "code": "0.1.0+abc"}
    scene = {"seconds": 30.2, "views": 348, "s_per_view": 0.08}
    path.write_text(
        json.dumps({"stages": {"sp-strawberry: generate": stage}, "scenes": {"Single-Strawberry/000": scene}})
    )
    state = RunState.load(path)
    assert (
        state.stages["sp-strawberry: generate"].seconds == 61.5
        and state.stages["sp-strawberry: generate"].note == "2 scenes"
    )


def test_a_state_round_trips_and_keeps_no_episodes(tmp_path: Path, evaluated: EvaluationResults) -> None:
    kept = without_episodes(evaluated)
    assert all(row.episodes is None for row in kept.policies.values())
    assert all(row.episodes for row in evaluated.policies.values())  # the evaluation itself is left whole
    assert kept.policies["A2C"].paired[BEST_FIXED] == evaluated.policies["A2C"].paired[BEST_FIXED]
    state = RunState(
        config=json.loads(json.dumps(asdict(CONFIGS["small"]))),
        stages={
            "sp-strawberry: validate": StageRecord(
                seconds=12.3, note="checked 2 scenes: sound", code="x", check_seconds=4.5, stamp="ab12"
            ),
            "sp-strawberry: evaluate": StageRecord(seconds=3.0, note="split all", code="x"),
        },
        results={"sp": kept},
        scene_folders={"sp-strawberry": ["Single-Strawberry/000", "Single-Strawberry/001"]},
    )
    path = state.save(tmp_path / "state.json")
    assert RunState.load(path) == state
    saved = json.loads(path.read_text())
    assert list(saved) == ["config", "stages", "results", "scene_folders"]
    assert saved["stages"]["sp-strawberry: evaluate"] == {"seconds": 3.0, "note": "split all", "code": "x"}
    assert all("episodes" not in row for row in saved["results"]["sp"]["policies"].values())
    whole = evaluated.write(tmp_path / "results" / "sp-strawberry.json")
    assert path.stat().st_size < whole.stat().st_size / 2  # the episodes stay in the results file


def test_an_old_state_is_read_again_from_the_runs_results_files(tmp_path: Path, evaluated: EvaluationResults) -> None:
    """A run in progress keeps an older state.json: its stages stand, each evaluation is taken from
    the group's results file, and one whose file is gone (or edited) is left out, to be evaluated
    again, rather than refused."""
    # The run's file predates the interval over scenes: the state makes it from the episodes, as
    # the page did before.
    data = evaluated.as_json()
    made = data["policies"]["A2C"]["paired"][BEST_FIXED]
    assert made["scene_low"] is not None and len(made["per_scene"]) == 2
    del data["policies"]["A2C"]["paired"][BEST_FIXED]["scene_low"]
    del data["policies"]["A2C"]["paired"][BEST_FIXED]["scene_high"]
    (tmp_path / "results").mkdir()
    (tmp_path / "results" / "sp-strawberry.json").write_text(json.dumps(data))
    config = asdict(CONFIGS["small"])  # Table 4's run: its state keeps results by scenario
    old = {
        "config": config,
        "stages": {
            "sp-strawberry: validate": {
                "seconds": 58.1,
                "note": "sound",
                "code": "x",
                "check_seconds": 13.5,
                "stamp": "d3",
            },
            "sp-strawberry: evaluate": {"seconds": 45.4, "note": "split all", "code": "y"},
            "mp-vine: evaluate": {"seconds": 9.0, "note": "split test", "code": "y"},
        },
        "results": {"sp": old_summary(evaluated), "mp": old_summary(evaluated)},  # no mp-vine.json
        "scene_folders": {"sp-strawberry": ["Single-Strawberry/000", "Single-Strawberry/001"]},
    }
    path = tmp_path / "state.json"
    path.write_text(json.dumps(old, indent=2))

    state = RunState.load(path)
    assert list(state.results) == ["sp"]  # mp's file is gone: its evaluate stage runs again
    assert state.results["sp"] == without_episodes(load_results(tmp_path / "results" / "sp-strawberry.json"))
    assert state.stages["sp-strawberry: validate"].stamp == "d3"  # a sound validation is not redone
    assert state.stages["sp-strawberry: validate"].check_seconds == 13.5
    assert state.config == json.loads(json.dumps(config))
    # The page's numbers are the ones the old summary held, the interval over scenes included.
    for learner in ("A2C", "PPO"):
        gap = state.results["sp"].policies[learner].paired[BEST_FIXED]
        assert gap.model_dump(exclude_none=True) == old["results"]["sp"][f"{learner.lower()}_vs_best_fixed"]
    assert path.read_text() == json.dumps(old, indent=2)  # reading writes nothing

    # Saved, the state is in the new form, and reads back as it was.
    state.save(path)
    assert RunState.load(path) == state
    # A results file edited since is not taken into the state either.
    data["policies"]["Rand"]["oer_tau"]["mean"] = 0.999
    (tmp_path / "results" / "sp-strawberry.json").write_text(json.dumps(data))
    path.write_text(json.dumps(old))
    assert RunState.load(path).results == {}


def test_the_crops_runs_old_state_finds_each_group_by_its_own_name(
    tmp_path: Path, evaluated: EvaluationResults
) -> None:
    # The crops run keeps its results by group (sp-apple), Table 4's by scenario (sp).
    evaluated.write(tmp_path / "results" / "sp-apple.json")
    old = {"config": asdict(CONFIGS["crops"]), "results": {"sp-apple": old_summary(evaluated)}}
    (tmp_path / "state.json").write_text(json.dumps(old))
    state = RunState.load(tmp_path / "state.json")
    assert state.results["sp-apple"] == without_episodes(evaluated)

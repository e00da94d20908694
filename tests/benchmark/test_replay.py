"""`davis-ag verify RESULTS.json --dataset DATA`: every episode played again on the dataset; a
forged file whose episodes and summary agree with each other but not with the dataset is named
to the episode and field (issue 44)."""

from __future__ import annotations

import json
import shutil
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest

from davis_ag import cli
from davis_ag.benchmark import evaluate
from davis_ag.benchmark.results import EvaluationResults
from davis_ag.benchmark.summaries import action_counts, paired_gaps, session_metrics


def _always_up(observation: Any, info: dict[str, Any]) -> str:
    return "up"


@pytest.fixture(scope="module")
def results_file(sp_root: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An untouched evaluation on the test split: 2 sessions x 8 episodes of 6 policies."""
    folder = tmp_path_factory.mktemp("replay")
    return evaluate([_always_up], sp_root, "sp", sessions=2, episodes=8).write(folder / "results.json")


def forge(source: Path, folder: Path, edit: Callable[[dict[str, Any]], None]) -> Path:
    """Edit a file's episodes, then write every summary again from them, as a careful forger
    would: the file agrees with itself, so only the dataset can tell."""
    data = json.loads(source.read_text())
    edit(data)
    protocol = data["protocol"]
    records = {name: policy["episodes"] for name, policy in data["policies"].items()}
    for name, policy in data["policies"].items():
        keys = tuple(k for k in ("oer_tau", "reward", "length", "oer_0") if k in policy)
        policy.update(session_metrics(records[name], keys, protocol["sessions"]))
        policy["action_counts"] = action_counts(records[name], protocol["actions"])
        policy["paired"] = paired_gaps(name, records, protocol["seed"])
    path = folder / "forged.json"
    path.write_text(json.dumps(EvaluationResults.model_validate(data).as_json()))
    return path


def _verify(capsys: pytest.CaptureFixture[str], *args: str) -> tuple[int, str]:
    code = cli.main(["verify", *args])
    captured = capsys.readouterr()
    return code, (captured.out + captured.err).strip()


def test_an_untouched_file_is_sound_and_says_its_rate(
    results_file: Path, sp_root: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out = _verify(capsys, str(results_file), "--dataset", str(sp_root))
    assert code == 0, out
    assert "sound: 96 episodes of 6 policies replayed on the dataset in" in out and "episodes/s" in out


def _episode(data: dict[str, Any], policy: str = "LRD", index: int = 9) -> dict[str, Any]:
    return data["policies"][policy]["episodes"][index]


def _better(data: dict[str, Any]) -> None:
    """LRD's 10th episode (session 1, episode 1) claims a better ending than it had."""
    episode = _episode(data)
    episode["oer_tau"] = min(1.0, episode["oer_tau"] + 0.25)
    episode["reward"] = max(episode["oer_tau"] - episode["oer_0"], 0.0) ** 2


def _other_view(data: dict[str, Any]) -> None:
    episode = _episode(data)
    episode["path"][-1] = "0001.jpeg" if episode["path"][-1] != "0001.jpeg" else "0002.jpeg"


def _other_target(data: dict[str, Any]) -> None:
    for policy in data["policies"]:  # every policy's, so that the paired gaps still pair
        _episode(data, policy)["target_fruit"] += 1000


def _longer(data: dict[str, Any]) -> None:
    episode = _episode(data, "_always_up")
    episode["actions"].append(0)
    episode["path"].append(episode["path"][-1])
    episode["length"] += 1


@pytest.mark.parametrize(
    "edit, named",
    [
        (_better, "LRD session 1 episode 1: oer_tau is"),
        (_other_view, "LRD session 1 episode 1: path is"),
        (_other_target, "session 1 episode 1: target_fruit is"),
        (_longer, "_always_up session 1 episode 1: length (the episode ended) is"),
        (lambda d: d["fixed_actions"]["up"].update(oer_tau=0.99), "fixed_actions.up is"),
    ],
)
def test_a_forged_file_that_agrees_with_itself_is_named_to_the_episode(
    edit: Callable[[dict[str, Any]], None],
    named: str,
    results_file: Path,
    sp_root: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    forged = forge(results_file, tmp_path, edit)
    assert cli.main(["compare", str(forged)]) == 0  # its summaries agree with its episodes...
    capsys.readouterr()
    code, out = _verify(capsys, str(forged), "--dataset", str(sp_root))  # ...but not with the dataset
    assert code == 1 and named in out and "not sound: " in out and "replayed" in out and "\n" not in out, out
    code, out = _verify(capsys, str(results_file), str(forged), "--dataset", str(sp_root))
    assert code == 1 and "1 of 2 results files sound" in out
    # compare --verify ranks nothing of it
    assert cli.main(["compare", str(results_file), str(forged), "--verify", str(sp_root)]) == 1
    assert "not ranked" in capsys.readouterr().out


def test_another_dataset_is_named_before_any_episode(
    results_file: Path, sp_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    copy = Path(shutil.copytree(sp_root, tmp_path / "copy"))
    assert _verify(capsys, str(results_file), "--dataset", str(copy))[0] == 0  # a copy elsewhere is the same
    scene = next(copy.glob("*/001/scene.json"))
    meta = json.loads(scene.read_text())
    meta["seed"] += 1
    scene.write_text(json.dumps(meta))
    code, out = _verify(capsys, str(results_file), "--dataset", str(copy))
    assert code == 1 and "not sound: dataset scene Single-Strawberry/001 seed is" in out, out


def test_results_without_a_dataset_or_with_scenes_options_get_one_line(
    results_file: Path, sp_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    code, out = _verify(capsys, str(results_file))
    assert code == 2 and "give the dataset they evaluated: --dataset DATA" in out and "\n" not in out
    code, out = _verify(capsys, str(results_file), "--dataset", str(sp_root), "--keep", str(tmp_path / "k"))
    assert code == 2 and "--keep" in out
    data = json.loads(results_file.read_text())
    data["protocol"]["version"] = 0
    old = tmp_path / "old.json"
    old.write_text(json.dumps(data))
    code, out = _verify(capsys, str(old), "--dataset", str(sp_root))
    assert code == 2 and "protocol version 0" in out and "\n" not in out

"""A training run keeps the snapshot that scores best on the train split, across a kill."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from stable_baselines3 import A2C

from davis_ag.benchmark.selection import check_keep
from davis_ag.benchmark.training import checkpoint_paths, train_a2c, training_record_path
from davis_ag.errors import UserError
from kill_callback import KillAfter
from layout_factory import write_tiny_dataset

KWARGS = dict(total_timesteps=240, seed=1, n_envs=2, arch="pooled", device="cpu", select_every=40)


def _snapshots(folder: Path) -> list[Path]:
    return sorted(folder.glob("*.best-*.zip"))


def test_the_saved_model_is_the_best_scored_snapshot(tmp_path: Path, one_thread: None) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "models" / "a2c.zip"
    train_a2c(root, "sp", out_path=out, checkpoint_every=0, **KWARGS)
    selection = json.loads(training_record_path(out).read_text())["selection"]
    scores = selection["scores"]
    # Scored every 40 steps (a 2-environment step is 2 steps) and at the end, on the train split.
    assert [s["step"] for s in scores] == [40, 80, 120, 160, 200, 240]
    assert all(0 <= s["oer_tau"] <= 1 and 1 <= s["length"] <= 3 for s in scores)
    best = max(scores, key=lambda s: (s["oer_tau"], -s["step"]))
    assert selection["kept_step"] == best["step"] and selection["play"] == "sampled"
    assert A2C.load(out, device="cpu").num_timesteps == best["step"]
    assert _snapshots(out.parent) == []  # no snapshot files left behind


def test_scoring_leaves_the_training_run_unchanged(tmp_path: Path, one_thread: None) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    curves = []
    for keep in ("best-train", "last"):
        out = tmp_path / keep / "a2c.zip"
        train_a2c(root, "sp", out_path=out, checkpoint_every=0, keep=keep, **KWARGS)
        record = json.loads(training_record_path(out).read_text())
        assert record["keep"] == keep and ("selection" in record) == (keep == "best-train")
        curves.append(record["curve"])
    assert curves[0] == curves[1]  # same episodes, same rewards: scoring drew nothing of training's


def test_a_killed_run_resumes_with_the_best_it_had(tmp_path: Path, one_thread: None) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    with pytest.raises(KeyboardInterrupt):
        train_a2c(root, "sp", out_path=out, checkpoint_every=40, callback=KillAfter(130), **KWARGS)
    saved = json.loads(checkpoint_paths(out)[1].read_text())
    first = saved["selection"]
    assert [s["step"] for s in first] == [40, 80, 120]
    best = max(first, key=lambda s: (s["oer_tau"], -s["step"]))
    # Only the best snapshot the checkpoint names is kept on disk.
    assert [p.name for p in _snapshots(tmp_path)] == [f"a2c.best-{best['step']:07d}.zip"]
    train_a2c(root, "sp", out_path=out, checkpoint_every=40, **KWARGS)
    selection = json.loads(training_record_path(out).read_text())["selection"]
    assert selection["scores"][:3] == first and [s["step"] for s in selection["scores"]][3:] == [160, 200, 240]
    assert A2C.load(out, device="cpu").num_timesteps == selection["kept_step"]
    assert _snapshots(tmp_path) == []


def test_an_unknown_keep_rule_is_refused(tmp_path: Path) -> None:
    with pytest.raises(UserError, match="unknown --keep 'best'"):
        check_keep("best")


def test_a_stop_after_the_choice_but_before_the_record_keeps_every_score(
    tmp_path: Path, one_thread: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    """The kept snapshot was renamed into place before the training record and the checkpoint's
    removal: a stop in between left no snapshot under its name, and the run resumed from the
    checkpoint dropped every score and kept the checkpoint's model instead of the best."""
    from davis_ag.benchmark import selection as selection_module
    from davis_ag.benchmark import training

    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    real = training.write_json_atomic

    def stop_at_the_record(path: Path, data: object) -> None:
        if path == training_record_path(out):
            raise KeyboardInterrupt
        real(path, data)

    # The earliest snapshot is the best (as at paper scale, where the kept steps come early): the
    # resumed run publishes the file that is already in place.
    monkeypatch.setattr(
        selection_module,
        "train_split_score",
        lambda model, env, n: {"oer_tau": 1 - model.num_timesteps / 1000, "reward": 0.0, "length": 1.0},
    )
    monkeypatch.setattr(training, "write_json_atomic", stop_at_the_record)
    with pytest.raises(KeyboardInterrupt):
        train_a2c(root, "sp", out_path=out, checkpoint_every=40, **KWARGS)
    first = json.loads(checkpoint_paths(out)[1].read_text())["selection"]
    monkeypatch.setattr(training, "write_json_atomic", real)
    train_a2c(root, "sp", out_path=out, checkpoint_every=40, **KWARGS)
    selection = json.loads(training_record_path(out).read_text())["selection"]
    assert selection["scores"][: len(first)] == first  # none dropped
    assert A2C.load(out, device="cpu").num_timesteps == selection["kept_step"] == 40
    assert _snapshots(tmp_path) == [] and not list(tmp_path.glob(".*.link"))  # no stray link

"""A2C training checkpoints and resumes: a run killed midway continues where it stopped."""

from __future__ import annotations

import json
from pathlib import Path

import pytest
from kill_callback import KillAfter
from layout_factory import write_tiny_dataset
from stable_baselines3 import A2C

from davis_ag.benchmark.training import checkpoint_paths, train_a2c, training_record_path
from davis_ag.provenance import code_version


def test_a_killed_run_resumes_from_its_checkpoint(tmp_path: Path, one_thread: None,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "models" / "a2c"
    kwargs = dict(total_timesteps=240, seed=1, out_path=out, n_envs=2, arch="pooled", device="cpu",
                  checkpoint_every=40)
    with pytest.raises(KeyboardInterrupt):
        train_a2c(root, "sp", callback=KillAfter(130), **kwargs)
    model_file, settings_file = checkpoint_paths(out)
    saved = json.loads(settings_file.read_text())
    assert 80 <= saved["timesteps_done"] <= 130 and model_file.is_file()
    assert not (tmp_path / "models" / "a2c.zip").exists()  # no final model from a killed run

    path = train_a2c(root, "sp", **kwargs)
    assert f"at {saved['timesteps_done']} of 240 steps" in capsys.readouterr().out
    assert path == tmp_path / "models" / "a2c.zip"
    assert A2C.load(path, device="cpu").num_timesteps == 240  # no step trained twice or skipped
    assert not model_file.exists() and not settings_file.exists()
    # The record says it was made in two sittings, which steps each made, and with what code.
    record = json.loads(training_record_path(out).read_text())
    sittings = record["sittings"]
    assert [(s["from_step"], s["to_step"]) for s in sittings] == [(0, saved["timesteps_done"]),
                                                                  (saved["timesteps_done"], 240)]
    assert all(s["code"] == code_version() and s["seconds"] > 0 for s in sittings)
    assert record["timesteps"] == 240 and record["seconds"] == pytest.approx(sum(s["seconds"] for s in sittings), abs=0.2)


def test_a_checkpoint_of_another_dataset_is_not_resumed(tmp_path: Path, one_thread: None,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    first = write_tiny_dataset(tmp_path / "first", "sp", "strawberry", scenes=2)
    second = write_tiny_dataset(tmp_path / "second", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    with pytest.raises(KeyboardInterrupt):
        train_a2c(first, "sp", total_timesteps=200, seed=1, out_path=out, n_envs=2, arch="pooled",
                  device="cpu", checkpoint_every=20, callback=KillAfter(60))
    saved = json.loads(checkpoint_paths(out)[1].read_text())
    assert saved["dataset"] == str(Path(first).absolute())
    train_a2c(second, "sp", total_timesteps=100, seed=1, out_path=out, n_envs=2, arch="pooled",
              device="cpu", checkpoint_every=20)
    assert "resuming" not in capsys.readouterr().out


def test_a_checkpoint_from_before_datasets_were_recorded_still_resumes(
        tmp_path: Path, one_thread: None, capsys: pytest.CaptureFixture[str]) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    with pytest.raises(KeyboardInterrupt):
        train_a2c(root, "sp", total_timesteps=200, seed=1, out_path=out, n_envs=2, arch="pooled",
                  device="cpu", checkpoint_every=20, callback=KillAfter(60))
    settings_file = checkpoint_paths(out)[1]
    saved = json.loads(settings_file.read_text())
    settings_file.write_text(json.dumps({**saved, "dataset": "/"}))  # as earlier versions wrote it
    train_a2c(root, "sp", total_timesteps=200, seed=1, out_path=out, n_envs=2, arch="pooled",
              device="cpu", checkpoint_every=20)
    assert "resuming" in capsys.readouterr().out


def test_other_settings_never_resume_a_checkpoint(tmp_path: Path, one_thread: None,
                                                  capsys: pytest.CaptureFixture[str]) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    with pytest.raises(KeyboardInterrupt):
        train_a2c(root, "sp", total_timesteps=200, seed=1, out_path=out, n_envs=2, arch="pooled",
                  device="cpu", checkpoint_every=20, callback=KillAfter(60))
    path = train_a2c(root, "sp", total_timesteps=100, seed=2, out_path=out, n_envs=2, arch="pooled",
                     device="cpu", checkpoint_every=20)
    assert "resuming" not in capsys.readouterr().out
    assert A2C.load(path, device="cpu").num_timesteps == 100

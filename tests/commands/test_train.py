"""``davis-ag train`` whose output cannot be written keeps what it trained (issue 44, item 4): a
short run without checkpoints on a full disk said "no snapshot was finished yet" and lost a model
that was whole in memory."""

from __future__ import annotations

import errno
import json
import os
from collections.abc import Callable, Iterator
from contextlib import contextmanager
from pathlib import Path
from typing import IO, Any

import pytest
from stable_baselines3 import A2C

import davis_ag.atomic_files as atomic_files
import davis_ag.benchmark.checkpoints as checkpoints
from davis_ag import cli


def disk_full(monkeypatch: pytest.MonkeyPatch, full: Callable[[Path], bool]) -> None:
    """Every atomic write (models, snapshots, checkpoints, records) of a path ``full`` names fails
    as a full disk does; the rest are written."""
    real = atomic_files.atomic_output

    @contextmanager
    def atomic_output(path: str | os.PathLike[str], mode: str = "wb") -> Iterator[IO[Any]]:
        if full(Path(path)):
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        with real(path, mode) as handle:
            yield handle

    monkeypatch.setattr(atomic_files, "atomic_output", atomic_output)
    monkeypatch.setattr(checkpoints, "atomic_output", atomic_output)


def train(
    capsys: pytest.CaptureFixture[str], dataset: Path, out: Path, keep: str, extra: tuple[str, ...] = ()
) -> tuple[int, list[str]]:
    """A short run without checkpoints (``extra``: more flags): exit status and the lines on stderr."""
    code = cli.main(
        [
            "train",
            "--dataset",
            str(dataset),
            "--scenario",
            "sp",
            "--timesteps",
            "60",
            "--n-envs",
            "2",
            "--arch",
            "pooled",
            "--device",
            "cpu",
            "--checkpoint-every",
            "0",
            "--keep",
            keep,
            "--verbose",
            "0",
            "--out",
            str(out),
            *extra,
        ]
    )
    out_text, err = capsys.readouterr()
    assert "Traceback" not in out_text + err
    return code, err.splitlines()


@pytest.mark.parametrize("keep", ["best-train", "last"])
def test_a_model_whose_output_cannot_be_written_is_kept_elsewhere(
    keep: str,
    sp_root: Path,
    tmp_path: Path,
    one_thread: None,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    out = tmp_path / "full" / "m.zip"
    disk_full(monkeypatch, lambda path: path.parent == out.parent)  # the disk of --out is full
    code, lines = train(capsys, sp_root, out, keep)
    assert code == 1 and len(lines) == 1, lines  # the machine's failure: one line, exit 1
    line = lines[0]
    assert "No space left on device" in line and "no snapshot was finished" not in line
    kept = Path(line.split(" is kept in ")[1].split(":")[0])
    assert kept.is_relative_to(tmp_path / "cache") and kept.name == out.name
    assert f"to {out.parent} to use it" in line and "m.training.json beside it" in line
    model = A2C.load(kept, device="cpu")  # whole, and it acts
    assert model.num_timesteps == 60
    action, _ = model.predict(model.observation_space.sample())
    assert model.action_space.contains(action)
    record = json.loads((kept.parent / "m.training.json").read_text())
    assert record["timesteps"] == 60 and record["keep"] == keep and record["train_scenes"]
    if keep == "best-train":
        assert record["selection"]["kept_step"] == 60 and "train-split OER_tau" in line
    assert not out.exists() and not list(out.parent.glob("*.zip"))


def test_when_the_model_can_be_kept_nowhere_the_line_names_both_failures(
    sp_root: Path,
    tmp_path: Path,
    one_thread: None,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    out = tmp_path / "full" / "m.zip"
    disk_full(monkeypatch, lambda path: True)  # every disk is full
    code, lines = train(capsys, sp_root, out, "last")
    assert code == 1 and len(lines) == 1, lines
    line = lines[0]
    assert line.count("No space left on device") == 2 and str(out) in line
    assert "nor could the trained model (60 steps) be kept in" in line and "is lost" in line
    assert not list((tmp_path / "cache").rglob("*.zip"))  # no empty rescue folder claims to hold it
    assert not list((tmp_path / "cache").rglob("davis-ag-*"))


def test_the_torch_threads_asked_for_train_the_model_and_its_record_keeps_them(
    sp_root: Path, tmp_path: Path, one_thread: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """``--torch-threads``: two runs sharing a machine each take their share of its cores; the
    record's sitting says how many threads made it (the same weights come only from the same count)."""
    import torch

    out = tmp_path / "m.zip"
    torch.set_num_threads(2)  # not what is asked for
    try:
        code, lines = train(capsys, sp_root, out, "last", ("--torch-threads", "1"))
        assert code == 0 and torch.get_num_threads() == 1, lines
    finally:
        torch.set_num_threads(1)
    (sitting,) = json.loads(out.with_suffix(".training.json").read_text())["sittings"]
    assert sitting["torch_threads"] == 1
    for bad in ("0", str((os.cpu_count() or 1) + 1), "two"):
        with pytest.raises(SystemExit) as stopped:
            train(capsys, sp_root, tmp_path / f"bad-{bad}.zip", "last", ("--torch-threads", bad))
        assert stopped.value.code == 2
        err = capsys.readouterr().err.strip().splitlines()[-1]
        assert f"--torch-threads: {bad!r}: give torch from 1 to {os.cpu_count()} threads" in err
        assert not (tmp_path / f"bad-{bad}.zip").exists()

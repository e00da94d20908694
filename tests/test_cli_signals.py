"""SIGTERM and SIGINT end a long command with one line saying what was kept and that the same
command resumes, exit status 128 + the signal, no leaked-resource warning (issue 33 case 8).

Signals are sent by PID to a real ``davis-ag`` process, once it has finished something to keep.
"""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import time
import zipfile
from pathlib import Path

import pytest

from layout_factory import write_tiny_dataset

DAVIS_AG = [sys.executable, "-m", "davis_ag.cli"]
TINY = """\
seed: 3
image_size: 64x48
grid: {extent: [3.0, 3.0], step: 1.5, altitude_levels: [0]}
groups:
  - {scenario: sp, crop: strawberry, scenes: 2}
"""


def stop_when(process: subprocess.Popen, ready: callable, number: int, limit: float = 120) -> tuple[int, str]:
    """Send ``number`` to ``process`` once ``ready()`` holds; its exit status and stderr's lines
    that are no progress bar."""
    deadline = time.monotonic() + limit
    try:
        while not ready():
            assert process.poll() is None, process.communicate()
            assert time.monotonic() < deadline, "the command never got going"
            time.sleep(0.1)
        os.kill(process.pid, number)
        _, err = process.communicate(timeout=60)
    finally:
        if process.poll() is None:  # a failed check: never leave a long command eating the cores
            process.kill()
            process.communicate()
    lines = [line for line in err.replace("\r", "\n").splitlines() if line.strip() and "%|" not in line]
    return process.returncode, "\n".join(lines)


@pytest.mark.slow
def test_sigterm_ends_generate_with_one_line_and_the_run_resumes(tmp_path: Path) -> None:
    config, out = tmp_path / "tiny.yaml", tmp_path / "data"
    config.write_text(TINY)
    command = [*DAVIS_AG, "generate", "--config", str(config), "--out", str(out), "--workers", "2"]
    process = subprocess.Popen(command, stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    code, err = stop_when(process, lambda: (out / "dataset.json").exists(), signal.SIGTERM)
    assert code == 128 + signal.SIGTERM, err
    assert err.splitlines() == [
        "davis-ag generate: stopped by SIGTERM; finished scenes are kept and a scene in "
        "progress resumes from its views: run the same command again to resume"
    ], err
    assert "leaked" not in err
    done = subprocess.run([*command, "--quiet"], capture_output=True, text=True, timeout=300)
    assert done.returncode == 0 and "leaked" not in done.stderr, done.stderr
    assert sorted(p.name for p in (out / "Single-Strawberry").iterdir()) == ["000", "001"]


def test_sigint_ends_train_with_one_line_keeping_its_checkpoint(tmp_path: Path) -> None:
    data = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2, size=(64, 48))
    model = tmp_path / "a2c.zip"
    command = [
        *DAVIS_AG,
        "train",
        "--dataset",
        str(data),
        "--scenario",
        "sp",
        "--arch",
        "pooled",
        "--n-envs",
        "2",
        "--device",
        "cpu",
        "--verbose",
        "0",
        "--keep",
        "last",
        "--checkpoint-every",
        "20",
        "--out",
        str(model),
    ]
    env = {**os.environ, "OMP_NUM_THREADS": "1"}
    process = subprocess.Popen(
        [*command, "--timesteps", "1000000"], stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True, env=env
    )
    checkpoint = tmp_path / "a2c.checkpoint.json"
    code, err = stop_when(process, checkpoint.exists, signal.SIGINT)
    assert code == 128 + signal.SIGINT, err
    assert err.splitlines() == [
        "davis-ag train: stopped by SIGINT; the last checkpoint and the best snapshot so far "
        "are kept beside --out: run the same command again to resume"
    ], err
    assert not model.exists() and not list(tmp_path.glob(".*"))  # no lock, no temporary left
    # What resumes (tests/benchmark/test_training.py resumes such checkpoints): whole and readable.
    assert json.loads(checkpoint.read_text())["timesteps_done"] >= 20
    assert zipfile.is_zipfile(tmp_path / "a2c.checkpoint.zip")


@pytest.mark.parametrize("command", [["evaluate", "--policies", "LRD", "--episodes", "1000000", "--sessions", "1"]])
def test_sigterm_ends_evaluate_leaving_nothing_half_written(command: list[str], tmp_path: Path) -> None:
    data = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2, size=(64, 48))
    out = tmp_path / "results" / "r.json"
    process = subprocess.Popen(
        [*DAVIS_AG, *command, "--dataset", str(data), "--scenario", "sp", "--out", str(out)],
        stdout=subprocess.PIPE,
        stderr=subprocess.PIPE,
        text=True,
    )
    code, err = stop_when(process, lambda: (out.parent / ".r.json.lock").exists(), signal.SIGTERM)
    assert code == 128 + signal.SIGTERM and err.endswith("run the same command again to resume"), err
    assert err.count("\n") == 0 and not list(out.parent.iterdir())  # no lock, no temporary, no half file

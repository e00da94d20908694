"""Small real datasets for tests: a dataset config generated with Helios once per test session,
shared by every test and pytest-xdist worker that asks for the same config, and skipped where
pyhelios cannot render natively."""

from __future__ import annotations

import hashlib
import os
import shutil
from pathlib import Path

import pytest
from filelock import FileLock

from davis_ag.errors import UserError

#: A goblet vine (trunk and cordons: a robot's obstacles) on a 75 cm grid at three heights: 54 views,
#: with depth; the robot tests' scene (tests/benchmark/test_robot_moves.py, tests/live/test_continuous_robot.py).
ROBOT_VINE = """\
seed: 5
image_size: 128x72
grid: {extent: [3.0, 3.0], step: 0.75}
groups:
  - {scenario: sp, crop: vine, scenes: 1}
"""


def session_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """A folder every worker of this test session shares: the session's temporary root (with
    pytest-xdist each worker has its own base below it)."""
    base = tmp_path_factory.getbasetemp()
    return base.parent if os.environ.get("PYTEST_XDIST_WORKER") else base


def generate_config(tmp_path_factory: pytest.TempPathFactory, name: str, config_text: str) -> Path:
    """Generate the dataset ``config_text`` describes, once per session, and give the caller a copy.

    The first caller generates it in one process into a shared folder keyed by the config, under a
    file lock; every caller gets its own copy, so a test may change what it was given.

    Args:
        tmp_path_factory: pytest's factory (the copy goes into a new folder of it).
        name: The copy's folder name.
        config_text: A dataset config (YAML).

    Returns:
        The copy's dataset root.
    """
    from davis_ag.generate.run_config import load_dataset_config
    from davis_ag.generate.run_progress import RunOptions
    from davis_ag.generate.runner import run_dataset
    from davis_ag.scene.plants import require_native_helios

    try:
        require_native_helios()
    except UserError as error:
        pytest.skip(str(error))
    shared = session_folder(tmp_path_factory) / f"dataset-{hashlib.sha256(config_text.encode()).hexdigest()[:12]}"
    with FileLock(f"{shared}.lock"):
        if not (shared / "done").is_file():
            shutil.rmtree(shared, ignore_errors=True)  # a worker that died mid-way
            shared.mkdir(parents=True)
            config = shared / "config.yaml"
            config.write_text(config_text)
            run_dataset(load_dataset_config(config).requests(), shared / "data", RunOptions(workers=1, progress=False))
            (shared / "done").touch()
    root = tmp_path_factory.mktemp(name) / "data"
    shutil.copytree(shared / "data", root)
    return root

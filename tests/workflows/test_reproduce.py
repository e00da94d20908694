"""``davis-ag reproduce``'s training progress counts a resumed run from its checkpoint."""

from __future__ import annotations

from pathlib import Path

import pytest
from kill_callback import KillAfter
from layout_factory import write_tiny_dataset
from stable_baselines3.common.callbacks import CallbackList

from davis_ag.benchmark.training import train_a2c
from davis_ag.workflows.reproduce import _progress_callback


def test_progress_of_a_resumed_run_starts_at_its_checkpoint(tmp_path: Path, one_thread: None) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    kwargs = dict(total_timesteps=160, seed=1, out_path=tmp_path / "a2c", n_envs=2, arch="pooled",
                  device="cpu", checkpoint_every=40)
    with pytest.raises(KeyboardInterrupt):
        train_a2c(root, "sp", callback=CallbackList([_progress_callback(160, "t"), KillAfter(90)]), **kwargs)
    resumed = _progress_callback(160, "t")
    train_a2c(root, "sp", callback=resumed, **kwargs)
    # 80 steps came from the checkpoint and 80 from this sitting: the count ends at the total,
    # where it used to end at 80 ("80 of 160 steps" for a finished run).
    assert resumed.steps == 160

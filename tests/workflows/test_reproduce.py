"""``davis-ag reproduce``: a resumed run's progress starts at its checkpoint, the configurations
table follows the code, an evaluation gets the train-split yardstick."""

from __future__ import annotations

from pathlib import Path

import pytest
from kill_callback import KillAfter
from layout_factory import write_tiny_dataset
from stable_baselines3.common.callbacks import CallbackList

from davis_ag.benchmark.progress import TrainingProgress
from davis_ag.benchmark.training import train_a2c


def test_progress_of_a_resumed_run_starts_at_its_checkpoint(tmp_path: Path, one_thread: None) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    kwargs = dict(
        total_timesteps=160,
        seed=1,
        out_path=tmp_path / "a2c",
        n_envs=2,
        arch="pooled",
        device="cpu",
        checkpoint_every=40,
    )
    with pytest.raises(KeyboardInterrupt):
        train_a2c(
            root, "sp", callback=CallbackList([TrainingProgress(160, "t"), KillAfter(90)]), progress=False, **kwargs
        )
    resumed = TrainingProgress(160, "t")
    train_a2c(root, "sp", callback=resumed, progress=False, **kwargs)
    # 80 steps came from the checkpoint and 80 from this sitting: the count ends at the total,
    # where it used to end at 80 ("80 of 160 steps" for a finished run).
    assert resumed.steps == 160


def test_the_configurations_table_in_the_docs_is_the_codes() -> None:
    # docs/benchmark.md's table of `reproduce --config` sizes follows CONFIGS, never a hand copy.
    from davis_ag.workflows.reproduce import CONFIGS, CONFIGS_MARKER, configurations_table

    page = (Path(__file__).resolve().parents[2] / "docs" / "benchmark.md").read_text()
    section = page.split(f"<!-- {CONFIGS_MARKER}:start -->\n", 1)[1].split(f"\n<!-- {CONFIGS_MARKER}:end -->", 1)[0]
    assert section == configurations_table(), (
        'docs/benchmark.md is behind CONFIGS; rewrite it: python -c "from davis_ag.atomic_files import '
        "write_marked_section as w; from davis_ag.workflows import reproduce as r; "
        "w('docs/benchmark.md', r.CONFIGS_MARKER, r.configurations_table())\""
    )
    # Issue 22: medium's MP split keeps at least 3 test scenes (70/30 of 10 or more).
    assert CONFIGS["medium"].mp_scenes >= 10 and "| `medium` | 10 scenes | 10 scenes," in section


def test_an_evaluation_gets_the_train_split_yardstick_once(sp_root: Path) -> None:
    # A reused evaluation from before the yardstick gets it; one that has it is not recomputed.
    from davis_ag.benchmark.exact import split_fixed_actions
    from davis_ag.workflows.reproduce import _summary, add_train_split

    results = {"protocol": {"split": "test"}, "policies": {}}
    assert add_train_split(results, sp_root, "sp", "strawberry")
    assert results["train_split"] == split_fixed_actions(sp_root, "sp", "train", "strawberry")
    assert not add_train_split(results, sp_root, "sp", "strawberry")
    assert _summary(results)["train_split"] == results["train_split"]


def test_a_run_the_disk_cannot_hold_is_refused_before_anything_is_written(tmp_path: Path) -> None:
    # Issue 32: paper-scale writes about 48 GB of views and 21 GB of observation caches.
    from dataclasses import replace

    from davis_ag.errors import UserError
    from davis_ag.workflows.reproduce import CONFIGS, disk_needed, reproduce

    paper = CONFIGS["paper-scale"]
    # Table 3's 86 SP strawberry and 44 MP vine scenes (285 and 1,800 views, Table 2) at 1280x720.
    views = 86 * 285 + 44 * 1800
    assert 0.4e6 * views < disk_needed(paper) < 0.5e6 * views + 224 * 224 * 4 * views
    huge = replace(paper, name="huge", sp_scenes=10**7)
    out = tmp_path / "out"
    with pytest.raises(UserError, match=r"needs about .* GB more under .* GB free: free space, or pass --out"):
        reproduce(huge, out, tmp_path / "results.md")
    assert not out.exists() and not (tmp_path / "results.md").exists()

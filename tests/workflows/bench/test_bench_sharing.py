"""`davis-ag bench --only sharing`: two trainings at once, each on torch's threads and each on its
share of the cores, beside one alone, written into the page; a training that fails stops its row."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from davis_ag.errors import MachineError
from davis_ag.workflows.bench import sharing
from layout_factory import write_tiny_dataset


@pytest.mark.slow
def test_the_rows_time_their_processes_together_and_reach_the_page(tmp_path: Path) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    scratch = tmp_path / "scratch"
    scratch.mkdir()
    result = sharing.sharing_speed(scratch, steps=16, arch="pooled", root=root)
    alone, own, share = result["rows"].values()
    assert [r["processes"] for r in (alone, own, share)] == [1, 2, 2]
    # Each spawned process reports the threads it trained on: torch's own count, or half the cores.
    assert share["torch_threads"] == max(1, (os.cpu_count() or 1) // 2) <= own["torch_threads"]
    for row in (alone, own, share):
        assert len(row["steps_per_second_each"]) == row["processes"]
        assert row["steps_per_second"] == pytest.approx(sum(row["steps_per_second_each"]), abs=0.2)
    assert alone["over_alone"] == 1.0
    assert share["over_alone"] == pytest.approx(share["steps_per_second"] / alone["steps_per_second"], abs=0.01)
    page = tmp_path / "performance.md"
    page.write_text("# Performance\n\n<!-- bench-sharing:start -->\nold\n<!-- bench-sharing:end -->\nafter\n")
    sharing.write_sharing(result, (1.0, 2.0), page)
    text = page.read_text()
    assert "old" not in text and text.endswith("after\n")
    assert f"| two at once, half the cores each (--torch-threads) | 2 | {share['torch_threads']} |" in text
    assert f"({share['steps_per_second']} steps/s against {own['steps_per_second']})" in text


def test_a_training_that_fails_stops_its_row_in_one_line(tmp_path: Path) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    with pytest.raises(MachineError, match="a training of the row 'bad' failed"):
        sharing._row(root, tmp_path, "bad", 2, 1, 16, "no-such-network")

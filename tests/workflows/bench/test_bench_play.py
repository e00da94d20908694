"""`davis-ag bench --only play`: a model's episodes one at a time against in step, written into the page."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from davis_ag import cli
from davis_ag.workflows.bench import play


def test_both_ways_of_playing_a_model_are_timed_and_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert play.EPISODES == 200  # one session of section V-D's protocol; fewer here, for time
    monkeypatch.setattr(play, "EPISODES", 40)
    page = tmp_path / "performance.md"
    page.write_text("# Performance\n\n<!-- bench-play:start -->\nold\n<!-- bench-play:end -->\n")
    out = tmp_path / "bench.json"
    assert cli.main(["bench", "--only", "play", "--out", str(out), "--doc", str(page)]) == 0
    result = json.loads(out.read_text())["play"]
    assert result["episodes"] == 40 and result["same_episodes"] is True
    assert result["steps"] >= result["episodes"] and result["parameters"] > 30_000_000  # the paper's network
    assert result["gain"] == pytest.approx(result["one_at_a_time_s"] / result["in_step_s"], abs=0.1)  # of rounded times
    text = page.read_text()
    assert "old" not in text and "| in step (a forward pass per step of all the episodes) |" in text

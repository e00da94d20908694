"""`davis-ag bench --only robot`: every robot's reach of a scene and the grid step with a robot, timed and written."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from davis_ag import cli
from davis_ag.workflows.bench import robot

pytestmark = pytest.mark.slow


def test_the_reach_and_the_robot_step_are_timed_and_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert (robot.CROP, robot.SCENARIO) == ("apple-wall", "row")  # docs/robot.md's row; a small vine here, for time
    monkeypatch.setattr(robot, "CROP", "vine")
    monkeypatch.setattr(robot, "SCENARIO", "sp")
    monkeypatch.setattr(robot, "SIZE", (64, 36))
    monkeypatch.setattr(robot, "STEPS", 500)
    page = tmp_path / "performance.md"
    page.write_text("# Performance\n\n<!-- bench-robot:start -->\nold\n<!-- bench-robot:end -->\n")
    out = tmp_path / "bench.json"
    assert cli.main(["bench", "--only", "robot", "--out", str(out), "--doc", str(page)]) == 0
    result = json.loads(out.read_text())["robot"]
    assert set(result["reach"]) == {"panda-trolley", "ur10-lift", "ur5-trolley"}
    assert all(0 < r["seconds"] and 0 <= r["reached"] <= 1 for r in result["reach"].values())
    assert result["steps"] == 500 and result["steps_per_second_with"] > 0 and result["steps_per_second_without"] > 0
    text = page.read_text()
    assert "old" not in text and "| ur10-lift |" in text and "more a step" in text

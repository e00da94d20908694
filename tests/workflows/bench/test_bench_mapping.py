"""`davis-ag bench --only mapping`: a mapping step beside TVM-v0's, the update, the ceiling and the bound, timed and written."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from davis_ag import cli
from davis_ag.workflows.bench import mapping

pytestmark = pytest.mark.slow


def test_the_mapping_step_and_the_tables_are_timed_and_written(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    assert (mapping.CROP, mapping.SCENARIO) == ("apple-wall", "row")  # docs/mapping.md's row; a small vine here
    monkeypatch.setattr(mapping, "CROP", "vine")
    monkeypatch.setattr(mapping, "SCENARIO", "sp")
    monkeypatch.setattr(mapping, "SIZE", (64, 36))
    monkeypatch.setattr(mapping, "STEPS", 500)
    page = tmp_path / "performance.md"
    page.write_text("# Performance\n\n<!-- bench-mapping:start -->\nold\n<!-- bench-mapping:end -->\n")
    out = tmp_path / "bench.json"
    assert cli.main(["bench", "--only", "mapping", "--out", str(out), "--doc", str(page)]) == 0
    result = json.loads(out.read_text())["mapping"]
    assert result["steps"] == 500 and result["mapping_steps_per_second"] > 0 and result["tvm_steps_per_second"] > 0
    assert result["update_us"] > 0 and 0 <= result["ceiling"] <= 1
    assert all(b["fruit"] >= 0 for b in result["bounds"])
    text = page.read_text()
    assert "old" not in text and "| RowMapping-v0 |" in text and "the coverage update alone" in text

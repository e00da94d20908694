"""`davis-ag bench --only verify`: the time a results file's checks take, written into the page."""

from __future__ import annotations

import json
from pathlib import Path

from davis_ag import cli


def test_the_checks_of_a_paper_sized_results_file_are_timed_and_written(tmp_path: Path) -> None:
    page = tmp_path / "performance.md"
    page.write_text("# Performance\n\n<!-- bench-verify:start -->\nold\n<!-- bench-verify:end -->\n")
    out = tmp_path / "bench.json"
    assert cli.main(["bench", "--only", "verify", "--out", str(out), "--doc", str(page)]) == 0
    result = json.loads(out.read_text())["verify"]
    assert (result["policies"], result["episodes"]) == (8, 3 * 200 * 8)  # section V-D's protocol, eight rows
    assert result["replay_episodes_per_second"] > 0 and result["summaries_episodes_per_second"] > 0
    text = page.read_text()
    assert "old" not in text and "| every episode replayed on the dataset (`verify --dataset`) |" in text

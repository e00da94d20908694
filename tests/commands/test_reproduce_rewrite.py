"""``davis-ag reproduce --rewrite-results``: the page from a run's records, a run from before PPO included."""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import pytest

from davis_ag import cli
from davis_ag.workflows.reproduce.configs import CONFIGS
from davis_ag.workflows.reproduce.state import RunState, StageRecord
from results_factory import results


def test_a_run_from_before_ppo_is_rewritten_without_claiming_ppo(
    tmp_path: Path, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    # Issue 32: medium's state.json predates ReproduceConfig.learners; its page still renders, and
    # nothing on it says PPO ran, although the configuration now trains it.
    config = json.loads(json.dumps(asdict(CONFIGS["medium"])))
    del config["learners"]
    evaluated = results({"A2C": 0.6, "Rand": 0.45, "LRD": 0.44, "UDD": 0.3}, scenes=["Single-Strawberry/003"])
    RunState(
        config=config,
        results={"sp": evaluated},
        stages={"sp-strawberry: train A2C": StageRecord(seconds=7200.0, note="300000 steps", code="x")},
    ).save(tmp_path / "state.json")
    page = tmp_path / "results.md"
    elsewhere = tmp_path / "clone"
    elsewhere.mkdir()
    monkeypatch.chdir(elsewhere)  # a clone, whose docs/results.md is the committed page
    # Without --results the page lives with its run, never in the working folder's docs/.
    assert cli.main(["reproduce", "--out", str(tmp_path), "--rewrite-results"]) == 0
    assert not list(elsewhere.iterdir())
    text = page.read_text()
    assert "| A2C | .600 ± .010 |" in text and "| sp-strawberry: train A2C | 7200 |" in text
    assert "PPO" not in text
    assert capsys.readouterr().out.strip() == f"wrote {page}"

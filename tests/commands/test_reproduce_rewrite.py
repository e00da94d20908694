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


def _run_under(tmp_path: Path, rule: str) -> Path:
    """A finished medium run's records under ``rule``, in its own folder."""
    out = tmp_path / f"run-{rule}"
    out.mkdir()
    config = json.loads(json.dumps(asdict(CONFIGS["medium"])))
    config["split_rule"] = rule
    evaluated = results({"A2C": 0.6, "Rand": 0.45, "LRD": 0.44, "UDD": 0.3}, scenes=["Single-Strawberry/003"])
    RunState(config=config, results={"sp": evaluated}).save(out / "state.json")
    return out


def test_each_split_rules_run_has_its_own_page_and_never_replaces_anothers(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    from davis_ag.workflows.reproduce.pages.results import page_split_rule

    docs = tmp_path / "docs"
    docs.mkdir()
    readme = tmp_path / "README.md"
    readme.write_text("<!-- table4:start -->\nthe headline\n<!-- table4:end -->\n")
    scenes_page, starts_page = docs / "results.md", docs / "results-starts.md"
    scenes, starts = _run_under(tmp_path, "scenes"), _run_under(tmp_path, "starts")
    assert cli.main(["reproduce", "--out", str(scenes), "--rewrite-results", "--results", str(scenes_page)]) == 0
    headline = scenes_page.read_text()
    assert page_split_rule(headline) == "scenes" and headline.startswith("# Table 4 reproduction\n")
    # The starts run refuses the scenes run's page, in one line, and leaves it as it was.
    assert cli.main(["reproduce", "--out", str(starts), "--rewrite-results", "--results", str(scenes_page)]) == 2
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "split rule scenes" in err and "results-starts.md" in err
    assert scenes_page.read_text() == headline
    # Its own page names the rule and leaves the README's block (the headline run's) alone.
    before = readme.read_text()
    assert cli.main(["reproduce", "--out", str(starts), "--rewrite-results", "--results", str(starts_page)]) == 0
    assert page_split_rule(starts_page.read_text()) == "starts"
    assert starts_page.read_text().startswith("# Table 4 reproduction, split rule `starts`\n")
    assert readme.read_text() == before
    # And the scenes run may not replace the starts page either.
    assert cli.main(["reproduce", "--out", str(scenes), "--rewrite-results", "--results", str(starts_page)]) == 2


def test_reproduce_takes_the_split_rule_and_refuses_another_rules_page_before_running(
    tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    page = tmp_path / "results.md"
    page.write_text("# Table 4 reproduction\n\nthe scenes run's page\n")
    out = tmp_path / "run"
    assert (
        cli.main(
            ["reproduce", "--config", "small", "--split-rule", "starts", "--out", str(out), "--results", str(page)]
        )
        == 2
    )
    assert "split rule scenes" in capsys.readouterr().err
    assert page.read_text() == "# Table 4 reproduction\n\nthe scenes run's page\n"
    assert not (out / "state.json").exists(), "a refused run must not start"

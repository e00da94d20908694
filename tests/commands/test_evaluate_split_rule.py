"""``--split-rule`` from the command line (issue 59): evaluate under ``starts`` writes the rule
into the results, verify replays it under that rule, and compare never ranks it beside a
``scenes`` evaluation; the rule is refused where it does not apply."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from davis_ag import cli


def evaluate(dataset: Path, out: Path, *extra: str) -> int:
    flags = ["--dataset", str(dataset), "--scenario", "sp", "--episodes", "4", "--sessions", "1"]
    return cli.main(["evaluate", *flags, "--policies", "Rand,Oracle", "--out", str(out), *extra])


def test_evaluate_under_the_starts_rule_then_verify_and_compare(
    sp_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    starts, scenes = tmp_path / "starts.json", tmp_path / "scenes.json"
    assert evaluate(sp_root, starts, "--split-rule", "starts") == 0
    assert "split test (split rule starts): 2 SP scene(s)" in capsys.readouterr().out
    protocol = json.loads(starts.read_text())["protocol"]
    assert protocol["split_rule"] == "starts" and protocol["scenes"] == [
        "Single-Strawberry/000",
        "Single-Strawberry/001",
    ]
    assert evaluate(sp_root, scenes) == 0
    assert json.loads(scenes.read_text())["protocol"]["split_rule"] == "scenes"
    capsys.readouterr()
    assert cli.main(["verify", str(starts), str(scenes), "--dataset", str(sp_root)]) == 0  # each under its own rule
    assert "2 of 2 results files sound" in capsys.readouterr().out
    # A file from before the rules records none, and replays as scenes.
    older = json.loads(scenes.read_text())
    del older["protocol"]["split_rule"]
    (tmp_path / "older.json").write_text(json.dumps(older))
    assert cli.main(["verify", str(tmp_path / "older.json"), "--dataset", str(sp_root), "--split-rule", "scenes"]) == 0
    assert cli.main(["verify", str(starts), "--dataset", str(sp_root), "--split-rule", "scenes"]) == 2
    assert "evaluated under --split-rule starts, not scenes" in capsys.readouterr().err
    assert cli.main(["compare", str(starts), str(scenes)]) == 2
    assert "differ in split rule (scenes against starts)" in capsys.readouterr().err
    assert cli.main(["compare", str(scenes), str(tmp_path / "older.json"), "--split-rule", "scenes"]) == 0


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--env", "continuous"], "--split-rule starts splits TVM-v0's starts; --env continuous splits by scenes"),
        (["--task", "mapping"], "--split-rule starts splits TVM-v0's starts; --task mapping splits by scenes"),
    ],
)
def test_the_rule_is_refused_where_it_does_not_apply(
    sp_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    flags = ["--dataset", str(sp_root), "--scenario", "sp", "--out", str(tmp_path / "r.json")]
    code = cli.main(["evaluate", *flags, "--split-rule", "starts", *extra])
    assert code == 2
    assert message in capsys.readouterr().err
    assert not (tmp_path / "r.json").exists()

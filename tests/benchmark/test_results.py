"""The results file: typed, versioned, exactly what davis_ag.benchmark.evaluate returns."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from davis_ag.benchmark import evaluate
from davis_ag.benchmark.results import PROTOCOL_VERSION, EvaluationResults, load_results
from davis_ag.errors import UserError


def test_the_file_is_the_object(sp_root: Path, tmp_path: Path) -> None:
    results = evaluate([lambda observation, info: "left"], sp_root, scenario="sp", sessions=2, episodes=5, seed=3)
    assert isinstance(results, EvaluationResults)
    protocol = results.protocol
    assert (protocol.version, protocol.split, protocol.sessions, protocol.episodes, protocol.seed) == (
        PROTOCOL_VERSION,
        "test",
        2,
        5,
        3,
    )
    assert protocol.scenes == ["Single-Strawberry/001"] and protocol.starts > 0
    # The dataset's identity: every scene (not only the split's) with its seed.
    assert [(s.id, s.seed) for s in results.dataset.scenes] == [
        ("Single-Strawberry/000", 0),
        ("Single-Strawberry/001", 1),
    ]
    path = results.write(tmp_path / "r.json")
    assert load_results(path) == results
    assert json.loads(path.read_text()) == results.as_json()
    gap = results.policies["<lambda>"].paired["Best fixed action"]
    assert gap.low <= gap.gap <= gap.high and gap.episodes == 10
    assert [s.scene for s in gap.per_scene] == ["Single-Strawberry/001"]


def test_a_file_that_is_not_results_is_one_line(tmp_path: Path) -> None:
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps({"protocol": {"scenario": "sp"}, "policies": {}}))
    with pytest.raises(UserError, match=r"not davis-ag evaluation results \(protocol.split"):
        load_results(bad)
    bad.write_text("{")
    with pytest.raises(UserError, match="not JSON"):
        load_results(bad)

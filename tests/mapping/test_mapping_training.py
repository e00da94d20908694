"""Learners on row mapping: trained by the benchmark's run, snapshots kept by train-split coverage, scored and replayed."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from davis_ag.benchmark.training import train_agent, training_record_path
from davis_ag.errors import UserError
from davis_ag.mapping.evaluation import evaluate_mapping, replay_mapping
from davis_ag.mapping.training import mapping_task
from layout_factory import write_tiny_dataset


@pytest.fixture(scope="module")
def tiny_mp(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_tiny_dataset(tmp_path_factory.mktemp("mp"), "mp", "vine", scenes=2)


def test_a_mapping_learner_is_trained_scored_and_replayed(tiny_mp: Path, tmp_path: Path) -> None:
    out = train_agent(
        tiny_mp, "mp", total_timesteps=60, n_envs=2, arch="pooled", out_path=tmp_path / "m.zip",
        checkpoint_every=0, select_every=40, progress=False, task=mapping_task(budget=4),
    )  # fmt: skip
    record = json.loads(training_record_path(out).read_text())
    assert record["task"] == {"name": "mapping", "seen_fraction": 0.5, "budget": 4}
    scores = record["selection"]["scores"]
    assert scores and all(0 <= s["coverage"] <= 1 and "oer_tau" not in s for s in scores)
    results = evaluate_mapping([out], tiny_mp, "mp", "test", 1, 5, 0, budget=4, baselines=["Rand"])
    assert set(results.policies) == {"A2C", "Rand", "Best fixed move"}
    assert replay_mapping(results, tiny_mp, "m.json").sound


def test_a_tvm_model_is_refused_on_mapping(tiny_mp: Path, tmp_path: Path) -> None:
    tvm = train_agent(
        tiny_mp, "mp", total_timesteps=20, n_envs=2, arch="pooled", out_path=tmp_path / "t.zip",
        checkpoint_every=0, keep="last", progress=False,
    )  # fmt: skip
    with pytest.raises(UserError, match="the model has 9 actions"):
        evaluate_mapping([tvm], tiny_mp, "mp", "test", 1, 2, 0, baselines=False)

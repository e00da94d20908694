"""``reproduce`` under a split rule (issue 59): the learners train and everything is scored under
the configuration's rule, and nothing made under another rule is reused."""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

from davis_ag.benchmark.training import training_record_path
from davis_ag.workflows.reproduce.configs import CONFIGS
from davis_ag.workflows.reproduce.learners import model_path, train_learner
from davis_ag.workflows.reproduce.run import add_train_split, split_scene_ids
from davis_ag.workflows.stages import evaluation_split, run_baselines


def test_a_run_under_the_starts_rule_trains_and_scores_under_it(
    tmp_path: Path, sp_root: Path, one_thread: None
) -> None:
    config = replace(CONFIGS["small"], n_envs=2, seed=1, split_rule="starts")
    model = model_path(tmp_path, "sp-strawberry")
    kwargs = dict(arch="pooled", checkpoint_every=0, progress=False)
    assert train_learner("a2c", sp_root, "sp", "strawberry", model, 40, config, **kwargs) is not None
    record = json.loads(training_record_path(model).read_text())
    assert record["split_rule"] == "starts"
    assert train_learner("a2c", sp_root, "sp", "strawberry", model, 40, config, **kwargs) is None  # reused
    both = ["Single-Strawberry/000", "Single-Strawberry/001"]
    assert split_scene_ids(sp_root, "sp", "test", "strawberry", "starts") == both
    assert evaluation_split(sp_root, "sp", "strawberry", "starts") == "test"
    results = run_baselines(sp_root, "sp", "strawberry", "test", 2, 1, model=model, split_rule="starts")
    assert results.protocol.split_rule == "starts" and "A2C" in results.policies
    assert add_train_split(results, sp_root, "sp", "strawberry", "starts")
    assert results.train_split is not None and results.train_split.starts > 0
    # The same run under the scenes rule trains its model anew: the starts model saw its test scenes.
    assert train_learner("a2c", sp_root, "sp", "strawberry", model, 40, replace(config, split_rule="scenes"), **kwargs)
    assert "split_rule" not in json.loads(training_record_path(model).read_text())

"""Exact expectations of the image-blind policies, the start rule, and the Best fixed action row."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from davis_ag.benchmark import TVMEnv
from davis_ag.benchmark.agents import FixedActionAgent, build_agents, heuristic
from davis_ag.benchmark.evaluation import BEST_FIXED, evaluate_policies, write_json
from davis_ag.benchmark.exact import (
    action_probabilities,
    expected_metrics,
    fixed_action_expectations,
    split_fixed_actions,
    start_expectations,
)


def _enumerate(env: TVMEnv, start: tuple[str, str, int], probs: np.ndarray) -> dict[str, float]:
    """Expected final OER, reward and length of one start by playing every action sequence in the
    real environment (replayed from the start), each weighted by its probability."""
    totals = {"oer_tau": 0.0, "reward": 0.0, "length": 0.0}

    def play(prefix: list[int], weight: float) -> None:
        env.reset(options={"start": start})
        for action in prefix[:-1]:
            env.step(action)
        _, reward, terminated, _, info = env.step(prefix[-1])
        if terminated:
            totals["oer_tau"] += weight * info["oer_t"]
            totals["reward"] += weight * reward
            totals["length"] += weight * len(prefix)
            return
        for a in np.flatnonzero(probs):
            play([*prefix, int(a)], weight * probs[a])

    for a in np.flatnonzero(probs):
        play([int(a)], probs[a])
    return totals


@pytest.mark.parametrize("policy", ["LRD", "UDD", "Rand", "down", "done"])
def test_dynamic_programme_matches_every_action_sequence_played(sp_root: Path, policy: str) -> None:
    env = TVMEnv(sp_root, "sp", split="all")
    chosen = None if policy == "Rand" else heuristic(policy).actions if policy in ("LRD", "UDD") else (policy,)
    probs = action_probabilities(env.action_names, chosen)
    per_start = start_expectations(env, probs)
    for row in range(0, len(env.starts), max(1, len(env.starts) // 6)):  # a spread of starts
        scene, box = env.starts[row]
        cache = env.caches[scene]
        start = (
            env.scenes[scene].id,
            cache.view_names[cache.box_view[box]],
            int(cache.fruit_ids[cache.box_fruit[box]]),
        )
        played = _enumerate(env, start, probs)
        for key, value in played.items():
            assert per_start[key][row] == pytest.approx(value, abs=1e-6), (policy, start, key)


def test_sampled_means_fall_within_their_standard_errors_of_the_exact_values(sp_root: Path) -> None:
    env = TVMEnv(sp_root, "sp", split="train")
    results = evaluate_policies(
        env, build_agents(["LRD", "UDD", "Rand"]), episodes=200, sessions=3, seed=3, best_fixed_action=True
    ).as_json()
    for name in ("LRD", "UDD", "Rand", BEST_FIXED):
        summary = results["policies"][name]
        for key in ("oer_tau", "reward", "length"):
            mean, sem, exact = summary[key]["mean"], summary[key]["sem"], summary["exact"][key]
            if sem == 0:  # every episode the same (e.g. a fixed move always plays tau steps)
                assert mean == pytest.approx(exact), (name, key)
            else:
                assert abs(mean - exact) <= 3 * sem, (name, key, mean, exact, sem)
    # A policy that looks at the image (the Oracle) has no exact value here.
    oracle = evaluate_policies(env, build_agents(["Oracle"]), episodes=5, sessions=1).as_json()
    assert "exact" not in oracle["policies"]["Oracle"]


def test_pairs_rule_draws_every_eligible_start_equally(sp_root: Path) -> None:
    env = TVMEnv(sp_root, "sp", split="all")
    old = TVMEnv(sp_root, "sp", split="all", start_rule="scene")
    assert env.start_rule == "pairs" and np.array_equal(env.starts, old.starts)
    p_pairs, p_scene = env.start_probabilities(), old.start_probabilities()
    assert p_pairs == pytest.approx(np.full(len(env.starts), 1 / len(env.starts)))
    assert p_scene.sum() == pytest.approx(1.0) and not np.allclose(p_pairs, p_scene)
    # Every eligible start meets section V-D's condition.
    for scene, box in env.starts:
        assert env.caches[scene].box_oer[box] < 0.4
    for rule_env, probs in ((env, p_pairs), (old, p_scene)):
        index = {(int(s), int(b)): k for k, (s, b) in enumerate(rule_env.starts)}
        counts = np.zeros(len(probs))
        n = 4000
        rule_env.reset(seed=11)
        for _ in range(n):
            rule_env.reset()
            counts[index[(rule_env._scene, rule_env._box)]] += 1
        expected = n * probs
        # Each start's count within five binomial standard deviations of its probability.
        assert np.all(np.abs(counts - expected) <= 5 * np.sqrt(expected * (1 - probs))), rule_env.start_rule


def test_unknown_start_rule_is_refused(sp_root: Path) -> None:
    from davis_ag.errors import UserError

    with pytest.raises(UserError, match="start_rule"):
        TVMEnv(sp_root, "sp", split="all", start_rule="views")


def test_best_fixed_action_row_and_histograms_in_the_json(sp_root: Path, tmp_path: Path) -> None:
    env = TVMEnv(sp_root, "sp", split="test")
    results = evaluate_policies(
        env, build_agents(["LRD", "Rand"]), episodes=40, sessions=3, best_fixed_action=True
    ).as_json()
    fixed = fixed_action_expectations(env)
    assert list(results["fixed_actions"]) == list(env.action_names)
    for action, values in fixed.items():
        assert results["fixed_actions"][action] == pytest.approx(values)
    row = results["policies"][BEST_FIXED]
    best = row["action"]
    assert all(fixed[best]["oer_tau"] >= v["oer_tau"] for v in fixed.values())
    # It always played that one action, on the same episodes as the others.
    assert row["action_counts"][best] == sum(row["action_counts"].values()) > 0
    assert row["exact"] == pytest.approx(fixed[best])
    saved = json.loads(write_json(results, tmp_path / "r.json").read_text())
    for name in ("LRD", "Rand", BEST_FIXED):
        assert list(saved["policies"][name]["action_counts"]) == list(env.action_names)
    assert saved["protocol"]["start_rule"] == "pairs"
    assert saved["protocol"]["starts"] == len(env.starts)


def test_fixed_action_agent_matches_its_exact_value(sp_root: Path) -> None:
    env = TVMEnv(sp_root, "sp", split="all")
    agent = FixedActionAgent("left")
    assert agent.name == "always left"
    assert expected_metrics(env, agent.action_probabilities(env)) == pytest.approx(
        fixed_action_expectations(env)["left"]
    )


def test_the_train_split_yardstick_is_every_fixed_action_on_train(sp_root: Path) -> None:
    # Where an A2C snapshot is chosen (train), the page sets it beside always playing one move there.
    env = TVMEnv(sp_root, "sp", split="train", crop="strawberry")
    train = split_fixed_actions(sp_root, "sp", "train", "strawberry")
    assert train["split"] == "train" and train["starts"] == len(env.starts) > 0
    assert list(train["fixed_actions"]) == list(env.action_names)
    for action, values in fixed_action_expectations(env).items():
        assert train["fixed_actions"][action] == pytest.approx(values)
    test = split_fixed_actions(sp_root, "sp", "test", "strawberry")
    assert test["starts"] != train["starts"] or test["fixed_actions"] != train["fixed_actions"]

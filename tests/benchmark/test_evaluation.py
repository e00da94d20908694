"""The section V-D protocol, the Table 4 summary, its files, and the train/evaluate commands."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import pytest

from davis_ag.benchmark import TVMEnv
from davis_ag.benchmark.agents import build_agents
from davis_ag.benchmark.evaluation import (
    episode_seeds,
    evaluate_policies,
    run_episode,
    write_json,
)
from davis_ag.benchmark.results_table import format_table
from davis_ag.cli import add_command
from davis_ag.errors import UserError
from davis_ag.figures.result_charts import plot_results


def _parser() -> argparse.ArgumentParser:
    # Only our commands: the CLI's other sub-commands are not needed (nor maybe present) here.
    parser = argparse.ArgumentParser(prog="davis-ag")
    sub = parser.add_subparsers(dest="command", required=True)
    add_command(sub, "train")
    add_command(sub, "evaluate")
    return parser


def test_episode_seeds_are_fixed_and_distinct() -> None:
    a, b = episode_seeds(0, 0, 200), episode_seeds(0, 0, 200)
    assert a == b and len(set(a[0])) == 200
    assert episode_seeds(0, 1, 200)[0] != a[0]  # sessions differ
    assert set(a[0]).isdisjoint(a[1])  # the agent never mirrors the environment's stream


def test_protocol_and_summary(sp_root: Path) -> None:
    env = TVMEnv(sp_root, "sp", "test")
    agents = build_agents(["LRD", "UDD", "Rand", "Oracle"])
    results = evaluate_policies(env, agents, episodes=30, sessions=3, seed=5, keep_episodes=True).as_json()
    assert results["protocol"]["scenes"] == ["Single-Strawberry/001"]  # the test split only
    policies = results["policies"]
    assert list(policies) == ["LRD", "UDD", "Rand", "Oracle"]
    for name, summary in policies.items():
        episodes = summary["episodes"]
        assert len(episodes) == 90
        for metric in ("oer_tau", "reward", "length"):
            sessions = [np.mean([e[metric] for e in episodes if e["session"] == s]) for s in range(3)]
            assert summary[metric]["sessions"] == pytest.approx(sessions)
            assert summary[metric]["mean"] == pytest.approx(np.mean(sessions))
            assert summary[metric]["std"] == pytest.approx(np.std(sessions))
        # Action counts add up the recorded per-episode actions, named as the protocol says.
        assert results["protocol"]["actions"] == list(env.action_names)
        counts = summary["action_counts"]
        assert list(counts) == list(env.action_names)
        assert sum(counts.values()) == sum(e["length"] for e in episodes)
        for index, action in enumerate(env.action_names):
            assert counts[action] == sum(e["actions"].count(index) for e in episodes)
        for e in episodes:
            assert 1 <= e["length"] <= 3
            assert e["reward"] == pytest.approx(max(e["oer_tau"] - e["oer_0"], 0) ** 2)
    starts = {
        name: [(e["scene"], e["path"][0], e["target_fruit"]) for e in s["episodes"]] for name, s in policies.items()
    }
    assert all(v == starts["LRD"] for v in starts.values())  # same episodes for every policy
    again = evaluate_policies(env, build_agents(["Rand"]), episodes=30, sessions=3, seed=5).as_json()
    assert again["policies"]["Rand"]["reward"] == {k: v for k, v in policies["Rand"]["reward"].items()}  # reproducible


def test_episode_length_counts_done(sp_root: Path) -> None:
    env = TVMEnv(sp_root, "sp", "all")
    run = run_episode(env, build_agents(["LRD"])[0], 0, 0)
    assert run["length"] == len(run["actions"])
    assert run["actions"][-1] == env.done_action or run["length"] == env.tau


def test_table_json_and_plot(sp_root: Path, tmp_path: Path) -> None:
    env = TVMEnv(sp_root, "sp", "test")
    results = evaluate_policies(env, build_agents(["LRD", "Rand"]), episodes=10, sessions=2).as_json()
    table = format_table(results)
    lines = table.splitlines()
    assert "LRD" in lines[0] and "Rand" in lines[0]
    assert [line.split()[0] for line in lines[2:5]] == ["OER_tau", "Cum.", "Ep."]
    assert "±" in lines[2]
    # The footer explains the exact rows only where there are some.
    assert ("OER_tau exact" in table) == ("exact: expectation" in table)
    blind = {
        **results,
        "policies": {n: {k: v for k, v in p.items() if k != "exact"} for n, p in results["policies"].items()},
    }
    assert "1 SP scene(s) (Single-Strawberry/001)" in table and "eligible starts" in table
    assert "exact" not in format_table(blind)
    out = write_json(results, tmp_path / "r" / "results.json")
    assert json.loads(out.read_text())["policies"].keys() == {"LRD", "Rand"}
    png = plot_results(results, tmp_path / "r" / "results.png")
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_commands(sp_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], one_thread: None) -> None:
    model = tmp_path / "model.zip"
    args = _parser().parse_args(
        [
            "train",
            "--dataset",
            str(sp_root),
            "--scenario",
            "sp",
            "--timesteps",
            "40",
            "--n-envs",
            "2",
            "--arch",
            "pooled",
            "--device",
            "cpu",
            "--verbose",
            "0",
            "--out",
            str(model),
        ]
    )
    assert args.func(args) == 0 and model.is_file()
    out = tmp_path / "results.json"
    args = _parser().parse_args(
        [
            "evaluate",
            "--dataset",
            str(sp_root),
            "--scenario",
            "sp",
            "--model",
            str(model),
            "--episodes",
            "5",
            "--sessions",
            "2",
            "--out",
            str(out),
        ]
    )
    assert args.func(args) == 0
    printed = capsys.readouterr().out
    assert "A2C" in printed and "Oracle" in printed and "OER_tau" in printed
    saved = json.loads(out.read_text())
    assert set(saved["policies"]) == {"LRD", "UDD", "Rand", "Oracle", "A2C", "Best fixed action"}
    assert saved["policies"]["A2C"]["play"] == "sampled"  # as reproduce plays it; --deterministic otherwise
    assert "Best fixed action: always" in printed and "OER_tau exact" in printed
    args = _parser().parse_args(
        [
            "evaluate",
            "--dataset",
            str(sp_root),
            "--scenario",
            "sp",
            "--model",
            str(model),
            "--deterministic",
            "--policies",
            "LRD",
            "--episodes",
            "3",
            "--sessions",
            "1",
            "--out",
            str(out),
            "--force",
        ]
    )
    assert args.func(args) == 0
    assert json.loads(out.read_text())["policies"]["A2C"]["play"] == "deterministic"
    assert out.with_suffix(".png").is_file()


@pytest.mark.parametrize(
    "argv, message",
    [
        (["--policies", "LRD,Bogus"], "unknown name 'Bogus'"),  # refused as parsed
        (["--episodes", "0"], "argument --episodes"),
    ],
)
def test_evaluate_bad_values_are_refused_as_parsed(
    sp_root: Path, tmp_path: Path, argv: list[str], message: str, capsys: pytest.CaptureFixture[str]
) -> None:
    with pytest.raises(SystemExit) as exit_:
        _parser().parse_args(
            ["evaluate", "--dataset", str(sp_root), "--scenario", "sp", "--out", str(tmp_path / "r.json"), *argv]
        )
    assert exit_.value.code == 2 and message in capsys.readouterr().err


def test_a_continuous_policy_on_the_grid_is_refused(sp_root: Path, tmp_path: Path) -> None:
    args = _parser().parse_args(
        [
            "evaluate",
            "--dataset",
            str(sp_root),
            "--scenario",
            "sp",
            "--out",
            str(tmp_path / "r.json"),
            "--policies",
            "LRD,Greedy",
        ]
    )
    with pytest.raises(UserError, match="not a baseline of --env grid"):
        args.func(args)
    assert not (tmp_path / "r.json").exists()


def test_evaluate_missing_model(sp_root: Path, tmp_path: Path) -> None:
    args = _parser().parse_args(
        [
            "evaluate",
            "--dataset",
            str(sp_root),
            "--scenario",
            "sp",
            "--out",
            str(tmp_path / "r.json"),
            "--model",
            "/nonexistent.zip",
        ]
    )
    with pytest.raises(UserError, match="no such model"):
        args.func(args)


def test_not_a_dataset(tmp_path: Path) -> None:
    args = _parser().parse_args(
        ["evaluate", "--dataset", str(tmp_path), "--scenario", "sp", "--out", str(tmp_path / "r.json")]
    )
    with pytest.raises(UserError, match="not a DAVIS-Ag dataset"):
        args.func(args)


def test_the_table_says_when_a_policy_plays_one_action_or_episodes_replay_few_starts(sp_root: Path) -> None:
    """A collapsed learner (one action throughout) reads like a method, and an interval over 100
    episodes of a handful of starts reads like a sure gap; the table says both."""
    from davis_ag.benchmark.agents import FixedActionAgent
    from davis_ag.benchmark.results import as_results

    results = evaluate_policies(TVMEnv(sp_root, "sp", "test"), [FixedActionAgent("left")], episodes=50, sessions=2)
    table = format_table(results)
    assert "note: always left played left only: a fixed action, not a method" in table
    starts = as_results(results).protocol.starts
    assert f"note: 100 episodes replay {starts} eligible starts" in table and starts < 50
    assert "note: one session" not in table
    one = format_table(evaluate_policies(TVMEnv(sp_root, "sp", "test"), [FixedActionAgent("left")], 5, sessions=1))
    assert "note: one session, so every ± (the spread of session means) is 0" in one


def test_a_policy_is_prepared_once_for_all_its_episodes(sp_root: Path) -> None:
    """The Policy protocol promises one ``prepare(env)`` before any episode; it ran before each."""

    class Counting:
        name = "counting"

        def __init__(self) -> None:
            self.prepared = 0

        def prepare(self, env: object) -> None:
            self.prepared += 1

        def reset(self, seed: int | None = None) -> None:
            pass

        def act(self, observation: np.ndarray, info: dict) -> str:
            return "done"

    policy = Counting()
    evaluate_policies(TVMEnv(sp_root, "sp", "test"), [policy], episodes=5, sessions=2)
    assert policy.prepared == 1

"""Scoring row mapping: baselines beside the bound, the results file read back, replayed and ranked."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest

from davis_ag.cli import main
from davis_ag.errors import UserError
from davis_ag.mapping.evaluation import evaluate_mapping, replay_mapping
from davis_ag.mapping.leaderboard import mapping_leaderboard
from davis_ag.mapping.results import (
    MappingResults,
    coverage_curve,
    load_mapping_results,
    summarise,
)
from layout_factory import write_tiny_dataset


@pytest.fixture(scope="module")
def tiny_mp(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_tiny_dataset(tmp_path_factory.mktemp("mp"), "mp", "vine", scenes=2)


@pytest.fixture(scope="module")
def results(tiny_mp: Path) -> MappingResults:
    return evaluate_mapping([], tiny_mp, scenario="mp", split="all", sessions=2, episodes=15, budget=8)


def test_greedy_maps_at_least_as_much_as_the_sweep_and_nobody_beats_the_bound(results: MappingResults) -> None:
    rows = results.policies
    assert set(rows) == {"Sweep", "Rand", "Greedy", "Best fixed move"}
    assert rows["Best fixed move"].source.startswith("always ")
    assert rows["Greedy"].coverage.mean >= rows["Sweep"].coverage.mean
    assert rows["Greedy"].coverage.mean >= rows["Rand"].coverage.mean
    for row in rows.values():
        for episode in row.episodes:
            segment = results.segments[episode.scene]
            part = next(p for p in segment.parts if p.index == episode.part)
            final = coverage_curve(episode, results.protocol.budget)[-1]
            assert final <= part.bound <= part.ceiling <= segment.ceiling <= segment.fruit
            assert episode.part_ceiling == part.ceiling
            assert len(episode.actions) == results.protocol.budget == len(episode.path) - 1
    # Every policy mapped from the same starts.
    starts = [[e.path[0] for e in row.episodes] for row in rows.values()]
    assert all(s == starts[0] for s in starts)


def test_the_file_reads_back_and_replays_sound(results: MappingResults, tiny_mp: Path, tmp_path: Path) -> None:
    path = results.write(tmp_path / "mapping.json")
    again = load_mapping_results(path)
    assert again == results
    report = replay_mapping(again, tiny_mp, str(path))
    assert report.sound, report.text()
    assert report.episodes == 4 * 2 * 15


def _forge(results: MappingResults, policy: str, episode: int) -> MappingResults:
    """Change one episode's last action and fit every summary to it, as a forger would."""
    data = results.as_json()
    row = data["policies"][policy]
    stored = row["episodes"][episode]
    stored["actions"][-1] = (stored["actions"][-1] + 1) % len(data["protocol"]["actions"])
    forged = MappingResults.model_validate(data)
    fresh = summarise(
        forged.policies[policy].episodes, forged.protocol.budget, forged.protocol.sessions, forged.segments
    )
    row.update(json.loads(json.dumps(fresh)))
    return MappingResults.model_validate(data)


def test_a_forged_episode_is_named(results: MappingResults, tiny_mp: Path) -> None:
    forged = _forge(results, "Greedy", 17)  # session 1, episode 2
    report = replay_mapping(forged, tiny_mp, "forged.json")
    assert not report.sound
    assert "Greedy session 1 episode 2" in report.text()


def test_an_edited_summary_is_refused(results: MappingResults, tmp_path: Path) -> None:
    data = results.as_json()
    data["policies"]["Rand"]["coverage"]["mean"] = 0.99
    path = tmp_path / "edited.json"
    path.write_text(json.dumps(data))
    with pytest.raises(UserError, match="Rand's coverage is not what its episodes give"):
        load_mapping_results(path)


def test_the_leaderboard_ranks_by_coverage_and_refuses_other_budgets(
    results: MappingResults, tiny_mp: Path, tmp_path: Path
) -> None:
    a = results.write(tmp_path / "a.json")
    page = mapping_leaderboard([a])
    ranked = [
        line.split("|")[2].strip() for line in page.splitlines() if line.startswith("| 1 ") or line.startswith("| 2 ")
    ]
    assert ranked[0] == "Greedy"
    other = evaluate_mapping(
        [], tiny_mp, scenario="mp", split="all", sessions=1, episodes=3, budget=4, baselines=["Rand"]
    )
    b = other.write(tmp_path / "b.json")
    with pytest.raises(UserError, match="budget"):
        mapping_leaderboard([a, b])


def test_a_users_policy_is_scored_beside_the_baselines(tiny_mp: Path) -> None:
    def always_right(observation: np.ndarray, info: dict) -> str:
        return "right"

    scored = evaluate_mapping([always_right], tiny_mp, scenario="mp", split="all", sessions=1, episodes=4, budget=3)
    assert "always_right" in scored.policies
    assert all(set(e.actions) == {3} for e in scored.policies["always_right"].episodes)


def test_the_command_writes_the_file_and_the_curves_and_verify_replays_it(
    tiny_mp: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    out = tmp_path / "m.json"
    argv = ["evaluate", "--task", "mapping", "--dataset", str(tiny_mp), "--scenario", "mp", "--split", "all"]
    assert main([*argv, "--episodes", "4", "--sessions", "1", "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "| Greedy |" in printed and "Bound: the best" in printed
    assert out.is_file() and out.with_suffix(".png").is_file()
    assert main(["verify", str(out), "--dataset", str(tiny_mp)]) == 0
    assert "sound" in capsys.readouterr().out
    assert main(["compare", str(out)]) == 0
    assert "Row mapping" in capsys.readouterr().out


@pytest.mark.parametrize(
    ("extra", "message"),
    [
        (["--budget", "5"], "are for --task mapping"),
        (["--task", "mapping", "--env", "continuous"], "plays the grid"),
        (["--task", "mapping", "--policies", "Oracle"], "not a baseline of --task mapping"),
    ],
)
def test_bad_flags_are_one_line(
    tiny_mp: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], extra: list[str], message: str
) -> None:
    out = tmp_path / "m.json"
    argv = ["evaluate", "--dataset", str(tiny_mp), "--scenario", "mp", "--out", str(out), *extra]
    assert main(argv) == 2
    err = capsys.readouterr().err
    assert message in err and len(err.strip().splitlines()) == 1
    assert not out.exists()

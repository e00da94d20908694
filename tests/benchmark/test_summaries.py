"""Every reader of a results file makes its summaries again from the episodes: an edited summary
is refused in one line naming the policy and the field (issue 44)."""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import Any

import pytest
from hypothesis import given
from hypothesis import strategies as st

from davis_ag import cli
from davis_ag.benchmark import evaluate
from davis_ag.benchmark.results import load_results
from davis_ag.benchmark.summaries import session_metrics


def _always_up(observation: Any, info: dict[str, Any]) -> str:
    return "up"


@pytest.fixture(scope="module")
def results_file(sp_root: Path, tmp_path_factory: pytest.TempPathFactory) -> Path:
    """An untouched evaluation of one policy and the grid's baselines, 2 sessions x 6 episodes."""
    folder = tmp_path_factory.mktemp("summaries")
    return evaluate([_always_up], sp_root, "sp", sessions=2, episodes=6).write(folder / "results.json")


def _edited(source: Path, folder: Path, edit: Callable[[dict[str, Any]], None]) -> Path:
    data = json.loads(source.read_text())
    edit(data)
    path = folder / "edited.json"
    path.write_text(json.dumps(data))
    return path


def test_an_untouched_file_is_read_and_ranked(results_file: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert set(load_results(results_file).policies) >= {"_always_up", "LRD", "Rand", "Best fixed action"}
    assert cli.main(["compare", str(results_file)]) == 0
    assert "| 1 |" in capsys.readouterr().out


def _lrd(data: dict[str, Any]) -> dict[str, Any]:
    return data["policies"]["LRD"]


@pytest.mark.parametrize(
    "edit, field",
    [
        # The case: LRD's mean raised to .999, its episodes untouched, came first (exit 0).
        (lambda d: _lrd(d)["oer_tau"].update(mean=0.999), "LRD's oer_tau.mean is 0.999"),
        (lambda d: _lrd(d)["reward"].update(std=_lrd(d)["reward"]["std"] + 1e-4), "LRD's reward.std"),
        (lambda d: _lrd(d)["length"]["sessions"].__setitem__(1, 1.0), "LRD's length.sessions[1]"),
        (lambda d: _lrd(d)["oer_0"].update(sem=0.5), "LRD's oer_0.sem"),
        (lambda d: _lrd(d)["action_counts"].update(up=_lrd(d)["action_counts"]["up"] + 1), "action_counts.up"),
        (lambda d: _lrd(d)["paired"]["Rand"].update(high=0.5), "LRD's paired.Rand.high"),
        (lambda d: _lrd(d)["paired"]["Rand"]["per_scene"][0].update(gap=0.2), "paired.Rand.per_scene[0].gap"),
        (lambda d: _lrd(d)["episodes"].pop(), "LRD holds 11 episodes, not 2 sessions x 6"),
        (lambda d: _lrd(d)["episodes"][0].update(target_fruit=-5), "do not start where its baselines' do"),
        (lambda d: _lrd(d).pop("episodes"), "LRD kept no episodes"),
    ],
)
def test_an_edited_summary_is_refused_by_every_reader(
    edit: Callable[[dict[str, Any]], None],
    field: str,
    results_file: Path,
    sp_root: Path,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
) -> None:
    edited = _edited(results_file, tmp_path, edit)
    readers = [
        ["compare", str(edited)],
        ["plot", "actions", "--results", str(edited), "--out", str(tmp_path / "actions")],
        ["verify", str(edited), "--dataset", str(sp_root)],
    ]
    for reader in readers:
        assert cli.main(reader) == 2, reader
        err = capsys.readouterr().err.strip()
        assert field in err and str(edited) in err and "\n" not in err, (reader, err)
    assert not (tmp_path / "actions.png").exists()


def test_a_file_from_before_the_interval_over_scenes_is_still_read(results_file: Path, tmp_path: Path) -> None:
    def drop(data: dict[str, Any]) -> None:
        for policy in data["policies"].values():
            for gap in policy["paired"].values():
                gap.pop("scene_low", None), gap.pop("scene_high", None)

    assert load_results(_edited(results_file, tmp_path, drop)).policies["LRD"].paired["Rand"].scene_low is None


@given(
    st.lists(
        st.lists(st.floats(0, 1, allow_nan=False), min_size=1, max_size=6),
        min_size=1,
        max_size=4,
    )
)
def test_session_metrics_are_table_4s_mean_and_std_of_session_means(sessions: list[list[float]]) -> None:
    records = [{"session": s, "oer_tau": v} for s, values in enumerate(sessions) for v in values]
    metric = session_metrics(records, ("oer_tau",), len(sessions))["oer_tau"]
    means = [sum(values) / len(values) for values in sessions]
    assert metric["sessions"] == pytest.approx(means)
    assert metric["mean"] == pytest.approx(sum(means) / len(means))
    spread = (sum((m - metric["mean"]) ** 2 for m in means) / len(means)) ** 0.5  # population std (ddof 0)
    assert metric["std"] == pytest.approx(spread, abs=1e-12)
    values = [v for values in sessions for v in values]
    mean = sum(values) / len(values)
    assert metric["sem"] == pytest.approx(
        (sum((v - mean) ** 2 for v in values) / len(values)) ** 0.5 / len(values) ** 0.5, abs=1e-12
    )

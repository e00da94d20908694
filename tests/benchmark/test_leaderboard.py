"""davis-ag compare: a leaderboard of results of one dataset, split and protocol, and nothing else."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import pytest

from davis_ag import cli
from davis_ag.benchmark import evaluate
from davis_ag.benchmark.leaderboard import format_leaderboard, leaderboard
from davis_ag.benchmark.results import load_results
from davis_ag.errors import UserError
from layout_factory import write_tiny_dataset


def _always(move: str):
    def policy(observation, info):
        return move

    policy.__name__ = f"always_{move}"
    return policy


def test_compare_ranks_methods_with_their_gaps(
    sp_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    first = evaluate([_always("up")], sp_root, "sp", sessions=2, episodes=6).write(tmp_path / "up.json")
    second = evaluate([_always("down")], sp_root, "sp", sessions=2, episodes=6).write(tmp_path / "down.json")
    rows = leaderboard([first, second])
    names = [r.name for r in rows]
    # The baselines of both files played the same episodes: one row each.
    assert sorted(names) == sorted(["always_up", "always_down", "LRD", "UDD", "Rand", "Oracle", "Best fixed action"])
    assert [r.policy.oer_tau.mean for r in rows] == sorted((r.policy.oer_tau.mean for r in rows), reverse=True)
    assert all(r.gaps["Rand"] is not None for r in rows if r.name != "Rand")
    page = tmp_path / "board.md"
    assert cli.main(["compare", str(first), str(second), "--out", str(page)]) == 0
    text = page.read_text()
    assert text == format_leaderboard(rows) and text in capsys.readouterr().out
    assert "1 SP scene(s) (Single-Strawberry/001)" in text and "eligible starts" in text
    assert "Gap to Best fixed action [95 %]" in text


def test_gaps_over_several_scenes_give_the_interval_over_scenes_too(sp_root: Path, tmp_path: Path) -> None:
    # With two scenes or more, each gap also says whether it would hold on other scenes like these.
    from davis_ag.benchmark.results_table import format_table

    results = evaluate([_always("up")], sp_root, "sp", split="all", sessions=2, episodes=8)
    scenes = {e.scene for e in results.policies["always_up"].episodes}
    assert len(scenes) >= 2
    gap = results.policies["always_up"].paired["Rand"]
    assert gap.scene_low is not None and gap.scene_low <= gap.scene_high
    assert "  over scenes" in format_table(results)
    one_scene = evaluate([_always("up")], sp_root, "sp", sessions=1, episodes=4)  # the test split: one scene
    assert "over scenes" not in format_table(one_scene)
    rows = leaderboard([results.write(tmp_path / "up.json")])
    assert " scenes [" in format_leaderboard(rows) and "over the test scenes resampled" in format_leaderboard(rows)
    # A file from before the interval over scenes gets it from its episodes.
    path = tmp_path / "old.json"
    data = json.loads((tmp_path / "up.json").read_text())
    for policy in data["policies"].values():
        for gap in policy.get("paired", {}).values():
            gap.pop("scene_low", None), gap.pop("scene_high", None)
    path.write_text(json.dumps(data))
    row = next(r for r in leaderboard([path]) if r.name == "always_up")
    assert row.gaps["Rand"].scene_low == gap_rand_low(rows)


def gap_rand_low(rows: list) -> float:
    return next(r for r in rows if r.name == "always_up").gaps["Rand"].scene_low


def test_compare_refuses_another_dataset_or_split(
    sp_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    ours = evaluate([], sp_root, "sp", sessions=1, episodes=3).write(tmp_path / "ours.json")
    other_root = write_tiny_dataset(tmp_path / "other", "sp", "strawberry", scenes=2, seed=7)
    theirs = evaluate([], other_root, "sp", sessions=1, episodes=3).write(tmp_path / "theirs.json")
    train = evaluate([], sp_root, "sp", split="train", sessions=1, episodes=3).write(tmp_path / "train.json")
    for other, what in ((theirs, "differ in dataset"), (train, "differ in split")):
        assert cli.main(["compare", str(ours), str(other)]) == 2
        err = capsys.readouterr().err.strip()
        assert what in err and "cannot be ranked together" in err and "\n" not in err


def test_compare_ranks_files_made_before_and_after_the_dataset_gained_a_group(
    sp_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """The crops run adds a group at a time: its results of a group made before the next group was
    added were refused beside an evaluation of the same scenes made after."""
    grown = shutil.copytree(sp_root, tmp_path / "grown")
    before = evaluate([], grown, "sp", crop="strawberry", sessions=1, episodes=3).write(tmp_path / "before.json")
    write_tiny_dataset(grown, "sp", "tomato", scenes=2)
    after = evaluate([_always("up")], grown, "sp", crop="strawberry", sessions=1, episodes=3)
    after.write(tmp_path / "after.json")
    assert cli.main(["compare", str(before), str(tmp_path / "after.json")]) == 0
    small, large = load_results(before).dataset, after.dataset
    assert small is not None and large is not None
    # The page names both datasets (the baselines' rows are the first file's, always_up's the second's).
    assert (
        f"Datasets {small.fingerprint} ({len(small.scenes)} scenes), "
        f"{large.fingerprint} ({len(small.scenes) + 2} scenes)"
    ) in capsys.readouterr().out
    # A scene it played that is now another (here: drawn from another seed) is still refused.
    write_tiny_dataset(grown, "sp", "strawberry", scenes=2, seed=7)
    redrawn = evaluate([], grown, "sp", crop="strawberry", sessions=1, episodes=3).write(tmp_path / "redrawn.json")
    assert cli.main(["compare", str(before), str(redrawn)]) == 2
    assert "differ in dataset: scene Single-Strawberry/001 has seed 7001 against 1" in capsys.readouterr().err


def test_compare_refuses_the_same_seeds_drawn_otherwise(
    sp_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """Scene seeds follow from the dataset seed alone: a copy drawn with another appearance (or
    size, renderer, plants, grid) has the same seeds and, on TVM-v0, the same starts. It was
    ranked beside the original until the identity recorded how each scene was drawn."""
    copy = shutil.copytree(sp_root, tmp_path / "copy")
    ours = evaluate([], sp_root, "sp", sessions=1, episodes=3).write(tmp_path / "ours.json")
    same = evaluate([], copy, "sp", sessions=1, episodes=3).write(tmp_path / "same.json")
    assert cli.main(["compare", str(ours), str(same)]) == 0  # a copy elsewhere is the same dataset
    for path in copy.glob("*/*/scene.json"):
        meta = json.loads(path.read_text())
        meta["appearance"] = {"mode": "random"}
        path.write_text(json.dumps(meta))
    other = evaluate([], copy, "sp", sessions=1, episodes=3).write(tmp_path / "other.json")
    capsys.readouterr()
    assert cli.main(["compare", str(ours), str(other)]) == 2
    err = capsys.readouterr().err.strip()
    assert "scene Single-Strawberry/001 was drawn otherwise" in err and "\n" not in err  # the scene played
    # A file from before the identity said how scenes were drawn: evaluate it again.
    for name in ("ours", "old"):
        data = json.loads((tmp_path / "ours.json").read_text())
        for scene in data["dataset"]["scenes"]:
            scene["code"] = "0.1.0+abc"
            if name == "old":
                scene.pop("drawn")
        data["dataset"]["fingerprint"] = name
        (tmp_path / f"{name}.json").write_text(json.dumps(data))
    assert cli.main(["compare", str(tmp_path / "ours.json"), str(tmp_path / "old.json")]) == 2
    assert "evaluate it again" in capsys.readouterr().err


@pytest.mark.parametrize(
    "damage, where",
    [
        (lambda d: d.update(policies={}), "policies"),
        (lambda d: d.update(format="something else"), "format"),
        (lambda d: d["protocol"].update(version=99), "protocol.version"),
        (lambda d: d["protocol"].update(episodes=-3), "protocol.episodes"),
        (lambda d: d["protocol"].update(scenario="banana"), "protocol.scenario"),
        (lambda d: next(iter(d["policies"].values()))["oer_tau"].update(mean=float("nan")), "oer_tau.mean"),
    ],
)
def test_a_file_that_is_not_sound_results_is_refused_in_one_line(
    damage: Any, where: str, sp_root: Path, tmp_path: Path
) -> None:
    """compare ranked a file with no policies (an IndexError), another format, a future protocol
    version, negative episodes, an unknown scenario and NaN means."""
    sound = evaluate([], sp_root, "sp", sessions=1, episodes=2).write(tmp_path / "sound.json")
    data = json.loads(sound.read_text())
    damage(data)
    bad = tmp_path / "bad.json"
    bad.write_text(json.dumps(data))
    with pytest.raises(UserError, match=f"not davis-ag evaluation results \\(.*{where}") as error:
        leaderboard([bad])
    assert "\n" not in str(error.value)

"""TVM-v0 under each split rule: ``scenes`` plays exactly the scenes and starts it played before
the rules; under ``starts`` and ``fruits`` train and test play the same scenes and never the same
(view, target) start, 70/30 of each group's eligible starts."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest

from davis_ag.benchmark import exact
from davis_ag.benchmark.splits import dataset_splits, select_scenes
from davis_ag.benchmark.starts import eligible, min_pixels, start_names
from davis_ag.benchmark.tvm import TVMEnv
from davis_ag.data.reader import open_dataset
from davis_ag.errors import UserError
from davis_ag.formats.splits import split_scenes, train_count
from layout_factory import write_tiny_dataset
from real_scenes import ROBOT_VINE, generate_config


def names(env: TVMEnv) -> list[tuple[str, str, int]]:
    """Every start an environment draws from, by its identity."""
    return [
        start_names(env.scenes[scene].id, env.caches[scene], np.array([box]))[0] for scene, box in env.starts.tolist()
    ]


def check_sides(root: Path, scenario: str, rule: str) -> tuple[TVMEnv, TVMEnv]:
    """Train and test of ``rule`` play the same scenes and disjoint starts that make up ``all``'s,
    70/30 (round) of each group's; returns the two environments."""
    train, test, every = (TVMEnv(root, scenario, split, split_rule=rule) for split in ("train", "test", "all"))
    assert [s.id for s in train.scenes] == [s.id for s in test.scenes] == [s.id for s in every.scenes]
    ours, theirs, whole = set(names(train)), set(names(test)), set(names(every))
    assert len(ours) == len(train.starts) and len(theirs) == len(test.starts)
    assert not ours & theirs
    assert ours | theirs == whole
    if rule == "starts":
        for group in {s[0].split("/")[0] for s in whole}:
            held = [s for s in whole if s[0].startswith(group + "/")]
            assert sum(s in ours for s in held) == train_count(len(held))
    if rule == "fruits":
        assert not {(s[0], s[2]) for s in ours} & {(s[0], s[2]) for s in theirs}
    return train, test


@pytest.mark.parametrize("rule", ["starts", "fruits"])
def test_starts_split_within_the_same_scenes(tmp_path: Path, rule: str) -> None:
    root = write_tiny_dataset(tmp_path, "sp", "strawberry", scenes=3)
    write_tiny_dataset(tmp_path, "sp", "tomato", scenes=2)  # two groups: each splits on its own
    train, test = check_sides(root, "sp", rule)
    assert train.describe()["split_rule"] == rule
    # Every start-set consumer reads the side: the exact expectations are over the test starts only.
    assert len(exact.fixed_action_expectations(test)) == len(test.action_names)
    _, info = test.reset(seed=0)
    assert (info["scene"], info["path"][0], info["target_fruit"]) in set(names(test))


def test_the_scenes_rule_is_the_split_as_it_was(tmp_path: Path) -> None:
    root = write_tiny_dataset(tmp_path, "sp", "strawberry", scenes=5, splits=False)  # drawn by the rule itself
    dataset = open_dataset(root)
    wanted = split_scenes([s.id for s in dataset.scenes], 0)
    assert dataset_splits(dataset) == wanted
    for split in ("train", "test"):
        env = TVMEnv(dataset, "sp", split, split_rule="scenes")
        before = TVMEnv(dataset, "sp", split)  # no rule given: scenes, as before the rules
        assert [s.id for s in env.scenes] == wanted[split] == [s.id for s in select_scenes(dataset, "sp", split)]
        assert np.array_equal(env.starts, before.starts)
        # Every eligible start of the split's scenes, in scene, view, annotation order.
        every = [
            start_names(s.id, c, np.flatnonzero(eligible(c, min_pixels(s, c), 0.4)))
            for s, c in zip(env.scenes, env.caches)
        ]
        assert sorted(names(env)) == sorted(n for each in every for n in each)


def test_an_unknown_rule_is_one_line(sp_root: Path) -> None:
    with pytest.raises(UserError, match="unknown split_rule 'scene': choose one of scenes, starts, fruits"):
        TVMEnv(sp_root, "sp", "test", split_rule="scene")


@pytest.fixture(scope="module")
def real_vine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return generate_config(tmp_path_factory, "vine", ROBOT_VINE)


@pytest.mark.slow
def test_one_real_scene_splits_its_starts(real_vine: Path) -> None:
    """A real Helios vine scene: the scenes rule has no test scene in a one-scene group; the starts
    rule tests on 30 % of its starts."""
    with pytest.raises(UserError, match="the test split has none"):
        TVMEnv(real_vine, "sp", "test")
    train, test = check_sides(real_vine, "sp", "starts")
    assert len(train.starts) > len(test.starts) > 0
    assert len(test.starts) == len(train.starts) + len(test.starts) - train_count(len(train.starts) + len(test.starts))

"""The split rules of section V-D's 70/30 split: ``scenes`` exactly as before the rules, and
``starts``/``fruits`` never putting a start (or a target fruit) on both sides, 70/30 per group."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st

from davis_ag.errors import UserError
from davis_ag.formats.splits import (
    SPLIT_RULES,
    TRAIN_FRACTION,
    check_split_rule,
    split_group,
    split_scenes,
    split_starts,
    train_count,
)
from davis_ag.scene.specs import CROPS, SCENARIOS, parse_group_name
from davis_ag.seeds import SPLIT_STREAM

GROUPS = ("Single-Strawberry", "Single-Vine", "Multi-Tomato", "Multi-Vine", "not-a-group")
scene_ids = st.builds(lambda g, i: f"{g}/{i:03d}", st.sampled_from(GROUPS), st.integers(0, 30))
start_sets = st.sets(
    st.tuples(scene_ids, st.sampled_from([f"v{i:02d}" for i in range(12)]), st.integers(0, 40)), max_size=150
)
seeds = st.integers(0, 2**32 - 1)


def _split_group_before_the_rules(scene_ids: list[str], seed: int) -> dict[str, list[str]]:
    """split_group as it was written before the split rules (the scenes rule must not move)."""
    ids = sorted(scene_ids)
    parsed = parse_group_name(ids[0].split("/")[0]) if ids else None
    stream = [list(SCENARIOS).index(parsed[0].name), list(CROPS).index(parsed[1].name)] if parsed else [0, 0]
    order = np.random.default_rng(np.random.SeedSequence([seed, *stream, SPLIT_STREAM])).permutation(len(ids))
    n_train = round(TRAIN_FRACTION * len(ids))
    if len(ids) >= 2:
        n_train = min(max(n_train, 1), len(ids) - 1)
    return {"train": sorted(ids[i] for i in order[:n_train]), "test": sorted(ids[i] for i in order[n_train:])}


@given(st.sets(st.integers(0, 200), max_size=60), st.sampled_from(GROUPS), seeds)
def test_the_scenes_rule_splits_exactly_as_before(numbers: set[int], group: str, seed: int) -> None:
    ids = [f"{group}/{n:03d}" for n in numbers]
    assert split_group(ids, seed) == _split_group_before_the_rules(ids, seed)
    assert split_scenes(reversed(ids), seed) == _split_group_before_the_rules(ids, seed)


def _by_group(starts: list[tuple[str, str, int]]) -> dict[str, list[tuple[str, str, int]]]:
    groups: dict[str, list[tuple[str, str, int]]] = {}
    for start in starts:
        groups.setdefault(start[0].split("/")[0], []).append(start)
    return groups


@given(start_sets, seeds)
def test_no_start_is_on_both_sides_and_each_group_splits_70_30(starts: set, seed: int) -> None:
    split = split_starts(starts, seed)
    train, test = set(split["train"]), set(split["test"])
    assert not train & test
    assert train | test == starts
    for group, members in _by_group(sorted(starts)).items():
        n = len(members)
        held = sum(s[0].split("/")[0] == group for s in train)
        assert held == train_count(n)
        assert held == (round(0.7 * n) if n < 2 else min(max(round(0.7 * n), 1), n - 1))


@given(start_sets, seeds, st.randoms())
def test_a_split_depends_only_on_the_seed_and_the_set(starts: set, seed: int, random) -> None:
    listed = sorted(starts) * 2  # each start twice, in another order
    random.shuffle(listed)
    for rule in SPLIT_RULES[1:]:
        assert split_starts(listed, seed, rule) == split_starts(starts, seed, rule)


@given(start_sets, seeds)
def test_the_fruits_rule_puts_each_target_fruit_on_one_side(starts: set, seed: int) -> None:
    split = split_starts(starts, seed, "fruits")
    fruits = {side: {(s[0], s[2]) for s in split[side]} for side in ("train", "test")}
    assert not fruits["train"] & fruits["test"]
    assert set(split["train"]) | set(split["test"]) == starts
    for group in _by_group(sorted(starts)):
        n = len({(s[0], s[2]) for s in starts if s[0].split("/")[0] == group})
        assert sum(f[0].split("/")[0] == group for f in fruits["train"]) == train_count(n)


def test_the_rules_draw_from_streams_of_their_own() -> None:
    """The starts of 40 one-view scenes split as their scenes would on the scenes stream only by chance."""
    ids = [f"Single-Strawberry/{i:03d}" for i in range(40)]
    by_scenes = split_group(ids, 0)["train"]
    by_starts = [s[0] for s in split_starts([(i, "v", 1) for i in ids], 0)["train"]]
    by_fruits = [s[0] for s in split_starts([(i, "v", 1) for i in ids], 0, "fruits")["train"]]
    assert len(by_scenes) == len(by_starts) == len(by_fruits) == 28
    assert by_scenes != by_starts and by_starts != by_fruits


def test_an_unknown_rule_is_one_line() -> None:
    assert check_split_rule("starts") == "starts"
    with pytest.raises(UserError, match="unknown split_rule 'views': choose one of scenes, starts, fruits"):
        check_split_rule("views")
    with pytest.raises(UserError, match="splits by starts or fruits, not 'scenes'"):
        split_starts([], 0, "scenes")

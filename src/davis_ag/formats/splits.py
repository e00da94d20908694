"""The train/test split rules (section V-D: "the same split is applied to use 70 % and 30 % data
for training and test environments"), read three ways (:data:`SPLIT_RULES`):

- ``scenes`` (the default): 70 % of each group's scenes train, 30 % test. The generator writes it
  into ``splits.json``; a dataset without one (the original download) is split by the same rule
  with the dataset seed of its ``dataset.json``, else 0, so the benchmark, the exports and the
  generator always agree on which scenes test. Per group (scenario and crop, i.e. one published
  folder such as ``Single-Strawberry``): the ids are sorted, shuffled by a generator seeded with
  the dataset seed and the group, and the first ``round(0.7 n)`` train, keeping a scene on each
  side when the group has two or more.
- ``starts``: the episode starts of every scene of a group, each named by (scene id, view name,
  target fruit id), split 70/30 by the same rule on a stream of their own
  (:data:`~davis_ag.seeds.START_SPLIT_STREAM`): train and test play the same scenes, never the
  same start.
- ``fruits``: the target fruits of a group, each named by (scene id, fruit id), split 70/30 on a
  stream of their own (:data:`~davis_ag.seeds.FRUIT_SPLIT_STREAM`); a start goes with its fruit,
  so no fruit is a target on both sides.

Each split depends only on the seed and the set it splits.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from pathlib import Path
from typing import TypeVar

from davis_ag.errors import UserError
from davis_ag.formats.layout import DATASET_FILE
from davis_ag.scene.specs import CROPS, SCENARIOS, parse_group_name
from davis_ag.seeds import FRUIT_SPLIT_STREAM, SPLIT_STREAM, START_SPLIT_STREAM, stream_rng

#: Share of each group's scenes in the training split (section V-D).
TRAIN_FRACTION = 0.7
#: The split rules (see the module docstring); ``scenes`` is the default and what splits.json holds.
SPLIT_RULES = ("scenes", "starts", "fruits")
#: A start's identity: (scene id, view name, target fruit id).
Start = tuple[str, str, int]


def split_group(scene_ids: Sequence[str], seed: int) -> dict[str, list[str]]:
    """The seeded 70/30 train/test split of one group's scenes.

    Args:
        scene_ids: Ids of one group, e.g. ``Single-Strawberry/003``, any order.
        seed: The dataset seed.

    Returns:
        ``{"train": [...], "test": [...]}``, each sorted; depends only on the seed and the set of ids.
    """
    ids = sorted(scene_ids)
    # A stream of its own (the trailing 1) so the split never correlates with any scene seed.
    return _split_sorted(ids, seed, _group_keys(ids[0] if ids else ""), SPLIT_STREAM)


def _group_keys(scene_id: str) -> list[int]:
    """The group's keys of a split's stream: its scenario's and crop's indices (0, 0 for a folder
    that names no group)."""
    parsed = parse_group_name(scene_id.split("/")[0]) if scene_id else None
    return [list(SCENARIOS).index(parsed[0].name), list(CROPS).index(parsed[1].name)] if parsed else [0, 0]


def train_count(n: int) -> int:
    """How many of a group's ``n`` items train: ``round(0.7 n)``, at least one on each side from two."""
    n_train = round(TRAIN_FRACTION * n)
    return min(max(n_train, 1), n - 1) if n >= 2 else n_train


T = TypeVar("T", str, tuple[str, int], tuple[str, str, int])


def _split_sorted(items: list[T], seed: int, group: list[int], stream: int) -> dict[str, list[T]]:
    """Shuffle the sorted ``items`` of one group on the stream ``[seed, *group, stream]``; the
    first :func:`train_count` train."""
    order = stream_rng(seed, *group, stream).permutation(len(items))
    n_train = train_count(len(items))
    return {"train": sorted(items[i] for i in order[:n_train]), "test": sorted(items[i] for i in order[n_train:])}


def split_scenes(scene_ids: Iterable[str], seed: int) -> dict[str, list[str]]:
    """Split every group of a dataset's scenes (grouped by their folder) with :func:`split_group`.

    Returns:
        ``{"train": [...], "test": [...]}`` over all groups, each sorted.
    """
    groups: dict[str, list[str]] = {}
    for scene_id in scene_ids:
        groups.setdefault(str(scene_id).split("/")[0], []).append(str(scene_id))
    train: list[str] = []
    test: list[str] = []
    for ids in groups.values():
        split = split_group(ids, seed)
        train += split["train"]
        test += split["test"]
    return {"train": sorted(train), "test": sorted(test)}


def split_starts(starts: Iterable[Start], seed: int, rule: str = "starts") -> dict[str, list[Start]]:
    """Split a dataset's episode starts by the ``starts`` or ``fruits`` rule, group by group.

    Args:
        starts: (scene id, view name, target fruit id) of every eligible start, any order;
            a start given twice counts once.
        seed: The dataset seed.
        rule: ``starts`` (each start on one side) or ``fruits`` (each target fruit on one side,
            its starts with it).

    Returns:
        ``{"train": [...], "test": [...]}`` over all groups, each sorted; depends only on the seed,
        the rule and the set of starts.

    Raises:
        UserError: for another rule.
    """
    if rule not in SPLIT_RULES[1:]:
        raise UserError(f"split_starts splits by {' or '.join(SPLIT_RULES[1:])}, not {rule!r}")
    groups: dict[str, set[Start]] = {}
    for scene_id, view, fruit in starts:
        groups.setdefault(str(scene_id).split("/")[0], set()).add((str(scene_id), str(view), int(fruit)))
    train: list[Start] = []
    test: list[Start] = []
    for members in groups.values():
        ordered = sorted(members)
        keys = _group_keys(ordered[0][0])
        if rule == "starts":
            split = _split_sorted(ordered, seed, keys, START_SPLIT_STREAM)
        else:
            fruits = _split_sorted(sorted({(s, f) for s, _, f in ordered}), seed, keys, FRUIT_SPLIT_STREAM)
            chosen = set(fruits["train"])
            split = {"train": [s for s in ordered if (s[0], s[2]) in chosen]}
            split["test"] = [s for s in ordered if (s[0], s[2]) not in chosen]
        train += split["train"]
        test += split["test"]
    return {"train": sorted(train), "test": sorted(test)}


def check_split_rule(rule: str, where: str = "split_rule") -> str:
    """A split rule's name, checked.

    Raises:
        UserError: one line naming the rules.
    """
    if rule not in SPLIT_RULES:
        raise UserError(f"unknown {where} {rule!r}: choose one of {', '.join(SPLIT_RULES)}")
    return rule


def recorded_seed(root: str | Path) -> int:
    """The dataset seed ``<root>/dataset.json`` records, 0 without a readable one (the original
    download has none).

    Raises:
        UserError: when dataset.json records a seed that is no dataset seed (negative, a fraction,
            too large): the split drawn from it would be another one.
    """
    from davis_ag.formats.models import check_seed

    path = Path(root) / DATASET_FILE
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError, RecursionError):
        return 0
    if not isinstance(data, dict) or "seed" not in data:
        return 0
    return check_seed(data["seed"], f"{path}: seed")

"""The one train/test split rule (section V-D: 70 % of each group's scenes train, 30 % test).

The generator writes it into ``splits.json``; a dataset without one (the original download) is
split by the same rule with the dataset seed of its ``dataset.json``, else 0, so the benchmark,
the exports and the generator always agree on which scenes test.

Per group (scenario and crop, i.e. one published folder such as ``Single-Strawberry``): the ids
are sorted, shuffled by a generator seeded with the dataset seed and the group, and the first
``round(0.7 n)`` train, keeping a scene on each side when the group has two or more.
"""

from __future__ import annotations

import json
from collections.abc import Iterable, Sequence
from pathlib import Path

from davis_ag.formats.layout import DATASET_FILE
from davis_ag.scene.specs import CROPS, SCENARIOS, parse_group_name
from davis_ag.seeds import SPLIT_STREAM, stream_rng

#: Share of each group's scenes in the training split (section V-D).
TRAIN_FRACTION = 0.7


def split_group(scene_ids: Sequence[str], seed: int) -> dict[str, list[str]]:
    """The seeded 70/30 train/test split of one group's scenes.

    Args:
        scene_ids: Ids of one group, e.g. ``Single-Strawberry/003``, any order.
        seed: The dataset seed.

    Returns:
        ``{"train": [...], "test": [...]}``, each sorted; depends only on the seed and the set of ids.
    """
    ids = sorted(scene_ids)
    parsed = parse_group_name(ids[0].split("/")[0]) if ids else None
    stream = [list(SCENARIOS).index(parsed[0].name), list(CROPS).index(parsed[1].name)] if parsed else [0, 0]
    # A stream of its own (the trailing 1) so the split never correlates with any scene seed.
    order = stream_rng(seed, *stream, SPLIT_STREAM).permutation(len(ids))
    n_train = round(TRAIN_FRACTION * len(ids))
    if len(ids) >= 2:
        n_train = min(max(n_train, 1), len(ids) - 1)
    return {"train": sorted(ids[i] for i in order[:n_train]), "test": sorted(ids[i] for i in order[n_train:])}


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

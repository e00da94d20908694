"""Which scenes an environment uses: scenario and crop filter, then the train/test split.

Split (section V-D: 70 % of the data trains, 30 % tests): the dataset's ``splits.json``
(``Dataset.splits``) where it has one, its lists used as they are (scenes in neither list are
only used by ``split="all"``); otherwise (e.g. the original download, which ships none) the
generator's own rule, :mod:`davis_ag.formats.splits`, with the seed of the dataset's
``dataset.json`` (0 without one). The same dataset therefore always splits the same way, and as
the generator would have split it.

Under the split rules ``starts`` and ``fruits`` (:mod:`davis_ag.formats.splits`) train and test
play the same scenes, every scene of either list; which starts each side plays is
:mod:`davis_ag.benchmark.starts`'s.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import TYPE_CHECKING

from davis_ag.errors import UserError
from davis_ag.formats.layout import ANNOTATIONS
from davis_ag.formats.splits import check_split_rule, recorded_seed, split_scenes
from davis_ag.scene.specs import crop_spec, parse_group_name, scenario_spec

if TYPE_CHECKING:
    from davis_ag.data.reader import Dataset, Scene

SPLITS = ("train", "test", "all")


def scene_scenario(scene: Scene) -> str | None:
    """A scene's scenario (``sp``/``mp``): the reader's, else from its group folder name."""
    value = getattr(scene, "scenario", None)
    if value:
        return scenario_spec(str(getattr(value, "name", value))).name
    parsed = parse_group_name(str(scene.id).split("/")[0])
    return parsed[0].name if parsed else None


def scene_crop(scene: Scene) -> str | None:
    """A scene's crop name (``strawberry``/``tomato``/``vine``), or ``None`` if unknown."""
    value = getattr(scene, "crop", None)
    if value:
        try:
            return crop_spec(str(getattr(value, "name", value))).name
        except UserError:
            return None
    parsed = parse_group_name(str(scene.id).split("/")[0])
    return parsed[1].name if parsed else None


def dataset_splits(dataset: Dataset) -> dict[str, list[str]]:
    """The train and test scene ids of a dataset (see the module docstring).

    Args:
        dataset: An opened dataset (``davis_ag.data.reader.Dataset``).

    Returns:
        ``{"train": [...], "test": [...]}``.

    Raises:
        UserError: when splits.json names a scene, under the folder opened, whose folder is there
            without a readable annotations.json: it would silently leave its split.
    """
    splits = getattr(dataset, "splits", None)
    if splits is not None:
        lists = {"train": [str(i) for i in splits.train], "test": [str(i) for i in splits.test]}
        _refuse_unlabelled(dataset, lists)
        return lists
    return split_scenes((s.id for s in dataset.scenes), recorded_seed(dataset.root))


def _refuse_unlabelled(dataset: Dataset, lists: dict[str, list[str]]) -> None:
    """Refuse a split naming a scene under the opened folder whose folder is there without
    readable labels: the reader passes over such a folder, so the scene would silently leave its
    split (and a benchmark or an export be made on fewer scenes than it says)."""
    readable = {s.id for s in dataset.scenes}
    opened = getattr(dataset, "opened", None) or dataset.root
    for split, ids in lists.items():
        for scene_id in ids:
            folder = Path(os.path.normpath(dataset.root / scene_id))  # an id with ".." is no scene of ours
            inside = folder == opened or opened in folder.parents
            if inside and scene_id not in readable and folder.is_dir() and not (folder / ANNOTATIONS).is_file():
                raise UserError(
                    f"{folder}: a {split} scene of splits.json without a readable {ANNOTATIONS}, so it would "
                    "silently leave its split; move the folder out of the dataset and run davis-ag generate (or the "
                    "reproduce that made it) again to make it anew; davis-ag validate on the dataset root lists "
                    "every such scene"
                )


def select_scenes(
    dataset: Dataset, scenario: str, split: str, crop: str | None = None, rule: str = "scenes"
) -> list[Scene]:
    """The scenes of one scenario (and crop) in one split, sorted by id.

    Args:
        dataset: An opened dataset (``davis_ag.data.reader.Dataset``).
        scenario: ``sp`` or ``mp``.
        split: ``train``, ``test`` or ``all``.
        crop: Keep only this crop; ``None`` keeps every crop.
        rule: The split rule: ``scenes`` (default) keeps the split's scenes; ``starts`` and
            ``fruits`` keep the scenes of both lists for ``train`` and ``test`` alike.

    Returns:
        The selected scenes.

    Raises:
        UserError: for an unknown split or rule, when nothing is left, or when the split lost a
            scene (:func:`dataset_splits`).
    """
    scenario = scenario_spec(scenario).name
    crop = crop_spec(crop).name if crop else None
    if split not in SPLITS:
        raise UserError(f"unknown split {split!r}: choose one of {', '.join(SPLITS)}")
    check_split_rule(rule)
    scenes = [s for s in dataset.scenes if scene_scenario(s) == scenario and (crop is None or scene_crop(s) == crop)]
    where = f"{scenario}{'/' + crop if crop else ''} scenes of {dataset.root}"
    if not scenes:
        raise UserError(f"no {where}: pick a scenario/crop the dataset has")
    if split == "all":
        return sorted(scenes, key=lambda s: s.id)
    lists = dataset_splits(dataset)
    keep = set(lists[split]) if rule == "scenes" else set(lists["train"]) | set(lists["test"])
    chosen = sorted((s for s in scenes if s.id in keep), key=lambda s: s.id)
    if not chosen:
        raise UserError(
            f"the {split} split has none of the {len(scenes)} {where}: give a "
            "dataset with more scenes, or evaluate on all of them (evaluate --split all, split='all')"
        )
    return chosen


def as_dataset(dataset: Dataset | str | os.PathLike[str]) -> Dataset:
    """Accept an opened dataset or a path to one."""
    if not isinstance(dataset, (str, os.PathLike)):
        return dataset
    from davis_ag.data.reader import open_dataset

    return open_dataset(Path(os.fspath(dataset)))

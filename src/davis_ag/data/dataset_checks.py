"""The checks of a dataset beyond its scenes one by one: splits.json, dataset.json, scene
folders the reader passes over for want of labels, and scenes of a group whose view counts
disagree.
"""

from __future__ import annotations

import os
from collections import Counter
from typing import Any

from pydantic import BaseModel, ValidationError

from davis_ag.data.problems import Problem, outside_reason, read_json_file
from davis_ag.data.reader import ANNOTATIONS, SCENE_METADATA, SPLITS, Dataset, Scene
from davis_ag.formats.layout import DATASET_FILE, IMAGES
from davis_ag.formats.models import DatasetFile, SplitsFile, one_line


def check_splits(dataset: Dataset, whole: bool) -> list[Problem]:
    path = dataset.root / SPLITS
    splits, problems = read_root_file(dataset, SPLITS, SplitsFile)
    if splits is None:
        return problems
    known = {scene.id for scene in dataset.scenes}
    # Only scenes under the opened path are known; a group or scene opened alone sees a subset.
    problems = [
        Problem(path, f"{name} lists {i}, which is not a scene here")
        for name, ids in (("train", splits.train), ("test", splits.test))
        for i in ids
        if whole and i not in known
    ]
    # Likewise a group opened alone answers only for its own scenes listed twice.
    if both := [i for i in splits.in_both() if whole or i in known]:
        problems.append(Problem(path, f"{len(both)} scene(s) in both train and test, e.g. {both[0]}"))
    return problems


def unlabelled_scenes(dataset: Dataset, whole: bool) -> list[Problem]:
    """Scene folders beside the dataset's scenes that have images or a scene.json but no readable
    annotations.json: the reader passes over them, so without this a scene whose labels were lost
    would leave the dataset "sound" and a scene short."""
    problems = []
    groups = {scene.path.parent for scene in dataset.scenes}
    if whole:  # a group whose every scene lost its labels holds no scene the reader found
        groups |= {p for p in dataset.root.iterdir() if p.is_dir() and not p.name.startswith(".")}
    for group in sorted(groups):
        try:
            folders = sorted(p for p in group.iterdir() if p.is_dir() and not p.name.startswith("."))
        except OSError:
            continue
        for folder in folders:
            labels = folder / ANNOTATIONS
            if labels.is_file() or not ((folder / IMAGES).is_dir() or (folder / SCENE_METADATA).exists()):
                continue
            what = "a folder" if labels.is_dir() else "unreadable" if os.path.lexists(labels) else "missing"
            problems.append(
                Problem(
                    labels,
                    f"{what}: this scene has images but no labels; move the folder out of the dataset and run "
                    "davis-ag generate (or the reproduce that made it) again to make it anew",
                )
            )
    return problems


def read_root_file(dataset: Dataset, name: str, model: type[BaseModel]) -> tuple[Any, list[Problem]]:
    """A JSON file at the dataset's root read through its model: ``(model or None, problems)``;
    ``(None, [])`` where the file is absent."""
    path = dataset.root / name
    if not path.is_file():
        return None, []
    outside = outside_reason(path, dataset.root)
    data, error = (None, outside) if outside else read_json_file(path)
    if error:
        return None, [Problem(path, error)]
    try:
        return model.model_validate(data), []
    except ValidationError as invalid:
        return None, [Problem(path, one_line(invalid))]


def check_dataset_file(dataset: Dataset) -> list[Problem]:
    """dataset.json (ours), where the root has one: the settings its scenes share."""
    return read_root_file(dataset, DATASET_FILE, DatasetFile)[1]


def check_counts(dataset: Dataset, counts: dict[str, int]) -> list[Problem]:
    """Scenes of a group share one grid, so a scene with another view count lost or gained images."""
    problems = []
    by_group: dict[str, list[Scene]] = {}
    for scene in dataset.scenes:
        if scene.id in counts:
            by_group.setdefault(scene.group, []).append(scene)
    for group, scenes in by_group.items():
        common, votes = Counter(counts[s.id] for s in scenes).most_common(1)[0]
        if votes * 2 <= len(scenes):
            continue
        problems += [
            Problem(
                s.path / ANNOTATIONS,
                f"has {counts[s.id]} views but {votes} of the {len(scenes)} scenes of {group} have {common}",
            )
            for s in scenes
            if counts[s.id] != common
        ]
    return problems

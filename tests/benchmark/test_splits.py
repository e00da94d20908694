"""A split never loses a scene silently: a listed scene whose labels are gone is refused."""

from __future__ import annotations

import os
from pathlib import Path

import pytest

from davis_ag.benchmark.splits import dataset_splits, select_scenes
from davis_ag.data.reader import open_dataset
from davis_ag.errors import UserError
from layout_factory import write_tiny_dataset


def test_a_listed_scene_without_readable_labels_is_refused(tmp_path: Path) -> None:
    root = write_tiny_dataset(tmp_path, "sp", "strawberry", scenes=3, size=(64, 48))
    whole = dataset_splits(open_dataset(root))
    assert sorted(whole["train"] + whole["test"]) == [f"Single-Strawberry/00{i}" for i in range(3)]
    labels = root / "Single-Strawberry" / "001" / "annotations.json"
    labels.unlink()
    os.symlink("annotations.json", labels)  # a link to itself: there, but never readable
    with pytest.raises(
        UserError, match=r"Single-Strawberry/001: a (train|test) scene of splits.json without a readable"
    ):
        select_scenes(open_dataset(root), "sp", "train")
    with pytest.raises(UserError, match="Single-Strawberry/001"):
        dataset_splits(open_dataset(root / "Single-Strawberry"))  # its group opened
    # A scene opened alone is no damage to its split: the others are merely not opened.
    alone = open_dataset(root / "Single-Strawberry" / "000")
    assert dataset_splits(alone) == whole

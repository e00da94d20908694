"""One labelled image at a time, as detection formats want it: views by split, instances per view.

Exports (COCO, YOLO) and the PyTorch dataset share this module so that they agree on the split,
the category of each crop and the pixels of each instance. Nothing here holds a whole dataset:
:func:`iter_split_views` walks scene by scene.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from davis_ag.benchmark.splits import dataset_splits
from davis_ag.data.reader import Box, Dataset, Scene, View
from davis_ag.errors import UserError

#: One category per crop; ids are fixed so every split and every export agrees (COCO counts from 1).
CATEGORIES: tuple[str, ...] = ("strawberry", "tomato", "vine")
#: The splits an export writes, and ``all`` for every scene.
EXPORT_SPLITS: tuple[str, ...] = ("train", "test")


def category_id(crop: str | None) -> int:
    """COCO category id of a crop (1-based; the YOLO class is this minus one).

    Raises:
        UserError: for a scene whose group folder names no known crop.
    """
    if crop not in CATEGORIES:
        raise UserError(f"unknown crop {crop!r}: a scene's group folder must name one of "
                        f"{', '.join(CATEGORIES)} (e.g. Single-Strawberry)")
    return CATEGORIES.index(crop) + 1


def scenes_by_split(dataset: Dataset) -> dict[str, list[Scene]]:
    """The dataset's scenes per split.

    ``splits.json`` where the dataset has one (scenes in neither list are left out), else the
    the generator's seeded 70/30 split by scene within each group
    (:func:`davis_ag.benchmark.splits.dataset_splits`), so exports and the benchmark agree.

    Returns:
        ``{"train": [...], "test": [...]}``, each sorted by scene id.
    """
    splits = dataset_splits(dataset)
    keep = {split: set(splits[split]) for split in EXPORT_SPLITS}
    return {split: [s for s in dataset.scenes if s.id in keep[split]] for split in EXPORT_SPLITS}


@dataclass(frozen=True)
class Instance:
    """One fruit in one view.

    Attributes:
        box: The published box (inclusive pixel extent).
        category: COCO category id of its crop.
        visible_fraction: From scene.json, or ``None`` where the scene has none.
        mask: ``H x W`` bool array, or ``None`` where the view has no ``_seg.png``.
    """

    box: Box
    category: int
    visible_fraction: float | None
    mask: np.ndarray | None

    @property
    def xyxy(self) -> tuple[float, float, float, float]:
        """The box in continuous pixel coordinates, ``(x1, y1, x2, y2)`` with ``x2 = xmin + width``."""
        return (float(self.box.xmin), float(self.box.ymin), float(self.box.xmin + self.box.width),
                float(self.box.ymin + self.box.height))


@dataclass(frozen=True)
class LabelledView:
    """A view with everything a detection format needs.

    Attributes:
        view: The reader's view.
        width: Image width in pixels.
        height: Image height in pixels.
        instances: Its fruits, in annotation order.
        depth: Path of its depth image, or ``None`` where there is none.
    """

    view: View
    width: int
    height: int
    instances: tuple[Instance, ...]
    depth: Path | None


def image_size(path: Path) -> tuple[int, int]:
    """``(width, height)`` read from the file's header, without decoding its pixels.

    Raises:
        UserError: when the file is missing or not an image.
    """
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as im:
            return im.size
    except FileNotFoundError:
        raise UserError(f"{path}: image file missing; re-download or regenerate the scene") from None
    except (OSError, UnidentifiedImageError) as error:
        raise UserError(f"{path}: cannot read ({error}); re-download or regenerate the scene") from None


def label_view(view: View, with_masks: bool = True) -> LabelledView:
    """Collect one view's instances.

    Args:
        view: A view of a scene whose group names its crop.
        with_masks: Decode the ``_seg.png`` into one mask per instance.

    Raises:
        UserError: for an unknown crop, unreadable files, or a mask whose size differs from the image's.
    """
    scene = view.scene
    category = category_id(scene.crop)
    width, height = image_size(view.image_path)
    seg = view.mask() if with_masks else None
    if seg is not None and seg.shape != (height, width):
        raise UserError(f"{view.mask_path}: mask is {seg.shape[1]}x{seg.shape[0]}, image {width}x{height}; "
                        "run `davis-ag validate` on the scene")
    fractions = scene.metadata.visible_in(view.name) if scene.metadata else {}
    instances = []
    for box in view.boxes:
        fraction = fractions.get(str(box.fruit_id))
        instances.append(Instance(box, category, None if fraction is None else float(fraction),
                                  None if seg is None else seg == box.fruit_id))
    depth = view.depth_path
    return LabelledView(view, width, height, tuple(instances), depth if depth.is_file() else None)


def iter_split_views(scenes: list[Scene], with_masks: bool = True) -> Iterator[LabelledView]:
    """Every view of the scenes, scene by scene, labelled (one view's pixels in memory at a time)."""
    for scene in scenes:
        cached = "views" in vars(scene)
        for view in scene:
            yield label_view(view, with_masks)
        if not cached:
            del scene.views  # a whole dataset's parsed annotations would otherwise pile up


def count_views(scenes: list[Scene]) -> int:
    """Views in the scenes (reads each scene's annotations, no pixels), for progress bars."""
    return sum(len(scene) for scene in scenes)

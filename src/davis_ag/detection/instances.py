"""One labelled image at a time, as detection formats want it: views by split, instances per view.

Exports (COCO, YOLO) and the PyTorch dataset share this module so that they agree on the split,
the category of each crop and the pixels of each instance. Nothing here holds a whole dataset:
:func:`iter_split_views` walks scene by scene.
"""

from __future__ import annotations

import sys
from collections.abc import Iterator
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np

from davis_ag.benchmark.splits import dataset_splits
from davis_ag.data.reader import Box, Dataset, Scene, View
from davis_ag.data.safe_read import check_inside
from davis_ag.errors import UserError
from davis_ag.scene.specs import CROPS

#: One category per crop, in ``specs.CROPS``'s order (the paper's three first, the plant-library
#: crops appended after them); ids are fixed so every split and every export agrees (COCO counts from 1).
CATEGORIES: tuple[str, ...] = tuple(CROPS)
#: The splits an export writes, and ``all`` for every scene.
EXPORT_SPLITS: tuple[str, ...] = ("train", "test")


def category_id(crop: str | None) -> int:
    """COCO category id of a crop (1-based; the YOLO class is this minus one).

    Raises:
        UserError: for a scene whose group folder names no known crop.
    """
    if crop not in CATEGORIES:
        raise UserError(
            f"unknown crop {crop!r}: a scene's group folder must name one of "
            f"{', '.join(CATEGORIES)} (e.g. Single-Strawberry)"
        )
    return CATEGORIES.index(crop) + 1


def check_export_splits(dataset: Dataset) -> dict[str, set[str]]:
    """The scene ids of each split, after refusing a split an export must not follow.

    Raises:
        UserError: when a scene is in both splits (its test images would train).
    """
    splits = dataset_splits(dataset)
    keep = {split: set(splits[split]) for split in EXPORT_SPLITS}
    both = sorted(keep["train"] & keep["test"])
    if both:
        raise UserError(
            f"{dataset.root}: splits.json lists {len(both)} scene(s) in both train and test (e.g. {both[0]}); "
            "fix it, or regenerate it (`davis-ag validate` names every one)"
        )
    return keep


def scenes_by_split(dataset: Dataset) -> dict[str, list[Scene]]:
    """The dataset's scenes per split.

    ``splits.json`` where the dataset has one (scenes in neither list are left out), else the
    the generator's seeded 70/30 split by scene within each group
    (:func:`davis_ag.benchmark.splits.dataset_splits`), so exports and the benchmark agree.

    Returns:
        ``{"train": [...], "test": [...]}``, each sorted by scene id.

    Raises:
        UserError: as :func:`check_export_splits`.
    """
    keep = check_export_splits(dataset)
    on_disk = {s.id for s in dataset.scenes}
    listed = keep["train"] | keep["test"]
    unlisted = sorted(on_disk - listed)
    if unlisted and listed - on_disk:  # a scene folder renamed: it would silently leave its split
        missing = sorted(listed - on_disk)
        raise UserError(
            f"{dataset.root}: splits.json names {len(missing)} scene(s) not there (e.g. {missing[0]}) and "
            f"{len(unlisted)} scene folder(s) are in no split (e.g. {unlisted[0]}): rename the folders "
            "back, or regenerate splits.json"
        )
    if unlisted:
        print(
            f"note: {len(unlisted)} scene(s) of {dataset.root} are in no split of its splits.json and are not "
            f"exported (e.g. {unlisted[0]})",
            file=sys.stderr,
        )
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
        return (
            float(self.box.xmin),
            float(self.box.ymin),
            float(self.box.xmin + self.box.width),
            float(self.box.ymin + self.box.height),
        )


@dataclass(frozen=True)
class LabelledView:
    """A view with everything a detection format needs.

    Attributes:
        view: The reader's view.
        width: Image width in pixels.
        height: Image height in pixels.
        instances: Its fruits, in annotation order.
        depth: Path of its depth image, or ``None`` where there is none.
        clipped: Boxes that reached outside the image, cut to it.
        dropped: Boxes with no pixel inside the image, left out.
    """

    view: View
    width: int
    height: int
    instances: tuple[Instance, ...]
    depth: Path | None
    clipped: int = 0
    dropped: int = 0


def image_size(path: Path, root: Path | None = None) -> tuple[int, int]:
    """``(width, height)`` of an image inside the dataset, after proving that it decodes whole.

    An export copies or links the file and hands it to trainers: a file that points outside the
    dataset, or a JPEG cut short (which Pillow may be told to pad silently), must stop it first.

    Args:
        path: The image.
        root: The dataset root it must lie in (None: no check).

    Raises:
        UserError: when the file is outside the dataset, missing, not an image or truncated.
    """
    from PIL import Image, UnidentifiedImageError

    check_inside(path, root)
    try:
        with Image.open(path) as im:
            size, kind = im.size, im.format
            im.load()
        if kind == "JPEG":  # Pillow pads a truncated JPEG when ImageFile.LOAD_TRUNCATED_IMAGES is set
            with open(path, "rb") as handle:
                handle.seek(-2, 2)
                if handle.read(2) != b"\xff\xd9":
                    raise OSError("the JPEG ends before its end marker (truncated)")
        return size
    except FileNotFoundError:
        raise UserError(f"{path}: image file missing; re-download or regenerate the scene") from None
    except (OSError, UnidentifiedImageError, ValueError) as error:
        raise UserError(f"{path}: cannot decode ({error}); re-download or regenerate the scene") from None


def clip_box(box: Box, width: int, height: int) -> Box | None:
    """A box cut to the image (inclusive pixel extents), or None when no pixel of it is inside."""
    x0, y0 = max(box.xmin, 0), max(box.ymin, 0)
    x1, y1 = min(box.xmin + box.width, width), min(box.ymin + box.height, height)
    if x1 <= x0 or y1 <= y0:
        return None
    return replace(box, xmin=x0, ymin=y0, width=x1 - x0, height=y1 - y0)


def label_view(view: View, with_masks: bool = True) -> LabelledView:
    """Collect one view's instances; boxes reaching outside the image are cut to it (or left out
    when nothing is inside) and counted.

    Args:
        view: A view of a scene whose group names its crop.
        with_masks: Decode the ``_seg.png`` into one mask per instance.

    Raises:
        UserError: for an unknown crop, unreadable files or files outside the dataset, or a mask
            whose size differs from the image's.
    """
    scene = view.scene
    category = category_id(scene.crop)
    width, height = image_size(view.image_path, scene.root)
    seg = view.mask() if with_masks else None
    if seg is not None and seg.shape != (height, width):
        raise UserError(
            f"{view.mask_path}: mask is {seg.shape[1]}x{seg.shape[0]}, image {width}x{height}; "
            "run `davis-ag validate` on the scene"
        )
    fractions = scene.metadata.visible_in(view.name) if scene.metadata else {}
    instances, clipped, dropped = [], 0, 0
    for published in view.boxes:
        box = clip_box(published, width, height)
        if box is None:
            dropped += 1
            continue
        clipped += box != published
        fraction = fractions.get(str(box.fruit_id))
        instances.append(
            Instance(
                box,
                category,
                None if fraction is None else float(fraction),
                None if seg is None else seg == box.fruit_id,
            )
        )
    depth = view.depth_path
    if depth.is_file():
        check_inside(depth, scene.root)
    return LabelledView(view, width, height, tuple(instances), depth if depth.is_file() else None, clipped, dropped)


def tally(counts: dict[str, int], item: LabelledView, unit: str, found: int) -> None:
    """Count one exported view into an export's ``counts``: the image, its ``found`` instances
    (under ``unit``) and its boxes cut to the image or left out."""
    counts["images"] += 1
    counts[unit] += found
    counts["clipped"] = counts.get("clipped", 0) + item.clipped
    counts["dropped"] = counts.get("dropped", 0) + item.dropped


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

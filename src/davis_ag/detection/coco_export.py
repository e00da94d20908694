"""``davis-ag export coco``: one COCO instances file per split, masks as pycocotools RLE.

Layout written::

    OUT/annotations/instances_train.json
    OUT/annotations/instances_test.json

Images stay where they are: each ``file_name`` is relative to the dataset root, which the file
records as ``info.image_root`` (pass it as the image folder to COCO-style loaders). Per image:
``scene``, ``view`` and ``depth_file`` (relative, only where ``NNNN_depth.png`` exists). Per
annotation: ``bbox`` is the published box (``[xmin, ymin, width, height]``, inclusive pixel
extent, which is COCO's convention for pixel masks), ``segmentation`` the RLE of the fruit's
pixels (views without ``_seg.png`` get boxes only, no ``segmentation`` key), ``area`` its pixel
count, and ``attributes`` the stable ``fruit_id`` and the ``visible_fraction``. One category per
crop, fixed ids: strawberry 1, tomato 2, vine 3, then the plant-library crops. With ``organs``, the organ classes as semantic
masks too (:mod:`davis_ag.detection.organ_export`).

The JSON is streamed: images and annotations go to two temporary files as views are read, then
are joined into the final file, which appears atomically.
"""

from __future__ import annotations

import json
import shutil
import tempfile
from pathlib import Path
from typing import IO, Any

import numpy as np

from davis_ag.atomic_files import atomic_output
from davis_ag.data.reader import Scene, open_dataset
from davis_ag.detection.instances import CATEGORIES, LabelledView, count_views, iter_split_views, scenes_by_split, tally
from davis_ag.detection.organ_export import (
    ORGAN_CATEGORY_BASE,
    coco_organ_categories,
    organ_masks,
)

#: Name prefix of a split's hidden working folder beside its file (a killed run's is removed by the next).
WORK_PREFIX = ".coco-"


def rle_of(mask: np.ndarray) -> dict[str, Any]:
    """pycocotools' compressed RLE of a bool mask, with ``counts`` as text (JSON-ready)."""
    from pycocotools import mask as mask_utils

    rle = mask_utils.encode(np.asfortranarray(mask.astype(np.uint8)))
    return {"size": [int(v) for v in rle["size"]], "counts": rle["counts"].decode("ascii")}


def _image_entry(item: LabelledView, image_id: int, root: Path) -> dict[str, Any]:
    view = item.view
    entry: dict[str, Any] = {
        "id": image_id,
        "file_name": view.image_path.relative_to(root).as_posix(),
        "width": item.width,
        "height": item.height,
        "scene": view.scene.id,
        "view": view.name,
    }
    if item.depth is not None:
        entry["depth_file"] = item.depth.relative_to(root).as_posix()
        entry["depth_units"] = "mm"
    return entry


def _annotation_entries(item: LabelledView, image_id: int, first_id: int) -> list[dict[str, Any]]:
    entries = []
    for offset, inst in enumerate(item.instances):
        box = inst.box
        entry: dict[str, Any] = {
            "id": first_id + offset,
            "image_id": image_id,
            "category_id": inst.category,
            "bbox": [box.xmin, box.ymin, box.width, box.height],
            "iscrowd": 0,
            "area": int(inst.mask.sum()) if inst.mask is not None else box.area,
            "attributes": {"fruit_id": box.fruit_id, "visible_fraction": inst.visible_fraction},
        }
        if inst.mask is not None:
            entry["segmentation"] = rle_of(inst.mask)
        entries.append(entry)
    return entries


def organ_annotations(item: LabelledView, image_id: int, first_id: int) -> list[dict[str, Any]]:
    """One semantic annotation per organ class present in the view (see
    :mod:`davis_ag.detection.organ_export`); none without a class image."""
    from davis_ag.scene.organs import ORGAN_NAMES

    entries: list[dict[str, Any]] = []
    for value, mask in organ_masks(item.view):
        rows, cols = np.nonzero(mask)
        x0, y0 = int(cols.min()), int(rows.min())
        entries.append(
            {
                "id": first_id + len(entries),
                "image_id": image_id,
                "category_id": ORGAN_CATEGORY_BASE + value,
                "bbox": [x0, y0, int(cols.max()) - x0 + 1, int(rows.max()) - y0 + 1],
                "iscrowd": 0,
                "area": int(mask.sum()),
                "segmentation": rle_of(mask),
                "attributes": {"organ": ORGAN_NAMES[value], "semantic": True},
            }
        )
    return entries


def _write_array_items(handle: IO[str], items: list[dict[str, Any]], first: bool) -> bool:
    for item in items:
        handle.write(("" if first else ",\n") + json.dumps(item, separators=(",", ":")))
        first = False
    return first


def write_coco_split(
    scenes: list[Scene], root: Path, target: Path, split: str, progress: bool = True, organs: bool = False
) -> dict[str, int]:
    """Write one split's COCO instances file.

    Args:
        scenes: The split's scenes.
        root: The dataset root (``file_name`` is relative to it).
        target: The JSON file to write (atomically).
        split: Its name, recorded in ``info``.
        progress: Show a tqdm bar on stderr.
        organs: Add the organ classes' semantic masks.

    Returns:
        ``{"images": n, "annotations": m, "clipped": boxes cut to their image, "dropped": boxes left out}``.
    """
    from tqdm import tqdm

    counts = {"images": 0, "annotations": 0, "clipped": 0, "dropped": 0}
    header = {
        "info": {
            "description": f"DAVIS-Ag {split} split, exported by davis-ag",
            "image_root": str(root),
            "split": split,
            "scenes": [s.id for s in scenes],
        },
        "licenses": [],
        "categories": [{"id": i + 1, "name": name, "supercategory": "fruit"} for i, name in enumerate(CATEGORIES)]
        + (coco_organ_categories() if organs else []),
    }
    with tempfile.TemporaryDirectory(dir=target.parent, prefix=WORK_PREFIX) as tmp:
        images_path, annotations_path = Path(tmp) / "images", Path(tmp) / "annotations"
        with open(images_path, "w") as images, open(annotations_path, "w") as annotations:
            first_image = first_annotation = True
            # A bar on a terminal only (not in logs), closed before an error's line is printed.
            with tqdm(
                total=count_views(scenes), desc=f"coco {split}", unit="view", disable=None if progress else True
            ) as bar:
                for item in iter_split_views(scenes):
                    image_id = counts["images"] + 1
                    first_image = _write_array_items(images, [_image_entry(item, image_id, root)], first_image)
                    entries = _annotation_entries(item, image_id, counts["annotations"] + 1)
                    if organs:
                        entries += organ_annotations(item, image_id, counts["annotations"] + 1 + len(entries))
                    first_annotation = _write_array_items(annotations, entries, first_annotation)
                    tally(counts, item, "annotations", len(entries))
                    bar.update()
        with atomic_output(target, "w") as out:
            head = json.dumps(header, indent=1)
            out.write(head[:-2] + ',\n "images": [\n')  # reopen the header object: its last "\n}"
            with open(images_path) as part:
                shutil.copyfileobj(part, out)
            out.write('\n],\n "annotations": [\n')
            with open(annotations_path) as part:
                shutil.copyfileobj(part, out)
            out.write("\n]\n}\n")
    return counts


def export_coco(
    dataset_dir: Path,
    out_dir: Path,
    splits: tuple[str, ...] = ("train", "test"),
    progress: bool = True,
    organs: bool = False,
) -> dict[str, dict[str, int]]:
    """Export a DAVIS-Ag dataset to COCO instances files, one per split.

    Args:
        dataset_dir: Dataset root, group folder or scene folder.
        out_dir: Folder that receives ``annotations/instances_<split>.json``.
        splits: Which splits to write.
        progress: Show progress bars.
        organs: Add the organ classes' semantic masks (views with class images).

    Returns:
        Per split, the image and annotation counts.
    """
    dataset = open_dataset(dataset_dir)
    by_split = scenes_by_split(dataset)
    (out_dir / "annotations").mkdir(parents=True, exist_ok=True)
    return {
        split: write_coco_split(
            by_split[split], dataset.root, out_dir / "annotations" / f"instances_{split}.json", split, progress, organs
        )
        for split in splits
    }

"""``davis-ag export yolo``: the ultralytics dataset layout, boxes or polygons, with its data YAML.

Layout written (what ``ultralytics`` expects: each ``labels/`` path mirrors its ``images/`` path)::

    OUT/data.yaml                     path, train, val, test, names
    OUT/images/train/Single-Strawberry_000_0001.jpeg
    OUT/labels/train/Single-Strawberry_000_0001.txt
    OUT/images/test/...   OUT/labels/test/...

Images are hard links to the dataset's files where the file system allows (no copy, no extra
space), copies elsewhere. One label line per fruit: ``class xc yc w h`` (``--task detect``) or
``class x1 y1 x2 y2 ...`` (``--task segment``: the outline of the fruit's pixels; a fruit split
into pieces by a leaf is one polygon whose pieces are joined by zero-width seams, as
ultralytics' own COCO converter joins them; rasterised, a seam adds a one-pixel line). Coordinates are normalised to [0, 1]; classes are
0 strawberry, 1 tomato, 2 vine, then the plant-library crops (``instances.CATEGORIES``). ``val`` is the test split (ultralytics validates on ``val``).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path

import numpy as np

from davis_ag.atomic_files import atomic_output, temporary_sibling, write_text_atomic
from davis_ag.data.reader import Scene, open_dataset
from davis_ag.detection.instances import CATEGORIES, LabelledView, count_views, iter_split_views, scenes_by_split, tally
from davis_ag.detection.organ_export import organ_masks, yolo_organ_class, yolo_organ_names
from davis_ag.errors import MachineError, UserError
from davis_ag.formats.layout import IMAGE_SUFFIX, view_stem

TASKS = ("detect", "segment")


def flat_name(view_id: str) -> str:
    """``Single-Strawberry/000`` + ``0001.jpeg`` -> ``Single-Strawberry_000_0001`` (no suffix)."""
    return view_stem(view_id.replace("/", "_"))


def mask_polygon(mask: np.ndarray) -> np.ndarray:
    """One closed outline of a bool mask's pixels, ``K x 2`` (x, y) pixel centres.

    Pieces (outer contours of the connected parts) are joined into one polygon by going from the
    first piece's start to each other piece and back along the same line, which adds no area.

    Raises:
        ValueError: for an empty mask.
    """
    import cv2

    contours, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    pieces = [c.reshape(-1, 2) for c in sorted(contours, key=cv2.contourArea, reverse=True)]
    if not pieces:
        raise ValueError("empty mask")
    anchor = pieces[0][:1]
    joined = [pieces[0], anchor]
    for piece in pieces[1:]:
        joined += [piece, piece[:1], anchor]
    return np.concatenate(joined).astype(float)


def outline_pieces(mask: np.ndarray) -> list[np.ndarray]:
    """Each connected part of a bool mask as its own closed outline, ``K x 2`` (x, y), largest first;
    parts of fewer than three outline points (specks of a pixel or two) are left out.

    For organ classes, which fall into hundreds of parts (every stem): joined into one polygon,
    the seams between them fill in as a fan when the polygon is drawn.
    """
    import cv2

    contours, _ = cv2.findContours(mask.astype(np.uint8), cv2.RETR_EXTERNAL, cv2.CHAIN_APPROX_NONE)
    pieces = [c.reshape(-1, 2) for c in sorted(contours, key=cv2.contourArea, reverse=True)]
    return [piece.astype(float) for piece in pieces if len(piece) >= 3]


def label_lines(item: LabelledView, task: str) -> list[str]:
    """The YOLO label lines of one view (see the module docstring).

    Raises:
        UserError: for ``segment`` on a view without an instance mask (a box line among polygon
            lines makes the file one ultralytics refuses to load).
    """
    w, h = float(item.width), float(item.height)
    lines = []
    for inst in item.instances:
        cls = inst.category - 1
        if task == "segment" and (inst.mask is None or not inst.mask.any()):
            what = "missing" if inst.mask is None else f"holds no pixel of fruit {inst.box.fruit_id}, which has a box"
            raise UserError(
                f"{item.view.mask_path}: {what}, and --task segment needs every box's mask (a box line among "
                "polygons is a file ultralytics refuses); export with --task detect (and --force over this "
                "unfinished export), or regenerate the scene"
            )
        if task == "segment":
            assert inst.mask is not None  # refused above where missing
            points = mask_polygon(inst.mask)
            # Pixel centres: the outline through them covers exactly the mask's pixels when filled.
            coords = " ".join(f"{(x + 0.5) / w:.6f} {(y + 0.5) / h:.6f}" for x, y in points)
            lines.append(f"{cls} {coords}")
        else:
            x1, y1, x2, y2 = inst.xyxy
            lines.append(
                f"{cls} {(x1 + x2) / 2 / w:.6f} {(y1 + y2) / 2 / h:.6f} {(x2 - x1) / w:.6f} {(y2 - y1) / h:.6f}"
            )
    return lines


def organ_lines(item: LabelledView) -> list[str]:
    """One segment line per connected part of each organ class in the view (see
    :mod:`davis_ag.detection.organ_export`); none without a class image. A part's holes are not
    drawn (YOLO polygons have none): the soil's outline covers the plant's foot, and ultralytics'
    overlapping masks (the default) lay the smaller parts over it."""
    w, h = float(item.width), float(item.height)
    return [
        f"{yolo_organ_class(value)} " + " ".join(f"{(x + 0.5) / w:.6f} {(y + 0.5) / h:.6f}" for x, y in piece)
        for value, mask in organ_masks(item.view)
        for piece in outline_pieces(mask)
    ]


def place_image(source: Path, target: Path) -> None:
    """Hard-link ``source`` to ``target`` (a copy where links are impossible), through a temporary
    sibling, so ``target`` is whole or absent whatever happens (a full disk, a kill).

    Raises:
        MachineError: naming ``target`` when it cannot be written.
    """
    tmp = temporary_sibling(target)
    tmp.unlink(missing_ok=True)
    try:
        try:
            os.link(source, tmp)
            os.replace(tmp, target)
        except OSError:
            tmp.unlink(missing_ok=True)
            with open(source, "rb") as src, atomic_output(target, "wb") as handle:
                shutil.copyfileobj(src, handle)
    except OSError as error:
        raise MachineError(
            f"{target}: cannot write the image ({error.strerror or error}); the files already "
            "exported are kept: free the space and run the same command again"
        ) from None


def write_yolo_split(
    scenes: list[Scene], out_dir: Path, split: str, task: str = "detect", progress: bool = True, organs: bool = False
) -> dict[str, int]:
    """Write one split's images and labels.

    Returns:
        ``{"images": n, "instances": m, "clipped": boxes cut to their image, "dropped": boxes left out}``.
    """
    from tqdm import tqdm

    images, labels = out_dir / "images" / split, out_dir / "labels" / split
    images.mkdir(parents=True, exist_ok=True)
    labels.mkdir(parents=True, exist_ok=True)
    counts = {"images": 0, "instances": 0, "clipped": 0, "dropped": 0}
    # A bar on a terminal only (not in logs), closed before an error's line is printed.
    with tqdm(total=count_views(scenes), desc=f"yolo {split}", unit="view", disable=None if progress else True) as bar:
        for item in iter_split_views(scenes, with_masks=task == "segment"):
            name = flat_name(f"{item.view.scene.id}/{item.view.name}")
            lines = label_lines(item, task)
            if organs:
                lines += organ_lines(item)
            write_text_atomic(labels / f"{name}.txt", "".join(f"{line}\n" for line in lines))
            place_image(item.view.image_path, images / f"{name}{IMAGE_SUFFIX}")
            tally(counts, item, "instances", len(lines))
            bar.update()
    return counts


def data_yaml(out_dir: Path, names: dict[int, str] | None = None) -> Path:
    """Write ``OUT/data.yaml`` for the train and test splits; returns its path."""
    import yaml

    names = names if names is not None else dict(enumerate(CATEGORIES))
    text = yaml.safe_dump(
        {"path": str(out_dir), "train": "images/train", "val": "images/test", "test": "images/test", "names": names},
        sort_keys=False,
    )
    return write_text_atomic(out_dir / "data.yaml", text)


def export_yolo(
    dataset_dir: Path,
    out_dir: Path,
    task: str = "detect",
    splits: tuple[str, ...] = ("train", "test"),
    progress: bool = True,
    organs: bool = False,
) -> dict[str, dict[str, int]]:
    """Export a DAVIS-Ag dataset to the ultralytics layout.

    Args:
        dataset_dir: Dataset root, group folder or scene folder.
        out_dir: The export folder.
        task: ``detect`` (boxes) or ``segment`` (polygons).
        splits: Which splits to write.
        progress: Show progress bars.
        organs: Add one polygon per organ class present (``segment`` only; see
            :mod:`davis_ag.detection.organ_export`).

    Returns:
        Per split, the image and instance counts.

    Raises:
        UserError: for an unknown task, or organs with boxes.
    """
    if task not in TASKS:
        raise UserError(f"unknown task {task!r}: choose one of {', '.join(TASKS)}")
    if organs and task != "segment":
        raise UserError("--organs exports semantic masks as polygons: add --task segment")
    dataset = open_dataset(dataset_dir)
    by_split = scenes_by_split(dataset)
    counts = {split: write_yolo_split(by_split[split], out_dir, split, task, progress, organs) for split in splits}
    for split in ("train", "test"):  # ultralytics wants every folder the YAML names
        (out_dir / "images" / split).mkdir(parents=True, exist_ok=True)
    names = dict(enumerate(CATEGORIES))
    if organs:
        names.update(yolo_organ_names())
    data_yaml(out_dir, names)
    return counts

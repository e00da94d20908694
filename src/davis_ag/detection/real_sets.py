"""A labelled image pool in YOLO or COCO layout, and the paper's random train/test splits of it.

Section VI-A draws three random splits of the real strawberry set, each 654 training and 159
test images. :func:`load_pool` reads any set a user points to:

- YOLO: a data YAML (every image its ``train``/``val``/``test`` entries list, folders or .txt
  lists) or a folder with ``images/`` beside ``labels/`` (searched recursively);
- COCO: an instances JSON; images are looked up under ``--real-images`` (default: the folder
  the ``file_name`` paths are relative to, ``info.image_root`` or the JSON's folder).

Boxes become YOLO lines; classes are the set's own (COCO categories in id order).
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from davis_ag.atomic_files import write_text_atomic
from davis_ag.errors import UserError, yaml_problem

#: Section VI-A's split sizes (Table 5).
PAPER_TRAIN, PAPER_TEST = 654, 159
_IMAGE_SUFFIXES = {".jpg", ".jpeg", ".png", ".bmp", ".webp", ".tif", ".tiff"}


@dataclass(frozen=True)
class Pool:
    """A labelled image set: image paths with their YOLO label lines, and the class names."""

    items: tuple[tuple[Path, tuple[str, ...]], ...]
    names: dict[int, str]


def _label_for(image: Path) -> Path:
    # ultralytics' rule: the last /images/ in the path becomes /labels/, the suffix .txt
    parts = list(image.parts)
    for i in range(len(parts) - 1, -1, -1):
        if parts[i] == "images":
            parts[i] = "labels"
            break
    return Path(*parts).with_suffix(".txt")


def _yolo_items(images: list[Path]) -> tuple[tuple[Path, tuple[str, ...]], ...]:
    items = []
    for image in sorted(set(images)):
        label = _label_for(image)
        lines = (
            tuple(line.strip() for line in label.read_text().splitlines() if line.strip()) if label.is_file() else ()
        )
        items.append((image, lines))
    return tuple(items)


def _images_under(folder: Path) -> list[Path]:
    return [p for p in folder.rglob("*") if p.suffix.lower() in _IMAGE_SUFFIXES]


def _from_yaml(path: Path) -> Pool:
    import yaml

    try:
        data = yaml.safe_load(path.read_text())
    except OSError as error:
        raise UserError(f"{path}: cannot read the data YAML ({error.strerror or error})") from None
    except yaml.YAMLError as error:
        raise UserError(f"{path}: {yaml_problem(error)}; give an ultralytics data YAML") from None
    if not isinstance(data, dict) or "names" not in data:
        raise UserError(f"{path}: an ultralytics data YAML needs 'names' and train/val/test entries")
    base = Path(data.get("path") or path.parent)
    base = base if base.is_absolute() else (path.parent / base)
    images: list[Path] = []
    for key in ("train", "val", "test"):
        entries = data.get(key) or []
        for entry in entries if isinstance(entries, list) else [entries]:
            where = base / entry
            if where.is_dir():
                images += _images_under(where)
            elif where.suffix == ".txt" and where.is_file():
                images += [(base / line.strip()).resolve() for line in where.read_text().splitlines() if line.strip()]
            elif where.is_file():
                images.append(where)
    names = data["names"]
    names = dict(enumerate(names)) if isinstance(names, list) else {int(k): str(v) for k, v in names.items()}
    return Pool(_yolo_items(images), names)


def _from_coco(path: Path, image_root: Path | None) -> Pool:
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError) as error:
        raise UserError(f"{path}: cannot read the COCO file ({error}); give an instances JSON") from None
    if not isinstance(data, dict) or not {"images", "annotations", "categories"} <= set(data):
        raise UserError(f"{path}: a COCO instances file needs images, annotations and categories")
    root = image_root or Path((data.get("info") or {}).get("image_root") or path.parent)
    categories = sorted(data["categories"], key=lambda c: c["id"])
    classes = {c["id"]: i for i, c in enumerate(categories)}
    lines: dict[int, list[str]] = {}
    sizes = {im["id"]: (float(im["width"]), float(im["height"])) for im in data["images"]}
    for ann in data["annotations"]:
        if ann.get("iscrowd"):
            continue
        x, y, w, h = (float(v) for v in ann["bbox"])
        iw, ih = sizes[ann["image_id"]]
        lines.setdefault(ann["image_id"], []).append(
            f"{classes[ann['category_id']]} {(x + w / 2) / iw:.6f} {(y + h / 2) / ih:.6f} {w / iw:.6f} {h / ih:.6f}"
        )
    items = tuple((root / im["file_name"], tuple(lines.get(im["id"], []))) for im in data["images"])
    return Pool(items, {i: c["name"] for i, c in enumerate(categories)})


def load_pool(path: Path, image_root: Path | None = None) -> Pool:
    """Read a labelled set (see the module docstring).

    Raises:
        UserError: when the path is none of the accepted layouts, or holds no image, or an image is missing.
    """
    if path.is_file() and path.suffix in (".yaml", ".yml"):
        pool = _from_yaml(path)
    elif path.is_file() and path.suffix == ".json":
        pool = _from_coco(path, image_root)
    elif path.is_dir() and (path / "data.yaml").is_file():
        pool = _from_yaml(path / "data.yaml")
    elif path.is_dir() and (path / "images").is_dir():
        pool = Pool(_yolo_items(_images_under(path / "images")), {})
        classes = {int(line.split()[0]) for _, lines in pool.items for line in lines}
        pool = Pool(pool.items, {c: f"class{c}" for c in range(max(classes, default=0) + 1)})
    else:
        raise UserError(
            f"{path}: not a labelled set: give an ultralytics data YAML, a folder with images/ "
            "and labels/, or a COCO instances JSON"
        )
    if not pool.items:
        raise UserError(f"{path}: no images found; check the paths it lists")
    missing = [str(p) for p, _ in pool.items if not p.is_file()]
    if missing:
        raise UserError(f"{missing[0]}: image missing ({len(missing)} in all); check the set or --real-images")
    return pool


def split_sizes(available: int, train: int = PAPER_TRAIN, test: int = PAPER_TEST) -> tuple[int, int]:
    """The split sizes asked for, or, for a smaller pool, the same proportions of all of it."""
    if available >= train + test:
        return train, test
    n_test = max(1, round(available * test / (train + test)))
    if available - n_test < 1:
        raise UserError(f"the set has {available} image(s): at least 2 are needed for a train/test split")
    return available - n_test, n_test


def write_split(pool: Pool, out_dir: Path, seed: int, train: int, test: int) -> Path:
    """Draw one random split and write it in the ultralytics layout; returns its data YAML.

    Images are hard-linked (copied where that is impossible); ``val`` is the test split.
    """
    import yaml

    from davis_ag.detection.yolo_export import place_image

    order = np.random.default_rng(seed).permutation(len(pool.items))
    for split, chosen in (("train", order[:train]), ("test", order[train : train + test])):
        for index in chosen:
            image, lines = pool.items[index]
            name = f"{index:06d}_{image.stem}"
            (out_dir / "images" / split).mkdir(parents=True, exist_ok=True)
            place_image(image, out_dir / "images" / split / f"{name}{image.suffix.lower()}")
            write_text_atomic(out_dir / "labels" / split / f"{name}.txt", "".join(f"{x}\n" for x in lines))
    return write_text_atomic(
        out_dir / "data.yaml",
        yaml.safe_dump(
            {
                "path": str(out_dir),
                "train": "images/train",
                "val": "images/test",
                "test": "images/test",
                "names": pool.names,
            },
            sort_keys=False,
        ),
    )

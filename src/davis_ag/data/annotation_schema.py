"""Pure parsing of annotations.json entries, and the box arithmetic on instance masks.

No file access here: the reader (:mod:`davis_ag.data.reader`) and the validator share these, and
the parsers raise ``ValueError`` with a reason that each turns into its own kind of report.
Conventions: a box is ``[xmin, ymin, width, height, fruit_id, 0]`` with the inclusive pixel
extent of the fruit's mask (``width = xmax - xmin + 1``); mask value 255 (uint8 masks) or 65535
(uint16 masks, scenes of more than 255 fruit: :mod:`davis_ag.formats.masks`) is no fruit.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from davis_ag.formats.layout import IMAGE_SUFFIX, view_name
from davis_ag.formats.masks import fruit_pixels
from davis_ag.scene import specs as config
from davis_ag.scene.specs import NO_FRUIT  # noqa: F401 - the uint8 masks' value, re-exported by the reader

_IMAGE_SUFFIXES = (IMAGE_SUFFIX, ".jpg")
#: Box values beyond this are damage, not pixels.
BOX_LIMIT = 2**20


@dataclass(frozen=True)
class Box:
    """One fruit's bounding box, in pixels, with inclusive extents.

    Attributes:
        xmin: Leftmost pixel column of the fruit.
        ymin: Topmost pixel row of the fruit.
        width: ``xmax - xmin + 1``.
        height: ``ymax - ymin + 1``.
        fruit_id: Instance id, stable across the views of a scene; also its mask value.
    """

    xmin: int
    ymin: int
    width: int
    height: int
    fruit_id: int

    @property
    def xmax(self) -> int:
        """Rightmost pixel column (inclusive)."""
        return self.xmin + self.width - 1

    @property
    def ymax(self) -> int:
        """Bottom pixel row (inclusive)."""
        return self.ymin + self.height - 1

    @property
    def area(self) -> int:
        """Pixels in the box, ``width * height``."""
        return self.width * self.height

    def to_list(self) -> list[int]:
        """The published form ``[xmin, ymin, width, height, fruit_id, 0]``."""
        return [self.xmin, self.ymin, self.width, self.height, self.fruit_id, 0]


def normalise_view_name(name: str | int) -> str:
    """The canonical image name of a view: ``"0001"``, ``"0001.jpeg"`` and ``1`` give ``"0001.jpeg"``.

    Args:
        name: An annotation key, pointer value or user input; an int is a 1-based view number.

    Returns:
        The name with the ".jpeg" suffix; "" stays "" (an invalid move).

    Raises:
        ValueError: for a name with a path separator or another suffix.
    """
    if isinstance(name, bool) or not isinstance(name, (str, int)):
        raise ValueError(f"an image name must be a string, not {type(name).__name__}")
    if isinstance(name, int):
        if name < 1:
            raise ValueError(f"view numbers start at 1, got {name}")
        return view_name(name)
    name = name.strip()
    if not name:
        return ""
    if "/" in name or "\\" in name:
        raise ValueError(f"image name {name!r} must not contain a folder")
    if not name.isprintable():
        raise ValueError(f"image name {name!r} holds a control character")
    for suffix in _IMAGE_SUFFIXES:
        if name.lower().endswith(suffix):
            name = name[: -len(suffix)]
            break
    if not name or "." in name:
        raise ValueError(f"image name {name!r} is not a .jpeg name like 0001.jpeg")
    return name + IMAGE_SUFFIX


def _number(value: Any, what: str) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
        raise ValueError(f"{what} must be a finite number, got {value!r}")
    return float(value)


def parse_box(raw: Any) -> Box:
    """Parse one published box ``[xmin, ymin, width, height, fruit_id, 0]``.

    Args:
        raw: A list of at least five numbers; floats are rounded, values after the fifth ignored.

    Returns:
        The :class:`Box`.

    Raises:
        ValueError: when it is not such a list.
    """
    if not isinstance(raw, (list, tuple)) or len(raw) < 5:
        raise ValueError(f"a box must be [xmin, ymin, width, height, fruit_id, 0], got {raw!r}")
    names = ("xmin", "ymin", "width", "height", "fruit_id")
    values = [round(_number(v, f"box {n}")) for v, n in zip(raw, names)]
    for value, name in zip(values, names):
        if not -BOX_LIMIT < value < BOX_LIMIT:  # no image is that large; tables hold 32-bit ints
            raise ValueError(f"box {name} {value} is out of range (|value| < {BOX_LIMIT})")
    return Box(*values)


def parse_pose(raw: Any) -> tuple[float, ...] | None:
    """Parse a published pose ``[x, y, z, yaw_deg, pitch_deg]``; ``None`` when absent.

    Raises:
        ValueError: for anything but a list of at least three numbers or null.
    """
    if raw is None:
        return None
    if not isinstance(raw, (list, tuple)) or len(raw) < 3:
        raise ValueError(f"pose must be [x, y, z, yaw, pitch], got {raw!r}")
    return tuple(_number(v, "pose value") for v in raw)


@dataclass(frozen=True)
class ViewRecord:
    """One annotations.json entry, parsed; what :class:`View` holds apart from its scene."""

    name: str
    pose: tuple[float, ...] | None
    boxes: tuple[Box, ...]
    pointers: dict[str, str]


def parse_entry(key: Any, entry: Any) -> ViewRecord:
    """Parse one annotations.json entry, tolerating the original download's variations.

    Args:
        key: The entry's key (an image name, with or without ".jpeg").
        entry: Its value: an object with "bounding_boxes", "pose" and pointer keys.

    Returns:
        The :class:`ViewRecord`; pointers hold only the action keys present, normalised.

    Raises:
        ValueError: with the reason, when the entry cannot be read.
    """
    name = normalise_view_name(key)
    if not name:
        raise ValueError("empty image name as key")
    if not isinstance(entry, dict):
        raise ValueError(f"entry must be an object, got {type(entry).__name__}")
    raw_boxes = entry.get("bounding_boxes", [])
    if not isinstance(raw_boxes, list):
        raise ValueError("bounding_boxes must be a list of boxes")
    boxes = tuple(parse_box(b) for b in raw_boxes)
    pose = parse_pose(entry.get("pose"))
    pointers = {}
    for action in config.ALL_ACTIONS:
        if action in entry:
            target = entry[action]
            if target is None:
                target = ""
            if not isinstance(target, str):
                raise ValueError(f'pointer {action!r} must be an image name or "", got {target!r}')
            pointers[action] = normalise_view_name(target)
    return ViewRecord(name, pose, boxes, pointers)


def boxes_from_mask(mask: np.ndarray) -> dict[int, Box]:
    """The bounding box of every fruit id's pixels in an instance mask (our writer's convention).

    Args:
        mask: ``H x W`` instance mask, uint8 (255 is no fruit) or uint16 (65535 is no fruit).

    Returns:
        Fruit id to its :class:`Box` (inclusive pixel extent), in id order.
    """
    ys, xs = np.nonzero(fruit_pixels(mask))
    if not len(ys):
        return {}
    ids = mask[ys, xs]
    order = np.argsort(ids, kind="stable")
    ids, ys, xs = ids[order], ys[order], xs[order]
    starts = np.flatnonzero(np.r_[True, ids[1:] != ids[:-1]])
    x0, x1 = np.minimum.reduceat(xs, starts), np.maximum.reduceat(xs, starts)
    y0, y1 = np.minimum.reduceat(ys, starts), np.maximum.reduceat(ys, starts)
    return {
        int(i): Box(int(a), int(b), int(c - a + 1), int(d - b + 1), int(i))
        for i, a, b, c, d in zip(ids[starts], x0, y0, x1, y1)
    }


def exposure_rate(mask: np.ndarray, box: Box) -> float:
    """Object exposure rate, equation (1) of the paper: fruit pixels inside the box over its area.

    Args:
        mask: ``H x W`` instance mask (fruit id per pixel).
        box: The target fruit's box; the part outside the image counts as not fruit.

    Returns:
        A value in [0, 1]; 0 for an empty box.
    """
    if box.area <= 0:
        return 0.0
    # Clamped at 0 both ends: a negative end would count from the image's far edge.
    y0, x0 = max(box.ymin, 0), max(box.xmin, 0)
    window = mask[y0 : max(box.ymax + 1, 0), x0 : max(box.xmax + 1, 0)]
    return float(np.count_nonzero(window == box.fruit_id)) / box.area

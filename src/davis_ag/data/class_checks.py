"""Checks of an organ class image (``images/NNNN_class.png``) against its view's instance mask."""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

import numpy as np

from davis_ag.formats.masks import fruit_pixels
from davis_ag.scene.organs import FRUIT, ORGAN_NAMES


def class_problems(class_path: Path, mask: np.ndarray | None, table: Sequence[str] = ORGAN_NAMES) -> list[str]:
    """Check a class image: 8-bit, one channel, known class values, the mask's size, and every
    fruit pixel of the instance mask labelled ``fruit`` (both come from the same id pass).

    Args:
        class_path: ``images/NNNN_class.png``.
        mask: The view's instance mask (``_seg.png``, decoded), when present and readable.
        table: The scene's class table (its scene.json's ``classes.table``: without
            ``structure`` in a scene without one), or the whole table.

    Returns:
        One reason per problem.
    """
    from PIL import Image

    try:
        with Image.open(class_path) as im:
            mode, classes = im.mode, np.asarray(im)
    except Exception as error:  # Pillow raises many types for a damaged file
        return [f"cannot decode ({error})"]
    if mode not in ("L", "P") or classes.dtype != np.uint8 or classes.ndim != 2:
        return [f"must be a uint8 single-channel PNG, got mode {mode}"]
    problems = []
    unknown = np.unique(classes[classes >= len(table)])
    if unknown.size:
        problems.append(
            f"holds class values {unknown.tolist()[:5]}, not in the scene's table 0..{len(table) - 1} "
            f"({', '.join(table)})"
        )
    if mask is None:  # absent or unreadable: the mask's own check reports it
        return problems
    if mask.shape != classes.shape:
        return [*problems, f"is {classes.shape[1]}x{classes.shape[0]} but its mask is {mask.shape[1]}x{mask.shape[0]}"]
    fruit = fruit_pixels(mask)
    wrong = int(np.count_nonzero(fruit & (classes != FRUIT)))
    if wrong:
        problems.append(f"{wrong} of {int(fruit.sum())} fruit pixels of the mask are not class {FRUIT} (fruit)")
    return problems

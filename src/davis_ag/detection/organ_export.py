"""Organ classes in the detection exports (``--organs``): semantic masks beside the fruit instances.

Where a view has an organ class image (``NNNN_class.png``), each organ class present in it but
the sky becomes one more label of that image:

- COCO: one annotation per class present, category ``ORGAN_CATEGORY_BASE + value`` (soil 101,
  fruit 102, leaf 103, stem 104, trunk 105; supercategory ``organ``), ``segmentation`` the RLE of
  the class's pixels, ``bbox`` their extent, ``area`` their count, ``iscrowd`` 0 and
  ``attributes.semantic`` true, as COCO-Stuff stores its semantic classes;
- YOLO (``--task segment`` only): one polygon line per class present, class
  ``len(CATEGORIES) + value - 1`` (after the crops), its outline joined as the fruit masks' are.

Views without a class image (the original download) get their fruit labels only.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from davis_ag.data.reader import View
from davis_ag.detection.instances import CATEGORIES
from davis_ag.scene.organs import ORGAN_NAMES, SKY

#: COCO category id of organ class ``v`` is this plus ``v``.
ORGAN_CATEGORY_BASE = 100
#: The organ classes exported (the sky is what is left).
EXPORTED = tuple(v for v in range(len(ORGAN_NAMES)) if v != SKY)


def coco_organ_categories() -> list[dict[str, Any]]:
    """The COCO categories of the organ classes."""
    return [{"id": ORGAN_CATEGORY_BASE + v, "name": ORGAN_NAMES[v], "supercategory": "organ"} for v in EXPORTED]


def organ_masks(view: View) -> list[tuple[int, np.ndarray]]:
    """``(class value, bool mask)`` of every exported organ class present in the view, in class
    order; empty without a class image."""
    classes = view.classes()
    if classes is None:
        return []
    masks = [(value, classes == value) for value in EXPORTED]
    return [(value, mask) for value, mask in masks if mask.any()]


def yolo_organ_class(value: int) -> int:
    """YOLO class of organ class ``value``: after the crops' classes."""
    return len(CATEGORIES) + EXPORTED.index(value)


def yolo_organ_names() -> dict[int, str]:
    """The YOLO names of the organ classes, by class."""
    return {yolo_organ_class(v): f"organ_{ORGAN_NAMES[v]}" for v in EXPORTED}

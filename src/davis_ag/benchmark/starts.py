"""Which starts a TVM-v0 environment draws its episodes from: section V-D's start rule per scene
(OER below 0.4, enough visible pixels), then the split rule's side
(:mod:`davis_ag.formats.splits`), then a robot's reach.

Under the ``scenes`` rule every eligible start of the split's scenes is kept. Under ``starts``
and ``fruits`` the environment opens every scene of the split (train and test alike), names each
eligible start by (scene id, view name, target fruit id) and keeps those of its side. The side
is drawn before a robot's reach is applied, so a robot restricts a split but never moves it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from davis_ag.benchmark.episode_rules import can_start
from davis_ag.benchmark.splits import scene_crop
from davis_ag.formats.splits import Start, check_split_rule, recorded_seed, split_starts
from davis_ag.scene.specs import crop_spec

if TYPE_CHECKING:
    from davis_ag.benchmark.cache import SceneCache
    from davis_ag.data.reader import Dataset, Scene


@dataclass
class SceneStarts:
    """One scene's starts, as compressed rows: views, then boxes per view."""

    views: np.ndarray  # (n,) view indices with at least one start
    offsets: np.ndarray  # (n + 1,) into boxes
    boxes: np.ndarray  # rows of the scene's box tables


def min_pixels(scene: Scene, cache: SceneCache) -> float:
    """Visible pixels a start target needs: scene.json's threshold if the scene has one (what its
    boxes were made with), else the crop's at the image size (the generator's rule)."""
    metadata = scene.metadata
    if metadata is not None and metadata.min_fruit_pixels is not None:
        return float(metadata.min_fruit_pixels)
    crop = scene_crop(scene)
    if crop is None:
        return 0.0
    return float(crop_spec(crop).min_fruit_pixels_at(*cache.image_size))


def eligible(cache: SceneCache, pixels: float, max_oer: float) -> np.ndarray:
    """Which box rows of a scene pass the start rule (OER and visible pixels), as a mask."""
    return can_start(cache.box_oer, max_oer) & (cache.box_pixels >= pixels)


def compress(cache: SceneCache, ok: np.ndarray) -> SceneStarts:
    """The box rows of ``ok`` grouped by view, each view's in annotation order."""
    boxes = np.flatnonzero(ok).astype(np.int32)
    # Rows were written view by view, so a stable sort by view keeps each view's boxes together.
    boxes = boxes[np.argsort(cache.box_view[boxes], kind="stable")]
    views, counts = np.unique(cache.box_view[boxes], return_counts=True)
    offsets = np.concatenate([[0], np.cumsum(counts)]).astype(np.int64)
    return SceneStarts(views=views.astype(np.int32), offsets=offsets, boxes=boxes)


def start_names(scene_id: str, cache: SceneCache, boxes: np.ndarray) -> list[Start]:
    """The identities (scene id, view name, target fruit id) of a scene's box rows."""
    names, fruits = cache.view_names, cache.fruit_ids
    return [
        (scene_id, names[int(v)], int(fruits[int(f)])) for v, f in zip(cache.box_view[boxes], cache.box_fruit[boxes])
    ]


def split_seed(dataset: Dataset) -> int:
    """The seed a dataset's splits are drawn with: splits.json's, else dataset.json's, else 0."""
    splits = getattr(dataset, "splits", None)
    if splits is not None and splits.seed is not None:
        return int(splits.seed)
    return recorded_seed(dataset.root)


def keep_side(
    dataset: Dataset, scenes: list[Scene], caches: list[SceneCache], masks: list[np.ndarray], rule: str, split: str
) -> list[np.ndarray]:
    """The eligible masks narrowed to ``split``'s side of the rule.

    Args:
        dataset: The opened dataset (its split seed).
        scenes: Every scene of the split rule's scenes (:func:`davis_ag.benchmark.splits.select_scenes`).
        caches: Their caches, in the same order.
        masks: Their eligible box rows (:func:`eligible`).
        rule: A split rule (:data:`~davis_ag.formats.splits.SPLIT_RULES`).
        split: ``train``, ``test`` or ``all``.

    Returns:
        The masks, unchanged under ``scenes`` or for ``all``.
    """
    check_split_rule(rule)
    if rule == "scenes" or split == "all":
        return masks
    names = [start_names(s.id, c, np.flatnonzero(m)) for s, c, m in zip(scenes, caches, masks)]
    side = set(split_starts((n for each in names for n in each), split_seed(dataset), rule)[split])
    kept = []
    for mask, each in zip(masks, names):
        narrowed = np.zeros_like(mask)
        narrowed[np.flatnonzero(mask)] = [n in side for n in each]
        kept.append(narrowed)
    return kept

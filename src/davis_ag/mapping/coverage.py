"""Which fruit a row segment has, which view sees which of them, and the share any view can see.

A fruit of the segment is one borne by a plant of the row the cameras face: in a ``row`` scene the
plants on the row's centre line (``|y| < row_spacing / 2``), not those of the two neighbouring rows
the scene grows behind it; in ``mp`` and ``sp`` scenes every plant. A fruit counts as *seen* in a
view where its visible fraction (scene.json's ``visible_fraction``: visible pixels over the pixels
it would cover with nothing in front) is at least :data:`SEEN_FRACTION`. A fruit without a box in
a view (fewer visible pixels than the scene's box threshold) is not seen there.

The move graph of a row grid falls into parts no move joins: the two alleys (the row stands
between them). An episode maps from the part it starts in, so each part's own ceiling (the share
of the segment's fruit seen from at least one of its views) is what bounds that episode.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from scipy.sparse import coo_matrix
from scipy.sparse.csgraph import connected_components

from davis_ag.benchmark.cache import SceneCache
from davis_ag.benchmark.splits import scene_crop, scene_scenario
from davis_ag.errors import UserError
from davis_ag.scene.specs import crop_spec

if TYPE_CHECKING:
    from davis_ag.data.reader import Scene

#: A fruit counts as seen in a view where at least this share of it is visible (the issue's default;
#: docs/mapping.md shows how coverage moves with it).
SEEN_FRACTION = 0.5


@dataclass(frozen=True)
class SegmentCoverage:
    """One scene's segment and what each view sees of it.

    Attributes:
        scene_id: The scene.
        fruit_ids: ``(n,)`` the segment's fruit ids, sorted.
        fruit_xyz: ``(n, 3)`` their centres (world, metres; scene.json's ``fruits``).
        seen: ``(n_views, n)`` bool: fruit ``j`` counts as seen in view ``i`` (views in cache order).
        part: ``(n_views,)`` int: the part of the move graph each view belongs to (an alley).
        threshold: The visible fraction a sighting needs.
    """

    scene_id: str
    fruit_ids: np.ndarray
    fruit_xyz: np.ndarray
    seen: np.ndarray
    part: np.ndarray
    threshold: float

    @property
    def fruit(self) -> int:
        """How many fruit the segment has."""
        return len(self.fruit_ids)

    @property
    def ceiling(self) -> float:
        """The share of the segment's fruit seen from at least one view of the grid (0 without fruit)."""
        return float(self.seen.any(axis=0).mean()) if self.fruit else 0.0

    def part_views(self, part: int) -> np.ndarray:
        """The views of one part of the move graph."""
        return np.flatnonzero(self.part == part)

    def part_ceiling(self, part: int) -> float:
        """The share of the segment's fruit seen from at least one view of ``part``."""
        if not self.fruit:
            return 0.0
        return float(self.seen[self.part_views(part)].any(axis=0).mean())


def move_parts(pointers: np.ndarray) -> np.ndarray:
    """The part of the move graph each view lies in (moves join views both ways, so parts are the
    graph's connected components; a view no move enters or leaves is a part of its own).

    Args:
        pointers: ``(n_views, n_moves)`` the view each move leads to, -1 for none.
    """
    rows, columns = np.nonzero(pointers >= 0)
    n = len(pointers)
    graph = coo_matrix((np.ones(len(rows), dtype=np.int8), (rows, pointers[rows, columns])), shape=(n, n))
    _, labels = connected_components(graph, directed=False)
    return labels.astype(np.int32)


def segment_plants(scene: Scene) -> set[int]:
    """The indices of the plants whose fruit make the segment (see the module docstring).

    Raises:
        UserError: when the scene has no scene.json with its plants (only generated scenes have one).
    """
    metadata = scene.metadata
    if metadata is None or not metadata.plants:
        raise UserError(
            f"scene {scene.id} has no scene.json with its plants and fruit: mapping needs scenes "
            "davis-ag generate wrote (the original download records no fruit positions)"
        )
    crop = scene_crop(scene)
    row = crop_spec(crop).row if crop is not None and scene_scenario(scene) == "row" else None
    half = row.row_spacing / 2 if row is not None else np.inf
    return {int(p.index) for p in metadata.plants if p.index is not None and p.position and abs(p.position[1]) < half}


def segment_coverage(
    scene: Scene, cache: SceneCache, pointers: np.ndarray, threshold: float = SEEN_FRACTION
) -> SegmentCoverage:
    """Build a scene's :class:`SegmentCoverage` from its scene.json.

    Args:
        scene: A reader scene with its scene.json.
        cache: Its observation cache (the view order).
        pointers: The moves the episode may make (a robot's restricted table), for the parts.
        threshold: The visible fraction a sighting needs, in (0, 1].

    Raises:
        UserError: for a threshold outside (0, 1] or a scene without scene.json.
    """
    if not 0.0 < threshold <= 1.0:
        raise UserError(f"seen fraction {threshold} is outside (0, 1]: give a share such as 0.5")
    plants = segment_plants(scene)
    metadata = scene.metadata
    assert metadata is not None  # segment_plants refused a scene without one
    fruits = sorted(
        (int(f.id), tuple(float(c) for c in (f.center or (np.nan,) * 3)))
        for f in metadata.fruits
        if f.id is not None and f.plant in plants
    )
    ids = np.array([f for f, _ in fruits], dtype=np.int64)
    column = {int(f): j for j, f in enumerate(ids)}
    seen = np.zeros((cache.n_views, len(ids)), dtype=bool)
    for i, name in enumerate(cache.view_names):
        for text, fraction in metadata.visible_in(name).items():
            j = column.get(int(text))
            if j is not None and float(fraction) >= threshold:
                seen[i, j] = True
    xyz = np.array([c for _, c in fruits], dtype=np.float64).reshape(-1, 3)
    return SegmentCoverage(scene.id, ids, xyz, seen, move_parts(pointers), float(threshold))

"""The numbers behind the figures, read from annotations.json (and scene.json where present).

Nothing here draws; the plotting modules call these and return what they computed, so tests
can check every count and bin against the annotations.

- A *position* is where the camera stood: views whose pose has the same ``x, y, z`` (to the
  millimetre) are one position. Our multi-plant scenes give each station one slip shared by
  its 12 headings, so the headings of a station fall together; the paper's Fig. 2 counts
  fruit per position.
- The *same location at another altitude* is what the ``up`` pointer leads to: the dataset's
  own link, valid for our data and the original download alike, whatever the grid's lattice.
- A fruit is *visible* in a view when the view has a box for it (section III-C's pixel
  threshold decided that when the dataset was made).
"""

from __future__ import annotations

from dataclasses import dataclass, field
from itertools import combinations
from typing import Any

import numpy as np

from davis_ag.data.reader import Scene, View, exposure_rate
from davis_ag.errors import UserError

#: Fig. 2's colour classes: at least this many of the paper's 24 fruit were visible.
PAPER_CLASS_EDGES = (5, 10, 16)
#: The paper's Fig. 2 scene had this many fruit; other scenes scale the class edges with theirs.
PAPER_FRUIT = 24


@dataclass
class Position:
    """One camera position of a scene and the fruit seen from it.

    Attributes:
        x, y, z: Where the camera stood (metres, the pose's values).
        views: The view names taken there (several headings in MP scenes).
        fruit: Ids of the fruit boxed in any of those views.
    """

    x: float
    y: float
    z: float
    views: list[str] = field(default_factory=list)
    fruit: set[int] = field(default_factory=set)


def _posed(scene: Scene) -> list[View]:
    views = [v for v in scene.views.values() if v.pose is not None]
    if not views:
        raise UserError(f"{scene.annotations_path}: no view has a pose; the figure needs poses")
    return views


def positions(scene: Scene) -> list[Position]:
    """Group a scene's views by camera position.

    Args:
        scene: The scene.

    Returns:
        One :class:`Position` per distinct ``(x, y, z)`` to the millimetre, in view order.

    Raises:
        UserError: when no view has a pose.
    """
    found: dict[tuple[int, int, int], Position] = {}
    for view in _posed(scene):
        assert view.pose is not None  # _posed keeps the views with a pose
        x, y, z = view.pose[:3]
        key = (round(x * 1000), round(y * 1000), round(z * 1000))
        spot = found.setdefault(key, Position(x, y, z))
        spot.views.append(view.name)
        spot.fruit.update(b.fruit_id for b in view.boxes)
    return list(found.values())


def altitudes(scene: Scene) -> list[float]:
    """The scene's camera altitudes (pose z to the centimetre), lowest first."""
    return sorted({round(pose[2], 2) for v in _posed(scene) if (pose := v.pose) is not None})


def scene_fruit_count(scene: Scene) -> int:
    """How many fruit the scene holds: scene.json's list, else every id boxed in some view."""
    if scene.metadata and scene.metadata.fruits:
        return len(scene.metadata.fruits)
    return len({b.fruit_id for v in scene.views.values() for b in v.boxes})


def class_edges(total_fruit: int) -> tuple[int, ...]:
    """Fig. 2's class edges (5, 10, 16 of 24 fruit) scaled to a scene of ``total_fruit`` fruit.

    Edges stay strictly increasing and at least 1, so every class keeps its meaning.
    """
    if total_fruit == PAPER_FRUIT:
        return PAPER_CLASS_EDGES
    edges: list[int] = []
    for edge in PAPER_CLASS_EDGES:
        value = max(1, round(edge * total_fruit / PAPER_FRUIT))
        edges.append(max(value, edges[-1] + 1) if edges else value)
    return tuple(edges)


def visibility_classes(counts: np.ndarray, edges: tuple[int, ...]) -> np.ndarray:
    """Class of each count: 0 below ``edges[0]``, k when at least ``edges[k-1]`` (Fig. 2's legend)."""
    return np.searchsorted(np.asarray(edges), np.asarray(counts), side="right")


def altitude_columns(scene: Scene) -> list[dict[int, set[int]]]:
    """For every lowest view of a location, the fruit seen at each altitude above it.

    A column starts at a view with no valid ``down`` move and follows ``up`` while it is valid.

    Args:
        scene: The scene.

    Returns:
        One dict per column: altitude level (index into :func:`altitudes`) to fruit ids.

    Raises:
        UserError: when the scene has no ``up`` pointers or fewer than two altitudes.
    """
    levels = altitudes(scene)
    if len(levels) < 2 or "up" not in scene.actions:
        raise UserError(
            f"{scene.annotations_path}: scene {scene.id} has {len(levels)} altitude(s) "
            "and no up/down moves; the altitude figure needs at least two altitudes"
        )
    level_of = {lv: i for i, lv in enumerate(levels)}
    columns = []
    for view in _posed(scene):
        if view.pointers.get("down"):
            continue  # not the lowest view of its column
        column: dict[int, set[int]] = {}
        current: View | None = view
        climbed: set[str] = set()
        while current is not None and current.pose is not None:
            if current.name in climbed:  # "up" pointers that lead back down: no column to draw
                raise UserError(
                    f"{scene.annotations_path}: the up moves from {view.name} come back to {current.name}; "
                    "fix its pointers (up must climb) or regenerate the scene"
                )
            climbed.add(current.name)
            column[level_of[round(current.pose[2], 2)]] = {b.fruit_id for b in current.boxes}
            current = current.next("up")
        if len(column) > 1:
            columns.append(column)
    return columns


def altitude_changes(scene: Scene) -> dict[str, Any]:
    """Fig. 3's numbers: visible-fruit differences and newly seen fruit between altitudes.

    For altitude levels ``i < j`` at the same location: ``|H_i| - |H_j|`` (positive when the
    lower view sees more) and ``|H_j \\ H_i|`` (fruit seen higher up and not lower); with three
    or more levels also ``|H_top \\ (H_lower...)|`` over every lower level of the column.

    Args:
        scene: The scene.

    Returns:
        ``{"altitudes": [...], "columns": n, "differences": {label: [...]},
        "novel": {label: [...]}}``, labels like ``"|H1|-|H2|"`` and ``"H2\\H1"``.
    """
    levels = altitudes(scene)
    columns = altitude_columns(scene)
    differences: dict[str, list[int]] = {}
    novel: dict[str, list[int]] = {}
    for i, j in combinations(range(len(levels)), 2):
        pairs = [(c[i], c[j]) for c in columns if i in c and j in c]
        differences[f"|H{i + 1}|-|H{j + 1}|"] = [len(a) - len(b) for a, b in pairs]
        novel[f"H{j + 1}\\H{i + 1}"] = [len(b - a) for a, b in pairs]
    if len(levels) >= 3:
        top = len(levels) - 1
        lower = "∪".join(f"H{k + 1}" for k in range(top))
        full = [c for c in columns if all(k in c for k in range(top + 1))]
        novel[f"H{top + 1}\\({lower})"] = [len(c[top] - set().union(*(c[k] for k in range(top)))) for c in full]
    return {"altitudes": levels, "columns": len(columns), "differences": differences, "novel": novel}


def integer_histogram(values: list[int] | np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Counts per integer value: bins centred on integers, from the smallest value to the largest.

    Returns:
        ``(counts, edges)`` as :func:`numpy.histogram` gives them; empty input gives one empty bin.
    """
    values = np.asarray(values, dtype=int)
    if values.size == 0:
        return np.zeros(1, dtype=int), np.array([-0.5, 0.5])
    edges = np.arange(values.min() - 0.5, values.max() + 1.5)
    counts, edges = np.histogram(values, bins=edges)
    return counts, edges


def box_oers(scenes: list[Scene]) -> tuple[np.ndarray, int]:
    """The OER (eq. 1) of every box, from the instance masks.

    Args:
        scenes: The scenes.

    Returns:
        ``(oer per box, boxes skipped because their view has no mask)``.
    """
    values: list[float] = []
    skipped = 0
    for scene in scenes:
        for view in scene.views.values():
            if not view.boxes:
                continue
            mask = view.mask()
            if mask is None:
                skipped += len(view.boxes)
                continue
            values.extend(exposure_rate(mask, box) for box in view.boxes)
    return np.asarray(values, dtype=float), skipped


def visible_fractions(scenes: list[Scene]) -> np.ndarray:
    """Every box's visible fraction from scene.json (ours only; empty for the original download)."""
    values = [
        float(f)
        for s in scenes
        for per_view in (s.metadata.visible_fraction.values() if s.metadata else ())
        for f in per_view.values()
    ]
    return np.asarray(values, dtype=float)

"""Where fruit can be seen from: the paper's Fig. 2 (visible fruit per camera position, one
panel per altitude) and Fig. 3 (how that changes between altitudes at the same location).

Positions come from the poses in annotations.json, so any lattice (square or staggered) and
the original download draw alike; the numbers come from :mod:`davis_ag.figures.scene_numbers`.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from davis_ag.data.reader import Scene
from davis_ag.figures.canvas import FORMATS, Plotted, new_figure, save_formats
from davis_ag.figures.scene_numbers import (
    altitude_changes,
    class_edges,
    integer_histogram,
    positions,
    scene_fruit_count,
    visibility_classes,
)
from davis_ag.scene.specs import crop_spec, plant_positions, scenario_spec

if TYPE_CHECKING:
    from matplotlib.axes import Axes

#: Fig. 2's colours, lowest class first: grey, pink, green, blue.
CLASS_COLOURS = ("#8c8c8c", "#f7c6cc", "#4c9a3f", "#3a3af0")


def plant_xy(scene: Scene) -> list[tuple[float, float]]:
    """Where the scene's plants stand: scene.json's positions, else the scenario's layout.

    Args:
        scene: The scene.

    Returns:
        ``(x, y)`` per plant; empty for a folder name that is no DAVIS-Ag group and no scene.json.
    """
    plants = scene.metadata.plants if scene.metadata else []
    if plants:
        return [(float(p.position[0]), float(p.position[1])) if p.position else (0.0, 0.0) for p in plants]
    if scene.scenario and scene.crop:
        return plant_positions(scenario_spec(scene.scenario), crop_spec(scene.crop))
    return []


def draw_plants(ax: Axes, scene: Scene) -> None:
    """Mark the scene's plants with black crosses (as Fig. 2 does)."""
    xy = plant_xy(scene)
    if xy:
        ax.scatter(
            [p[0] for p in xy],
            [p[1] for p in xy],
            marker="x",
            color="black",
            s=40,
            linewidths=1.5,
            label="plant",
            zorder=3,
        )


def plot_visibility(scene: Scene, out: str | Path, formats: tuple[str, ...] = FORMATS) -> Plotted:
    """Fig. 2: every camera position coloured by the number of fruit visible from it.

    A position's count is the number of distinct fruit boxed in its views (the union over
    headings where a position has several). Classes follow Fig. 2 (<5, >=5, >=10, >=16 of 24
    fruit), their edges scaled to the scene's fruit count.

    Args:
        scene: The scene.
        out: Output path without suffix.
        formats: File formats to write.

    Returns:
        The paths and ``{"scene", "fruit", "edges", "altitudes": [{"z", "x", "y", "count",
        "class"}]}``.
    """
    spots = positions(scene)
    total = scene_fruit_count(scene)
    edges = class_edges(total)
    levels = sorted({round(p.z, 2) for p in spots})
    labels = [f"<{edges[0]}"] + [f">={e}" for e in edges]
    figure = new_figure(3.4 * len(levels) + 1.2, 3.5)
    panels = []
    xs, ys = [p.x for p in spots], [p.y for p in spots]
    pad = 0.15
    for i, z in enumerate(levels):
        here = [p for p in spots if round(p.z, 2) == z]
        counts = np.array([len(p.fruit) for p in here])
        classes = visibility_classes(counts, edges)
        ax = figure.add_subplot(1, len(levels), i + 1)
        for k in range(len(labels) - 1, -1, -1):
            chosen = classes == k
            ax.scatter(
                np.array([p.x for p in here])[chosen],
                np.array([p.y for p in here])[chosen],
                s=46,
                color=CLASS_COLOURS[k],
                edgecolors="#303030",
                linewidths=0.6,
                label=labels[k],
                zorder=2,
            )
        draw_plants(ax, scene)
        ax.set_xlim(min(xs) - pad, max(xs) + pad)
        ax.set_ylim(min(ys) - pad, max(ys) + pad)
        ax.set_aspect("equal")
        ax.set_title(f"{z:.2f} m", fontsize=10)
        ax.tick_params(labelsize=7)
        panels.append(
            {
                "z": z,
                "x": [p.x for p in here],
                "y": [p.y for p in here],
                "count": counts.tolist(),
                "class": classes.tolist(),
            }
        )
    handles, names = figure.axes[0].get_legend_handles_labels()
    figure.legend(
        handles, names, loc="center right", fontsize=8, frameon=False, title=f"visible of {total}", title_fontsize=8
    )
    figure.suptitle(f"{scene.id}: visible fruit per camera position", fontsize=10)
    figure.tight_layout(rect=(0, 0, 1 - 1.1 / (3.4 * len(levels) + 1.2), 1))
    paths = save_formats(figure, out, formats)
    return Plotted(paths, {"scene": scene.id, "fruit": total, "edges": list(edges), "altitudes": panels})


def _grouped_histogram(ax: Axes, series: dict[str, list[int]], xlabel: str) -> dict[str, dict[str, list]]:
    """Bars of several integer histograms side by side on shared integer bins."""
    every = [v for values in series.values() for v in values]
    _, edges = integer_histogram(every)
    centres = (edges[:-1] + edges[1:]) / 2
    width = 0.8 / max(len(series), 1)
    drawn = {}
    for k, (label, values) in enumerate(series.items()):
        counts = np.histogram(values, bins=edges)[0] if values else np.zeros(len(centres), dtype=int)
        ax.bar(
            centres - 0.4 + width * (k + 0.5), counts, width=width, label=f"{label} (n={len(values)})", color=f"C{k}"
        )
        drawn[label] = {"edges": edges.tolist(), "counts": counts.tolist()}
    ax.set_xlabel(xlabel, fontsize=9)
    ax.set_ylabel("locations", fontsize=9)
    ax.legend(fontsize=7)
    ax.tick_params(labelsize=7)
    return drawn


def plot_altitude(scene: Scene, out: str | Path, formats: tuple[str, ...] = FORMATS) -> Plotted:
    """Fig. 3: (a) the change in visible fruit between altitudes at the same location and (b) the
    fruit newly seen higher up.

    ``H_k`` is the set of fruit boxed at altitude ``z_k`` (``z_1`` lowest); a location is a
    column of views joined by the ``up`` pointers.

    Args:
        scene: The scene (two altitudes at least).
        out: Output path without suffix.
        formats: File formats to write.

    Returns:
        The paths and :func:`~davis_ag.figures.scene_numbers.altitude_changes`'s numbers plus
        ``"histograms"``: ``{"differences"|"novel": {label: {"edges", "counts"}}}``.

    Raises:
        UserError: when the scene has fewer than two altitudes.
    """
    changes = altitude_changes(scene)
    figure = new_figure(10.0, 3.6)
    left, right = figure.add_subplot(1, 2, 1), figure.add_subplot(1, 2, 2)
    heights = ", ".join(f"z{k + 1}={z:.2f} m" for k, z in enumerate(changes["altitudes"]))
    histograms = {
        "differences": _grouped_histogram(left, changes["differences"], "|H_i| - |H_j| (fruit)"),
        "novel": _grouped_histogram(right, changes["novel"], "fruit seen only from higher up"),
    }
    left.set_title("(a) lower minus higher altitude", fontsize=9)
    right.set_title("(b) newly seen at higher altitudes", fontsize=9)
    figure.suptitle(f"{scene.id}: {changes['columns']} locations; {heights}", fontsize=9)
    figure.tight_layout()
    paths = save_formats(figure, out, formats)
    return Plotted(paths, {"scene": scene.id, **changes, "histograms": histograms})

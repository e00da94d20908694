"""A scene's view grid seen from above, each camera station coloured by a robot's reach.

One panel per camera height; x along the row, y across it. A station's colour is the share of
its headings the robot reaches (a single plant's grid has one heading a station: reached or
not); a cross marks a station it reaches at no heading. The base lines are drawn dashed, the
plants' stems as green dots and the trunk points the reach avoided as grey specks.
"""

from __future__ import annotations

from collections import defaultdict
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from davis_ag.figures.canvas import new_figure, save_figure

if TYPE_CHECKING:
    from davis_ag.data.reader import Scene
    from davis_ag.robot.reach import SceneReach


def plot_scene_reach(
    scene: Scene, reach: SceneReach, base_ys: tuple[float, ...], path: str | Path, trunks: np.ndarray | None = None
) -> Path:
    """Draw one scene's reach (see the module docstring) and save it as PNG.

    Args:
        scene: The scene.
        reach: One robot's reach of it.
        base_ys: The y of each base line, m.
        path: The PNG to write (atomically).
        trunks: ``(n, 3)`` obstacle points to draw, or ``None``.

    Returns:
        The path written.
    """
    stations: dict[float, dict[tuple[float, float], list[bool]]] = defaultdict(lambda: defaultdict(list))
    from davis_ag.robot.reach import view_poses

    for pose, ok in zip(view_poses(scene), reach.reachable):
        x, y, z = (round(float(v), 3) for v in pose[:3])
        stations[round(z, 2)][(x, y)].append(bool(ok))
    heights = sorted(stations)
    figure = new_figure(5.2 * len(heights), 4.2)
    axes = figure.subplots(1, len(heights), squeeze=False)[0]
    stems = [p.position for p in (scene.metadata.plants or [])] if scene.metadata else []
    for ax, z in zip(axes, heights):
        xy = np.array(list(stations[z]))
        share = np.array([np.mean(v) for v in stations[z].values()])
        if trunks is not None and len(trunks):
            near = trunks[np.abs(trunks[:, 2] - z) < 0.5]
            ax.scatter(near[:, 0], near[:, 1], s=0.2, c="0.7", linewidths=0)
        if stems:
            stem = np.array([s[:2] for s in stems if s])
            ax.scatter(stem[:, 0], stem[:, 1], s=12, c="tab:green", label="stems")
        art = ax.scatter(
            xy[:, 0], xy[:, 1], c=share, cmap="viridis", vmin=0, vmax=1, s=28, edgecolors="k", linewidths=0.3
        )
        none = share == 0
        ax.scatter(xy[none, 0], xy[none, 1], marker="x", c="tab:red", s=18, linewidths=0.8)
        for y in base_ys:
            ax.axhline(y, ls="--", c="0.3", lw=0.8)
        ax.set_title(f"camera at {z:g} m: {share.mean() * 100:.0f} % of views reached")
        ax.set_xlabel("x along the row (m)")
        ax.set_ylabel("y across (m)")
        ax.set_aspect("equal")
        figure.colorbar(art, ax=ax, fraction=0.04, label="share of headings reached")
    figure.suptitle(f"{scene.id}: {reach.robot} reaches {reach.share * 100:.0f} % of {len(reach.reachable)} views")
    figure.tight_layout()
    out = Path(path)
    save_figure(figure, out, dpi=100)
    return out

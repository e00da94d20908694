"""Pictures of row mapping: every policy's coverage curve over the budget, and one episode drawn on
its row segment (each fruit coloured by the step it was first seen, the camera's path drawn)."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from davis_ag.atomic_files import save_figure_atomic
from davis_ag.mapping.coverage import SegmentCoverage
from davis_ag.mapping.results import MappingEpisode, MappingResults, coverage_curve


def plot_coverage_curves(results: MappingResults, path: str | os.PathLike[str], title: str | None = None) -> Path:
    """Mean coverage after each move of the budget per policy (band: the standard error over
    episodes), with the budget's bound and the start parts' ceiling as dashed lines; saved as PNG.

    Args:
        results: A mapping evaluation.
        path: The PNG to write.
        title: The figure's title (default: the split, scenes and episodes it rests on).

    Returns:
        ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    protocol = results.protocol
    budget = protocol.budget
    moves = np.arange(budget + 1)
    fig, ax = plt.subplots(figsize=(6.4, 4.0))
    ordered = sorted(results.policies.items(), key=lambda item: -item[1].coverage.mean)
    for i, (name, row) in enumerate(ordered):
        curves = np.array([coverage_curve(e, budget) / e.fruit for e in row.episodes])
        mean = curves.mean(axis=0)
        sem = curves.std(axis=0) / np.sqrt(len(curves))
        ax.plot(moves, mean, color=f"C{i}", label=f"{name} ({mean[-1]:.3f})")
        ax.fill_between(moves, mean - sem, mean + sem, color=f"C{i}", alpha=0.25, linewidth=0)
    first = ordered[0][1]
    ax.axhline(
        first.bound, color="k", linestyle="--", linewidth=1, label=f"bound, best {budget + 1} views ({first.bound:.3f})"
    )
    ax.axhline(
        first.part_ceiling,
        color="grey",
        linestyle=":",
        linewidth=1.2,
        label=f"ceiling, start's alley ({first.part_ceiling:.3f})",
    )
    ax.set_xlabel("moves")
    ax.set_ylabel("coverage (share of the segment's fruit seen)")
    ax.set_xlim(0, budget)
    ax.set_ylim(0, 1)
    ax.grid(alpha=0.3)
    ax.legend(fontsize=8, loc="upper left")
    crop = f" {protocol.crop}" if protocol.crop else ""
    ax.set_title(
        title
        or f"{protocol.scenario}{crop} {protocol.split}: {len(protocol.scenes)} scene(s), "
        f"{protocol.sessions} x {protocol.episodes} episodes",
        fontsize=10,
    )
    fig.tight_layout()
    try:
        return save_figure_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)


def first_seen_steps(coverage: SegmentCoverage, view_indices: list[int]) -> np.ndarray:
    """The step at which each fruit of the segment was first seen along a path of views (-1: never)."""
    first = np.full(coverage.fruit, -1, dtype=np.int64)
    for step, view in enumerate(view_indices):
        fresh = coverage.seen[view] & (first < 0)
        first[fresh] = step
    return first


def plot_mapping_episode(
    coverage: SegmentCoverage,
    camera_xy: np.ndarray,
    episode: MappingEpisode,
    view_indices: list[int],
    path: str | os.PathLike[str],
    title: str = "",
) -> Path:
    """One episode on its segment: a top view (x, y) with the camera's path and every fruit, and a
    side view (x, height) of the fruit, each coloured by the step it was first seen (grey: never).

    Args:
        coverage: The scene's segment.
        camera_xy: ``(n_views, 2)`` each view's nominal camera position.
        episode: The episode (its path).
        view_indices: The path as view indices of the scene's cache.
        path: The PNG to write.
        title: The figure's title.

    Returns:
        ``path``.
    """
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    first = first_seen_steps(coverage, view_indices)
    seen = first >= 0
    steps = max(len(view_indices) - 1, 1)
    fig, (top, side) = plt.subplots(
        2, 1, figsize=(8.0, 5.2), gridspec_kw={"height_ratios": [1, 1]}, layout="constrained"
    )
    xyz = coverage.fruit_xyz
    for ax, (a, b), label in ((top, (0, 1), "y (m)"), (side, (0, 2), "height (m)")):
        ax.scatter(xyz[~seen, a], xyz[~seen, b], s=8, color="0.75", label="never seen")
        dots = ax.scatter(
            xyz[seen, a], xyz[seen, b], s=12, c=first[seen], cmap="viridis", vmin=0, vmax=steps, label="seen"
        )
        ax.set_ylabel(label)
        ax.set_aspect("equal")
        ax.grid(alpha=0.3)
    track = camera_xy[view_indices]
    top.scatter(camera_xy[:, 0], camera_xy[:, 1], s=2, color="0.85", zorder=0)
    top.plot(track[:, 0], track[:, 1], color="crimson", linewidth=1.5, marker="o", markersize=3, label="camera path")
    top.plot(track[:1, 0], track[:1, 1], marker="*", markersize=12, color="crimson", linestyle="none")
    top.legend(fontsize=7, loc="upper right")
    side.set_xlabel("x along the row (m)")
    fig.colorbar(dots, ax=[top, side], label="move at which first seen", shrink=0.8)
    share = seen.mean() if len(seen) else 0.0
    fig.suptitle(title or f"{episode.scene}: {seen.sum()} of {coverage.fruit} fruit seen ({share:.0%})", fontsize=10)
    try:
        return save_figure_atomic(fig, path, dpi=120)
    finally:
        plt.close(fig)

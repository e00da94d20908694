"""One episode as the paper's Fig. 6 draws it: the views the agent saw, left to right, each
captioned with the action taken next, the target boxed, other fruit boxed yellow when first
seen and red when seen before; beside them the scene's camera positions with the path drawn
and the current position as a red diamond.

The episode comes from ``davis-ag evaluate``'s per-episode records (``path`` holds the view
names, ``actions`` the action indices) or is walked here from a start view and action names
with the environment's rule: a move that is invalid or loses the target leaves the camera put.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import Any

from davis_ag.data.reader import Scene, View, exposure_rate
from davis_ag.errors import UserError
from davis_ag.figures.canvas import FORMATS, Plotted, new_figure, save_formats
from davis_ag.figures.scene_numbers import positions
from davis_ag.figures.visibility_plots import draw_plants

#: Most views a strip shows (the paper's Fig. 6 shows seven).
MAX_STRIP = 8
_TARGET = "#00e5ff"


def walk(scene: Scene, start: str, actions: list[str], target: int | None) -> list[str]:
    """The views an episode visits: the start, then one per move (``done`` ends it).

    Args:
        scene: The scene.
        start: The first view (``"0001"``, ``"0001.jpeg"`` or a number).
        actions: Action names.
        target: The target fruit; a move to a view without its box is refused, as in the
            environment. ``None`` refuses invalid moves only.

    Returns:
        View names, the start first; a refused move repeats the current view.

    Raises:
        UserError: for an unknown view or action, or a target not boxed in the start view.
    """
    view = scene.view(start)
    if target is not None and view.box(target) is None:
        boxed = ", ".join(str(b.fruit_id) for b in view.boxes) or "none"
        raise UserError(
            f"scene {scene.id}: view {view.name} has no box of fruit {target} "
            f"(its boxes: {boxed}); choose a target boxed in the start view"
        )
    path = [view.name]
    for action in actions:
        if action == "done":
            break
        nxt = view.next(action)
        if nxt is not None and (target is None or nxt.box(target) is not None):
            view = nxt
        path.append(view.name)
    return path


def _oer(view: View, target: int | None) -> float | None:
    box = view.box(target) if target is not None else None
    mask = view.mask() if box is not None else None
    return exposure_rate(mask, box) if mask is not None and box is not None else None


def plot_episode(
    scene: Scene,
    path: list[str],
    actions: list[str],
    target: int | None,
    out: str | Path,
    formats: tuple[str, ...] = FORMATS,
    title: str = "",
) -> Plotted:
    """Fig. 6: the episode's views in a strip beside the map of the scene with the path.

    Args:
        scene: The scene.
        path: View names visited (the start first), as :func:`walk` or the results give them.
        actions: The action names taken, one per step (the last may be ``done``).
        target: The target fruit id, boxed in cyan; ``None`` for none.
        out: Output path without suffix.
        formats: File formats to write.
        title: Figure title (default: scene, target and the OER at the start and the end).

    Returns:
        The paths and ``{"scene", "target", "views", "actions", "poses", "oer": [per view]}``.

    Raises:
        UserError: for a path naming no view of the scene.
    """
    from matplotlib.patches import Rectangle

    views = [scene.view(name) for name in path]
    shown = views[:MAX_STRIP]
    columns = min(len(shown), 4)
    rows = math.ceil(len(shown) / columns)
    figure = new_figure(3.3 * columns + 3.2, 2.3 * rows + 0.7)
    grid = figure.add_gridspec(rows, columns + 1, width_ratios=[1.0] * columns + [0.95])
    seen: set[int] = set()
    oers = [_oer(v, target) for v in views]
    for i, view in enumerate(shown):
        ax = figure.add_subplot(grid[i // columns, i % columns])
        ax.imshow(view.image(), interpolation="nearest")
        for box in view.boxes:
            colour = _TARGET if box.fruit_id == target else ("red" if box.fruit_id in seen else "yellow")
            ax.add_patch(
                Rectangle(
                    (box.xmin - 0.5, box.ymin - 0.5),
                    box.width,
                    box.height,
                    fill=False,
                    edgecolor=colour,
                    linewidth=2.0 if box.fruit_id == target else 0.8,
                )
            )
        seen.update(b.fruit_id for b in view.boxes)
        step = actions[i] if i < len(actions) else "end"
        oer = f", OER {oers[i]:.2f}" if oers[i] is not None else ""
        z = f", z={view.pose[2]:.2f} m" if view.pose is not None else ""
        ax.set_title(f"t={i}: {view.name}{z}{oer}\nnext: {step}", fontsize=7)
        ax.set_axis_off()
    ax = figure.add_subplot(grid[:, columns])
    spots = positions(scene)
    ax.scatter([p.x for p in spots], [p.y for p in spots], s=5, color="#c8c8c8", label="camera positions")
    draw_plants(ax, scene)
    xy = [(v.pose[0], v.pose[1]) for v in views if v.pose is not None]
    if xy:
        ax.plot(
            [p[0] for p in xy], [p[1] for p in xy], "-o", color="tab:blue", markersize=3, linewidth=1.5, label="path"
        )
        ax.scatter([xy[-1][0]], [xy[-1][1]], marker="D", s=60, color="red", zorder=4, label="current")
    ax.set_aspect("equal")
    ax.legend(fontsize=6, loc="upper center", bbox_to_anchor=(0.5, -0.1), ncol=2, frameon=False)
    ax.tick_params(labelsize=7)
    ax.set_title("global map (x, y in m)", fontsize=8)
    start, end = oers[0], oers[-1]
    figure.suptitle(
        title
        or f"{scene.id}, target fruit {target}: OER "
        f"{'-' if start is None else f'{start:.3f}'} -> {'-' if end is None else f'{end:.3f}'}",
        fontsize=9,
    )
    figure.tight_layout()
    # Room under the map for its legend's two rows, which tight_layout leaves out (they ran off the foot).
    figure.subplots_adjust(bottom=max(figure.subplotpars.bottom, 0.75 / figure.get_figheight()))
    paths = save_formats(figure, out, formats)
    return Plotted(
        paths,
        {
            "scene": scene.id,
            "target": target,
            "views": [v.name for v in views],
            "actions": list(actions),
            "poses": [list(v.pose) if v.pose else None for v in views],
            "oer": oers,
        },
    )


def episode_from_results(
    results: dict[str, Any], policy: str, index: int, source: str = "results"
) -> tuple[str, list[str], list[str], int]:
    """Pick one recorded episode: ``(scene id, path, action names, target fruit)``.

    Args:
        results: ``davis-ag evaluate``'s results.
        policy: The policy whose episode to draw.
        index: Episode number in the policy's records (0 first).
        source: The results file's name, for messages.

    Raises:
        UserError: for an unknown policy, results without episodes or an index out of range.
    """
    from davis_ag.figures.benchmark_plots import action_names, episode_records, policy_names

    policy_names(results, source, [policy])
    episodes = episode_records(results, policy, source)
    if not 0 <= index < len(episodes):
        raise UserError(f"{source}: policy {policy} has episodes 0..{len(episodes) - 1}, not {index}")
    record = episodes[index]
    names = action_names(results)
    return record["scene"], list(record["path"]), [names[a] for a in record["actions"]], int(record["target_fruit"])

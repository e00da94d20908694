"""Pictures for eyeballing a scene: a grid of views with their boxes, and a view beside its mask.

Figures are drawn on matplotlib's Agg canvas directly (no pyplot), so nothing touches a display
or pyplot's global figure list, and each PNG is written atomically so an interrupted run never
leaves a half-written picture behind.
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from davis_ag.data.reader import Scene, View
from davis_ag.errors import UserError
from davis_ag.figures.canvas import new_figure, save_figure
from davis_ag.formats.masks import fruit_pixels, no_fruit_value

if TYPE_CHECKING:
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

_TILE_INCHES = 3.2


def _pose_text(view: View) -> str:
    if view.pose is None:
        return "no pose"
    names = ("x", "y", "z", "yaw", "pitch")
    return " ".join(f"{n}={v:.2f}" if i < 3 else f"{n}={v:.0f}" for i, (n, v) in enumerate(zip(names, view.pose)))


def draw_boxes(ax: Axes, view: View, labels: bool) -> None:
    """Outline every fruit box of ``view`` in yellow on ``ax``, with its fruit id when ``labels``."""
    from matplotlib.patches import Rectangle

    for box in view.boxes:
        # Pixel centres sit on integers, so a pixel's outer edge is half a unit out.
        ax.add_patch(
            Rectangle(
                (box.xmin - 0.5, box.ymin - 0.5), box.width, box.height, fill=False, edgecolor="yellow", linewidth=0.8
            )
        )
        if labels:
            ax.text(box.xmin - 0.5, box.ymin - 1, str(box.fruit_id), color="yellow", fontsize=6, va="bottom", ha="left")


def pick_views(scene: Scene, n_views: int) -> list[View]:
    """Up to ``n_views`` views spread evenly over the scene, first and last included.

    Args:
        scene: The scene.
        n_views: How many to pick (at least 1).

    Returns:
        The views, in image order.
    """
    views = list(scene.views.values())
    if not views or n_views < 1:
        return []
    picks = np.linspace(0, len(views) - 1, min(n_views, len(views))).round().astype(int)
    return [views[i] for i in sorted(set(picks.tolist()))]


def contact_sheet_figure(scene: Scene, n_views: int = 12, columns: int = 4) -> Figure:
    """A grid of a scene's views with every fruit box, titled with view name and pose.

    Args:
        scene: The scene.
        n_views: Views to show, spread evenly over the scene.
        columns: Tiles per row.

    Returns:
        The figure (not saved).

    Raises:
        UserError: for a scene without views or non-positive sizes.
    """
    if n_views < 1 or columns < 1:
        raise UserError(f"contact sheet needs n_views >= 1 and columns >= 1, got {n_views} and {columns}")
    views = pick_views(scene, n_views)
    if not views:
        raise UserError(f"{scene.annotations_path}: scene {scene.id} has no views to draw")
    columns = min(columns, len(views))
    rows = math.ceil(len(views) / columns)
    figure = new_figure(columns * _TILE_INCHES, rows * _TILE_INCHES * 0.72)
    figure.suptitle(f"{scene.id}: {len(views)} of {len(scene.views)} views", fontsize=9)
    for i, view in enumerate(views):
        ax = figure.add_subplot(rows, columns, i + 1)
        ax.imshow(view.image(), interpolation="nearest")
        draw_boxes(ax, view, labels=False)
        ax.set_title(f"{view.name}  {len(view.boxes)} boxes\n{_pose_text(view)}", fontsize=6)
        ax.set_axis_off()
    figure.tight_layout()
    return figure


def draw_contact_sheet(scene: Scene, out_path: str | Path, n_views: int = 12, columns: int = 4) -> Path:
    """Draw :func:`contact_sheet_figure` to one file (format from the suffix).

    Args:
        scene: The scene.
        out_path: Where the picture goes; its folder is created.
        n_views: Views to show, spread evenly over the scene.
        columns: Tiles per row.

    Returns:
        ``out_path`` as a :class:`~pathlib.Path`.

    Raises:
        UserError: for a scene without views or non-positive sizes.
    """
    return save_figure(contact_sheet_figure(scene, n_views, columns), out_path)


def draw_masks(view: View, out_path: str | Path) -> Path:
    """Draw a view's image (with boxes and fruit ids) beside its instance mask.

    Args:
        view: The view.
        out_path: Where the PNG goes; its folder is created.

    Returns:
        ``out_path`` as a :class:`~pathlib.Path`.

    Raises:
        UserError: when the view has no mask file.
    """
    mask = view.mask()
    if mask is None:
        raise UserError(f"{view.mask_path}: missing, so {view.scene.id} {view.name} has no mask to draw")
    figure = new_figure(2 * _TILE_INCHES * 1.4, _TILE_INCHES * 0.9)
    left, right = figure.add_subplot(1, 2, 1), figure.add_subplot(1, 2, 2)
    left.imshow(view.image(), interpolation="nearest")
    draw_boxes(left, view, labels=True)
    left.set_title(f"{view.scene.id} {view.name}\n{_pose_text(view)}", fontsize=7)
    # Ids are labels, not magnitudes: a qualitative colour map, and no-fruit left blank.
    shown = np.ma.masked_equal(mask, no_fruit_value(mask))
    from matplotlib import colormaps

    cmap = colormaps["tab20"].with_extremes(bad="black")
    right.imshow(shown % 20, cmap=cmap, vmin=0, vmax=19, interpolation="nearest")
    draw_boxes(right, view, labels=True)
    ids = np.unique(mask[fruit_pixels(mask)]).tolist()
    right.set_title(f"instance mask: {len(ids)} fruits", fontsize=7)
    for ax in (left, right):
        ax.set_axis_off()
    figure.tight_layout()
    return save_figure(figure, out_path)

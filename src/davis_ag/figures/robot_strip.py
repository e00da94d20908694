"""A robot's episode as a strip of frames: the arm at each step, seen from the alley, above what
its camera saw there (:func:`davis_ag.live.robot_pictures.robot_frames`)."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from davis_ag.figures.canvas import new_figure, save_figure

if TYPE_CHECKING:
    from davis_ag.live.robot_pictures import RobotFrame


def plot_robot_strip(frames: list[RobotFrame], captions: list[str], title: str, path: str | Path) -> Path:
    """Draw the frames side by side, the third-person image above the camera's, and save a PNG.

    Args:
        frames: One per step, in order.
        captions: One line under each step's pair (the view, the move's seconds, the target's OER).
        title: The strip's title.
        path: The PNG to write (atomically).

    Returns:
        The path written.
    """
    figure = new_figure(3.4 * len(frames), 4.4)
    axes = figure.subplots(2, len(frames), squeeze=False)
    for column, (frame, caption) in enumerate(zip(frames, captions)):
        top, bottom = axes[0][column], axes[1][column]
        top.imshow(frame.onlooker)
        bottom.imshow(frame.camera)
        top.set_title(caption, fontsize=8)
        for ax in (top, bottom):
            ax.set_xticks([])
            ax.set_yticks([])
    axes[0][0].set_ylabel("the robot", fontsize=8)
    axes[1][0].set_ylabel("its camera", fontsize=8)
    figure.suptitle(title, fontsize=9)
    figure.tight_layout()
    out = Path(path)
    save_figure(figure, out, dpi=100)
    return out

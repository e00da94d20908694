"""The geometry of TVMContinuous-v0's moves (:mod:`davis_ag.live.tvm_continuous`): where the
camera may be, which straight moves are refused, and the default scale of a full action, each
from the scene's grid as its scene.json records it."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from davis_ag.formats.layout import ANNOTATIONS, SCENE_METADATA
from davis_ag.generate.recorded_settings import RecordedSettings
from davis_ag.scene.specs import camera_altitudes

#: Pitch limits of a free camera, degrees above the horizon.
PITCH_RANGE = (-85.0, 45.0)
#: The grid's move names as (action component, sign) (:meth:`~davis_ag.live.tvm_continuous.TVMContinuousEnv.action_for`).
NAMED_MOVES: dict[str, tuple[int, float]] = {
    "left": (0, -1.0),
    "right": (0, 1.0),
    "backward": (1, -1.0),
    "forward": (1, 1.0),
    "down": (2, -1.0),
    "up": (2, 1.0),
    "rotate_ccw": (3, 1.0),
    "rotate_cw": (3, -1.0),
}


def scene_folders(source: str | os.PathLike[str], scenario: str, split: str, crop: str | None) -> list[Path]:
    """The scene folders an environment opens: ``source`` itself when it is a scene folder, else
    the dataset's scenes of the scenario and split (:func:`davis_ag.benchmark.splits.select_scenes`)."""
    path = Path(os.fspath(source))
    if (path / SCENE_METADATA).is_file() and (path / ANNOTATIONS).is_file():
        return [path]
    from davis_ag.benchmark.splits import as_dataset, select_scenes

    return [scene.path for scene in select_scenes(as_dataset(path), scenario, split, crop)]


def grid_bounds(settings: RecordedSettings) -> tuple[np.ndarray, np.ndarray]:
    """Lower and upper corners (x, y, z) of where the camera may be: the grid's area (its odd
    rows reach half a step further east) and altitude range."""
    ex, ey = settings.scenario.extent
    altitudes = camera_altitudes(settings.scenario, settings.crop)
    return (
        np.array([-ex / 2, -ey / 2, min(altitudes)]),
        np.array([ex / 2 + settings.scenario.step / 2, ey / 2, max(altitudes)]),
    )


def blocked_move(
    bounds: tuple[np.ndarray, np.ndarray], stems: np.ndarray, radius: float, start: np.ndarray, end: np.ndarray
) -> str:
    """Why a straight move from ``start`` to ``end`` is refused: ``bounds`` (it ends outside
    ``bounds``), ``collision`` (its path comes within ``radius`` of a stem, one (x, y) row each), or "" (allowed)."""
    lo, hi = bounds
    if np.any(end < lo - 1e-9) or np.any(end > hi + 1e-9):
        return "bounds"
    a, b = start[:2], end[:2]
    ab = b - a
    for stem in stems:
        along = float(np.clip(np.dot(stem - a, ab) / max(float(np.dot(ab, ab)), 1e-12), 0.0, 1.0))
        if np.hypot(*(a + along * ab - stem)) <= radius + 1e-9:
            return "collision"
    return ""


def grid_climb(settings: RecordedSettings) -> float:
    """Vertical move of a full action by default, m: half the grid's altitude span."""
    altitudes = camera_altitudes(settings.scenario, settings.crop)
    return (max(altitudes) - min(altitudes)) / 2


def grid_turn(settings: RecordedSettings) -> float:
    """Yaw and pitch change of a full action by default, degrees: the grid's turn between
    headings (30 for a grid of one heading)."""
    headings = settings.scenario.headings
    return 360.0 / headings if headings > 1 else 30.0


def named_action(name: str, size: int) -> np.ndarray:
    """A grid move's name as a full unit move along its axis (:data:`NAMED_MOVES`; ``done`` stands
    still) in an action of ``size`` components.

    Raises:
        UserError: for a name with no such move here.
    """
    from davis_ag.errors import UserError

    action = np.zeros(size, dtype=np.float32)
    if name == "done":
        return action
    axis, sign = NAMED_MOVES.get(name, (size, 0.0))
    if axis >= size:
        names = [n for n, (a, _) in NAMED_MOVES.items() if a < size] + ["done"]
        raise UserError(
            f"invalid action {name!r}: this environment takes {', '.join(names)} or {size} numbers in [-1, 1]"
        )
    action[axis] = sign
    return action

"""The viewpoint grid and its action graph: pure geometry, no renderer.

Conventions (also in the README):

- World frame: x east, y north, z up, metres; the ground is z = 0. The single plant stands at the
  origin; the multi-plant row runs along x, centred on the origin.
- Grid: the scenario's extent is tiled with square cells of ``step`` metres, centred on the
  origin; a camera position is a cell centre, so no camera stands on a stem. A camera closer
  than the crop's exclusion radius to any plant, measured in 3-D from the camera to the plant's
  centre (its stem at the crop's ``centre_height``: half the plant, or the middle of the vine's
  canopy), is not placed; so the exclusion zone
  shrinks with altitude, and ``up``/``down`` can point to "" too.
- Yaw: degrees counter-clockwise from +x; pitch: degrees above the horizon (negative looks down).
- Single plant: the camera always aims at ``(0, 0, aim_height)``; forward, backward, right and
  left move one step along +y, -y, +x and -x (world-fixed, since the camera's heading follows
  the plant anyway).
- Multi plant: 12 headings 30 degrees apart; forward moves one step along the grid axis nearest
  to the heading (no heading is exactly diagonal), backward the opposite, left 90 degrees
  counter-clockwise of forward, right clockwise. rotate_ccw adds 30 degrees, rotate_cw subtracts.
  The pitch aims at ``aim_height`` at ``mp_aim_distance`` metres ahead.
- up and down move between the scenario's altitude levels.
- Slip: each station (position and altitude) draws one Gaussian offset per x and y; every
  heading at that station shares it (turning in place does not slip). Pointers and exclusion use
  the nominal grid; poses record where the camera really was.
- Views are numbered altitude first, then y, then x, then heading; view 0 is ``0001.jpeg``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from davis_ag.scene.specs import SLIP_SIGMA, CropSpec, ScenarioSpec

#: Horizontal distance ahead at which a multi-plant camera's optical axis meets aim_height, m.
MP_AIM_DISTANCE = 1.5

# Unit grid steps of the four grid axes, counter-clockwise from +x.
_AXES = ((1, 0), (0, 1), (-1, 0), (0, -1))
_SP_MOVES = {"forward": (0, 1), "backward": (0, -1), "right": (1, 0), "left": (-1, 0)}


@dataclass(frozen=True)
class Viewpoint:
    """One camera pose of the grid.

    Attributes:
        index: Position in the grid's view list; the image is ``f"{index + 1:04d}.jpeg"``.
        ix, iy: Grid column and row.
        level: Altitude level, 0 = lowest used by the scenario.
        heading: Heading index (always 0 in the single-plant scenario).
        nominal: Nominal camera position (x, y, z) on the grid, m.
        position: Camera position after slip (x, y, z), m.
        yaw: Degrees counter-clockwise from +x.
        pitch: Degrees above the horizon.
    """

    index: int
    ix: int
    iy: int
    level: int
    heading: int
    nominal: tuple[float, float, float]
    position: tuple[float, float, float]
    yaw: float
    pitch: float

    @property
    def image_name(self) -> str:
        """The published image file name, numbered from 1."""
        return f"{self.index + 1:04d}.jpeg"

    @property
    def pose(self) -> list[float]:
        """The published pose ``[x, y, z, yaw, pitch]``."""
        return [*self.position, self.yaw, self.pitch]

    def look_at(self, distance: float = 1.0) -> tuple[float, float, float]:
        """A point ``distance`` metres along the optical axis."""
        yaw, pitch = math.radians(self.yaw), math.radians(self.pitch)
        x, y, z = self.position
        return (
            x + distance * math.cos(pitch) * math.cos(yaw),
            y + distance * math.cos(pitch) * math.sin(yaw),
            z + distance * math.sin(pitch),
        )


@dataclass(frozen=True)
class ViewGrid:
    """Every viewpoint of a scene and where each action leads from it.

    Attributes:
        viewpoints: The views, in image order.
        actions: Pointer keys, in the order of ``next_view``'s columns.
        next_view: ``next_view[i, a]`` is the index reached from view i by action a, or -1.
    """

    viewpoints: tuple[Viewpoint, ...]
    actions: tuple[str, ...]
    next_view: np.ndarray

    def pointer(self, index: int, action: str) -> int | None:
        """The view reached from view ``index`` by ``action``, or ``None`` where the move is invalid."""
        target = int(self.next_view[index, self.actions.index(action)])
        return None if target < 0 else target

    def pointers(self, index: int) -> dict[str, str]:
        """The published pointer dictionary of a view: action to image name, "" where invalid."""
        return {
            action: "" if (t := self.pointer(index, action)) is None else self.viewpoints[t].image_name
            for action in self.actions
        }


def grid_axis(extent: float, step: float) -> np.ndarray:
    """Cell-centre coordinates of one grid axis, centred on 0."""
    count = int(round(extent / step))
    return (np.arange(count) - (count - 1) / 2) * step


def _aim(position: tuple[float, float, float], target: tuple[float, float, float]) -> tuple[float, float]:
    dx, dy, dz = (t - p for t, p in zip(target, position))
    return math.degrees(math.atan2(dy, dx)), math.degrees(math.atan2(dz, math.hypot(dx, dy)))


def build_view_grid(
    scenario: ScenarioSpec,
    crop: CropSpec,
    plant_centres: list[tuple[float, float, float]],
    aim_height: float,
    rng: np.random.Generator,
) -> ViewGrid:
    """Lay out a scene's viewpoints and action graph.

    Args:
        scenario: Grid extent, step, altitude levels, headings and actions.
        crop: Altitudes and exclusion radius.
        plant_centres: (x, y, z) of every plant's centre; cameras keep ``crop.exclusion_radius``
            away from each.
        aim_height: Height the camera aims at, m (half the plant height is a good choice).
        rng: Draws the slip; the only source of randomness.

    Returns:
        The :class:`ViewGrid`.
    """
    xs = grid_axis(scenario.extent[0], scenario.step)
    ys = grid_axis(scenario.extent[1], scenario.step)
    altitudes = [crop.altitudes[level] for level in scenario.altitude_levels]
    centres = np.asarray(plant_centres, dtype=float).reshape(-1, 3)

    def allowed(x: float, y: float, z: float) -> bool:
        gaps = np.linalg.norm(centres - np.array([x, y, z]), axis=1)
        return bool(np.all(gaps >= crop.exclusion_radius))

    viewpoints: list[Viewpoint] = []
    index_of: dict[tuple[int, int, int, int], int] = {}
    for level, z in enumerate(altitudes):
        for iy in range(len(ys)):
            for ix in range(len(xs)):
                if not allowed(xs[ix], ys[iy], z):
                    continue
                slip_x, slip_y = rng.normal(0.0, SLIP_SIGMA, size=2)
                nominal = (float(xs[ix]), float(ys[iy]), float(z))
                position = (float(xs[ix] + slip_x), float(ys[iy] + slip_y), float(z))
                for heading in range(scenario.headings):
                    if scenario.headings == 1:
                        yaw, pitch = _aim(position, (0.0, 0.0, aim_height))
                    else:
                        yaw = heading * 360.0 / scenario.headings
                        pitch = math.degrees(math.atan2(aim_height - z, MP_AIM_DISTANCE))
                    key = (ix, iy, level, heading)
                    index_of[key] = len(viewpoints)
                    viewpoints.append(
                        Viewpoint(len(viewpoints), ix, iy, level, heading, nominal, position,
                                  round(yaw, 4), round(pitch, 4))
                    )

    next_view = np.full((len(viewpoints), len(scenario.actions)), -1, dtype=np.int32)
    for view in viewpoints:
        for column, action in enumerate(scenario.actions):
            key = _move(view, action, scenario)
            next_view[view.index, column] = index_of.get(key, -1)
    return ViewGrid(tuple(viewpoints), scenario.actions, next_view)


def _move(view: Viewpoint, action: str, scenario: ScenarioSpec) -> tuple[int, int, int, int]:
    """Grid key an action leads to; it may name no viewpoint (outside the grid or excluded)."""
    ix, iy, level, heading = view.ix, view.iy, view.level, view.heading
    if action == "up":
        return ix, iy, level + 1, heading
    if action == "down":
        return ix, iy, level - 1, heading
    if action in ("rotate_ccw", "rotate_cw"):
        turn = 1 if action == "rotate_ccw" else -1
        return ix, iy, level, (heading + turn) % scenario.headings
    if scenario.headings == 1:
        dx, dy = _SP_MOVES[action]
    else:
        # Headings are multiples of 30 degrees, so the nearest axis is never a tie.
        forward = round(heading * 360.0 / scenario.headings / 90.0) % 4
        turn = {"forward": 0, "left": 1, "backward": 2, "right": 3}[action]
        dx, dy = _AXES[(forward + turn) % 4]
    return ix + dx, iy + dy, level, heading

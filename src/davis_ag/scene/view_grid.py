"""The viewpoint grid and its action graph: pure geometry, no renderer.

Conventions (also in the README, "Images per scene"):

- World frame: x east, y north, z up, metres; the ground is z = 0. The single plant stands at the
  origin; the multi-plant row runs along x, centred on the origin.
- Grid: a staggered lattice, as the original dataset's Fig. 2 shows it. Rows are ``step`` apart
  along y; within a row positions are ``step`` apart along x; rows are numbered from the -y edge
  and every odd row is shifted half a step along +x. The even rows span the scenario's extent
  exactly (``floor(extent / step) + 1`` positions per axis, centred on the origin), the odd rows
  reach half a step further east. A position whose horizontal (2-D) distance to any plant's
  stem is at most the crop's exclusion radius is not placed, so the same positions exist at
  every altitude. With the crop's grid (``scenario_spec(name, crop)``) this gives Table 3's
  images per scene (docs/dataset-format.md names the conventions tried).
- Yaw: degrees counter-clockwise from +x; pitch: degrees above the horizon (negative looks down).
- Moves keep the lattice indices simple: right/left go to the next position in the same row
  (+x / -x, exactly one step); forward/backward go to the next row (+y / -y) at the same column
  index, which on the staggered lattice also moves half a step sideways (+x from an even row,
  -x from an odd row), a zigzag that is back in line every two rows. Every move is therefore
  undone by its opposite.
- Single plant: the camera always aims at ``(0, 0, aim_height)``; forward, backward, right and
  left are world-fixed as above (+y, -y, +x, -x), since the camera's heading follows the plant.
- Row (ours): the lattice of MP over the crop's row (``RowSpec``): rows of positions along x in
  the two alleys, the lines within ``exclusion_band`` of the row's centre line left out, and no
  move crosses the row; headings, moves and pitch as MP's, the pitch aiming at ``aim_height``
  at the standoff ahead.
- Multi plant: 12 headings 30 degrees apart; forward moves along the lattice axis (row or
  column) nearest the heading (no heading is exactly diagonal), backward the opposite, left 90
  degrees counter-clockwise of forward, right clockwise; a move along y zigzags as above.
  rotate_ccw adds 30 degrees, rotate_cw subtracts. The pitch aims at ``aim_height`` at
  ``mp_aim_distance`` metres ahead.
- up and down move between the scenario's altitude levels; they are invalid only at the top and
  bottom level.
- Slip: each station (position and altitude) draws one Gaussian offset per x and y; every
  heading at that station shares it (turning in place does not slip). Pointers and exclusion use
  the nominal grid; poses record where the camera really was.
- Views are numbered altitude first, then y, then x, then heading; view 0 is ``0001.jpeg``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from davis_ag.scene.specs import SLIP_SIGMA, CropSpec, ScenarioSpec, camera_altitudes, plant_centres

#: Horizontal distance ahead at which a multi-plant camera's optical axis meets aim_height, m
#: (a row's camera: its standoff).
MP_AIM_DISTANCE = 1.5

# Unit grid steps of the four grid axes, counter-clockwise from +x.
_AXES = ((1, 0), (0, 1), (-1, 0), (0, -1))
_SP_MOVES = {"forward": (0, 1), "backward": (0, -1), "right": (1, 0), "left": (-1, 0)}


@dataclass(frozen=True)
class Viewpoint:
    """One camera pose of the grid.

    Attributes:
        index: Position in the grid's view list; the image is numbered ``index + 1``
            (:func:`davis_ag.formats.layout.view_name` names it).
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
    def number(self) -> int:
        """The view's published number, from 1 (its image name is :func:`davis_ag.formats.layout.view_name`'s)."""
        return self.index + 1

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


def lattice_size(extent: float, step: float) -> int:
    """Positions along one lattice axis: the first and last are at most ``extent`` apart.

    Args:
        extent: Grid size along the axis, m.
        step: Distance between neighbouring positions, m.

    Returns:
        ``floor(extent / step) + 1`` (a small tolerance absorbs floating-point error).
    """
    return math.floor(extent / step + 1e-9) + 1


def lattice_point(ix: int, iy: int, shape: tuple[int, int], step: float) -> tuple[float, float]:
    """Nominal (x, y) of lattice column ``ix`` in row ``iy``; odd rows sit half a step east.

    Args:
        ix: Column index within the row.
        iy: Row index, 0 at the -y edge.
        shape: Positions per row and number of rows, ``(nx, ny)``.
        step: Distance between neighbouring positions, m.

    Returns:
        The position, m; rows are centred on the origin before the odd rows' shift.
    """
    nx, ny = shape
    shift = step / 2 if iy % 2 else 0.0
    return (ix - (nx - 1) / 2) * step + shift, (iy - (ny - 1) / 2) * step


def lattice_shape(scenario: ScenarioSpec) -> tuple[int, int]:
    """Positions per row and number of rows of a scenario's lattice."""
    return lattice_size(scenario.extent[0], scenario.step), lattice_size(scenario.extent[1], scenario.step)


def excluded(x: float, y: float, stems: np.ndarray, radius: float) -> bool:
    """Whether a position is within ``radius`` (2-D, inclusive) of any plant's stem.

    Args:
        x, y: The position, m.
        stems: ``(n, 2)`` or ``(n, 3)`` plant stems or centres; only x and y count.
        radius: The crop's exclusion radius, m.

    Returns:
        True where no camera may stand. The 1e-9 tolerance keeps a lattice position at exactly
        the radius (0, 0.75 m for strawberry) out, as the original's Fig. 2 has it.
    """
    gaps = np.hypot(stems[:, 0] - x, stems[:, 1] - y)
    return bool(np.any(gaps <= radius + 1e-9))


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
        plant_centres: (x, y, z) of every plant's centre; cameras keep more than
            ``crop.exclusion_radius`` away from each, measured horizontally.
        aim_height: Height the camera aims at, m (half the plant height is a good choice).
        rng: Draws the slip; the only source of randomness.

    Returns:
        The :class:`ViewGrid`.
    """
    shape = lattice_shape(scenario)
    altitudes = camera_altitudes(scenario, crop)
    centres = np.asarray(plant_centres, dtype=float).reshape(-1, 3)
    row = crop.row if scenario.name == "row" else None
    aim_distance = MP_AIM_DISTANCE if row is None else row.standoff

    viewpoints: list[Viewpoint] = []
    index_of: dict[tuple[int, int, int, int], int] = {}
    for level, z in enumerate(altitudes):
        for iy in range(shape[1]):
            for ix in range(shape[0]):
                x, y = lattice_point(ix, iy, shape, scenario.step)
                if row is not None:
                    if abs(y) <= row.exclusion_band + 1e-9:  # the row itself: no camera inside it
                        continue
                elif excluded(x, y, centres, crop.exclusion_radius):
                    continue
                slip_x, slip_y = rng.normal(0.0, SLIP_SIGMA, size=2)
                nominal = (float(x), float(y), float(z))
                position = (float(x + slip_x), float(y + slip_y), float(z))
                for heading in range(scenario.headings):
                    if scenario.headings == 1:
                        yaw, pitch = _aim(position, (0.0, 0.0, aim_height))
                    else:
                        yaw = heading * 360.0 / scenario.headings
                        pitch = math.degrees(math.atan2(aim_height - z, aim_distance))
                    key = (ix, iy, level, heading)
                    index_of[key] = len(viewpoints)
                    viewpoints.append(
                        Viewpoint(
                            len(viewpoints), ix, iy, level, heading, nominal, position, round(yaw, 4), round(pitch, 4)
                        )
                    )

    next_view = np.full((len(viewpoints), len(scenario.actions)), -1, dtype=np.int32)
    for view in viewpoints:
        for column, action in enumerate(scenario.actions):
            target = index_of.get(_move(view, action, scenario), -1)
            # A row is a wall: on a grid coarser than its band a move could jump it.
            if target >= 0 and row is not None and (viewpoints[target].nominal[1] > 0) != (view.nominal[1] > 0):
                target = -1
            next_view[view.index, column] = target
    return ViewGrid(tuple(viewpoints), scenario.actions, next_view)


def views_per_scene(scenario: ScenarioSpec, crop: CropSpec) -> int:
    """How many views a scene of this scenario and crop has (the slip changes no count).

    Args:
        scenario: The grid (use ``scenario_spec(name, crop)`` for the crop's own).
        crop: Altitudes and exclusion radius.

    Returns:
        The number of views.
    """
    grid = build_view_grid(scenario, crop, plant_centres(scenario, crop), crop.centre_height, np.random.default_rng(0))
    return len(grid.viewpoints)


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


def view_facing(scenario: ScenarioSpec, crop: CropSpec, level: int, yaw: float) -> int:
    """The number of a view to show: at altitude ``level``, looking along ``yaw`` (to 10 degrees)
    towards the plants, the nearest to their middle (x = 0) and to the plants among those.

    Args:
        scenario, crop: The grid.
        level: Altitude level, 0 the lowest the scenario uses.
        yaw: Degrees counter-clockwise from +x (90: looking north, from south of the plants).

    Returns:
        The view's published number (from 1); the slip of dataset seed 0 decides near-ties.
    """
    grid = build_view_grid(scenario, crop, plant_centres(scenario, crop), crop.centre_height, np.random.default_rng(0))

    direction = (math.cos(math.radians(yaw)), math.sin(math.radians(yaw)))

    def score(view: Viewpoint) -> tuple[bool, float, float, float]:
        off = abs((view.yaw - yaw + 180.0) % 360.0 - 180.0)
        away = direction[0] * view.nominal[0] + direction[1] * view.nominal[1] > 0  # its back to the plants
        return away, round(off / 10.0), round(abs(view.nominal[0]), 3), abs(view.nominal[1])

    return min((v for v in grid.viewpoints if v.level == level), key=score).number

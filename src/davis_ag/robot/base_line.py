"""Where a robot's base drives in a scene: a line along x, on the side of the view it serves.

- ``row``: the alley's centre line, ``y = +-row_spacing / 2`` (the crop's ``RowSpec``): the
  base drives between two rows, as a trolley on heating pipes or an orchard platform does.
- ``sp`` and ``mp``: a line :data:`SP_MP_STANDOFF` metres from the plants' line (``y = 0``) on
  either side: a single plant or a short row seen from a base driving past it.

A view is served from the line on its own side (``y >= 0`` north, else south; a view at exactly
``y = 0`` counts as south), and the arm's base faces the plants: its +x points across the line,
towards ``y = 0``. The base slides along x within the scene's views' x range, plus
:data:`RAIL_MARGIN` at each end.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from davis_ag.scene.specs import crop_spec

#: Distance from the plants' line to the base line in ``sp`` and ``mp`` scenes, m: outside every
#: crop's exclusion radius (0.75-1.0 m), so the base never stands inside a plant.
SP_MP_STANDOFF = 1.0
#: How far the base may drive past the outermost views along x, m.
RAIL_MARGIN = 1.0


@dataclass(frozen=True)
class BaseLine:
    """One side's base line.

    Attributes:
        side: ``+1`` (north, ``y > 0``) or ``-1`` (south).
        y: The line's y, m.
        facing: Heading of the arm base's +x, radians counter-clockwise from +x (towards the plants).
        x_range: The base's travel along x, m.
    """

    side: int
    y: float
    facing: float
    x_range: tuple[float, float]


def line_distance(scenario: str, crop: str | None) -> float:
    """The base line's distance from the plants' line in a scene of this scenario and crop, m."""
    if scenario == "row" and crop is not None:
        row = crop_spec(crop).row
        if row is not None:
            return row.row_spacing / 2
    return SP_MP_STANDOFF


def side_of(y: float) -> int:
    """The side a view at ``y`` is served from: ``+1`` north of the plants' line, else ``-1``."""
    return 1 if y > 0 else -1


def base_lines(scenario: str, crop: str | None, view_x: tuple[float, float]) -> dict[int, BaseLine]:
    """Both sides' base lines of a scene.

    Args:
        scenario: ``sp``, ``mp`` or ``row``.
        crop: The scene's crop (its row spacing sets a row's alley line).
        view_x: The smallest and largest x of the scene's views, m.

    Returns:
        ``{+1: north line, -1: south line}``.
    """
    distance = line_distance(scenario, crop)
    x_range = (view_x[0] - RAIL_MARGIN, view_x[1] + RAIL_MARGIN)
    return {side: BaseLine(side, side * distance, -side * math.pi / 2, x_range) for side in (1, -1)}

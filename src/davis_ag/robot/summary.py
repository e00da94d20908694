"""A robot's reach in numbers: by camera height on an empty alley, and per group and height of a dataset.

:func:`reach_by_height` is what ``davis-ag robots`` prints: the share of camera poses a robot
reaches at each height, with nothing in the way but the ground and its own platform: cameras
:data:`LATERAL` metres out from the base line towards the plants, facing them at headings
:data:`HEADINGS` degrees off square and pitches :data:`PITCHES`, the base free along its line.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from davis_ag.robot.base_line import BaseLine
from davis_ag.robot.definitions import RobotDefinition
from davis_ag.robot.ik import random_seeds, reach_pose
from davis_ag.robot.model import build_robot, view_placement

if TYPE_CHECKING:
    from davis_ag.data.reader import Scene
    from davis_ag.robot.reach import SceneReach

#: Camera heights ``davis-ag robots`` tries, m (the crops' rows put cameras at 0.25-2.7 m).
HEIGHTS = (0.3, 0.6, 0.9, 1.2, 1.5, 1.8, 2.1, 2.4, 2.7, 3.0)
#: Distances of the cameras from the base line, m; headings off square, degrees; pitches, degrees.
LATERAL = (0.5, 1.0)
HEADINGS = (-45.0, 0.0, 45.0)
PITCHES = (-30.0, 0.0, 30.0)


def reach_by_height(definition: RobotDefinition, heights: tuple[float, ...] = HEIGHTS) -> dict[float, float]:
    """The share of test poses the robot reaches at each camera height (see the module docstring).

    Args:
        definition: The robot.
        heights: Camera heights, m.

    Returns:
        ``{height: share}``.
    """
    robot = build_robot(definition, BaseLine(1, 0.0, -np.pi / 2, (-2.0, 2.0)))
    rng = np.random.default_rng(0)  # a fixed table: the same every time it is printed
    shares = {}
    for z in heights:
        reached = []
        for lateral in LATERAL:
            for heading in HEADINGS:
                for pitch in PITCHES:
                    pose = [0.0, -lateral, z, -90.0 + heading, pitch]
                    seeds = random_seeds(robot, 0.0, 8, rng)
                    reached.append(reach_pose(robot, view_placement(pose), seeds).ok)
        shares[z] = float(np.mean(reached))
    return shares


@dataclass(frozen=True)
class HeightReach:
    """Views and reachable views of one group at one camera height.

    Attributes:
        group: The dataset group (``Row-AppleWall``).
        height: The camera height, m (the views' recorded z, to the centimetre).
        views: Views at that height.
        reached: How many the robot reaches.
    """

    group: str
    height: float
    views: int
    reached: int

    @property
    def share(self) -> float:
        return self.reached / self.views if self.views else 0.0


def reach_table(scenes: list[Scene], reaches: list[SceneReach]) -> list[HeightReach]:
    """Per group and camera height, the views a robot reaches (sorted by group, then height)."""
    counts: dict[tuple[str, float], list[int]] = {}
    from davis_ag.robot.reach import view_poses

    for scene, reach in zip(scenes, reaches):
        group = scene.id.split("/")[0]
        for pose, ok in zip(view_poses(scene), reach.reachable):
            tally = counts.setdefault((group, round(float(pose[2]), 2)), [0, 0])
            tally[0] += 1
            tally[1] += int(ok)
    return [HeightReach(group, height, views, reached) for (group, height), (views, reached) in sorted(counts.items())]

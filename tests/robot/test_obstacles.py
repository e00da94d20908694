"""Obstacles: a trunk in the way refuses a pose; leaves are brushed (never obstacles); the ground is one."""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np

from davis_ag.robot.base_line import base_lines
from davis_ag.robot.definitions import load_robot
from davis_ag.robot.ik import random_seeds, reach_pose
from davis_ag.robot.model import build_robot, view_placement
from davis_ag.robot.obstacles import trunk_points
from davis_ag.scene.organs import LEAF, STRUCTURE, TRUNK

#: A camera 0.6 m out from the north base line at 0.9 m, facing the row: a UR5 on its trolley reaches it.
POSE = [0.0, 1.15, 0.9, -90.0, 0.0]


def _scene_seeing(classes: np.ndarray) -> SimpleNamespace:
    """A one-view scene looking south at a wall 0.3 m ahead of :data:`POSE` whose pixels have ``classes``."""
    height, width = classes.shape
    camera = SimpleNamespace(fx=width / 5, fy=width / 5, cx=width / 2, cy=height / 2)  # 0.75 x 0.4 m at 0.3 m
    metadata = SimpleNamespace(image_size=lambda: (width, height), camera=camera)
    view = SimpleNamespace(
        name="0001.jpeg", pose=tuple(POSE), depth=lambda: np.full(classes.shape, 0.3), classes=lambda: classes
    )
    return SimpleNamespace(metadata=metadata, path="test", __iter__=None, views=[view])


class _Scene(SimpleNamespace):
    def __iter__(self):
        return iter(self.views)


def _wall(organ: int) -> _Scene:
    scene = _scene_seeing(np.full((40, 80), organ, dtype=np.uint8))
    return _Scene(**vars(scene))


def _reached(obstacles: np.ndarray | None) -> tuple[bool, str | None]:
    robot = build_robot(load_robot("ur5-trolley"), base_lines("row", "apple-wall", (-2.0, 2.0))[1], obstacles)
    # the camera 0.4 m south, through the wall: the wall stands between the camera and the base
    target = view_placement([POSE[0], POSE[1] - 0.4, *POSE[2:]])
    solution = reach_pose(robot, target, random_seeds(robot, 0.0, 12, np.random.default_rng(1)))
    return solution.ok, solution.blocked


def test_a_trunk_in_the_way_is_refused_and_leaves_are_brushed() -> None:
    trunks = trunk_points(_wall(TRUNK))
    assert len(trunks) > 50
    assert np.allclose(trunks[:, 1], POSE[1] - 0.3, atol=0.03)  # the wall, unprojected
    assert _reached(None) == (True, None)
    assert _reached(trunks) == (False, "obstacle")
    leaves = trunk_points(_wall(LEAF))
    assert len(leaves) == 0  # leaves are never obstacles
    assert _reached(leaves) == (True, None)


def test_a_trellis_in_the_way_is_an_obstacle_as_a_trunk_is() -> None:
    structure, trunks = trunk_points(_wall(STRUCTURE)), trunk_points(_wall(TRUNK))
    assert np.array_equal(structure, trunks)  # the same wall of posts and wires, the same points
    assert _reached(structure) == (False, "obstacle")


def test_the_ground_refuses_a_camera_below_it() -> None:
    robot = build_robot(load_robot("ur5-trolley"), base_lines("row", "apple-wall", (-2.0, 2.0))[1])
    low = view_placement([0.0, 1.15, 0.02, -90.0, -60.0])  # 2 cm up, looking down: the wrist meets the soil
    solution = reach_pose(robot, low, random_seeds(robot, 0.0, 12, np.random.default_rng(2)))
    assert not solution.ok

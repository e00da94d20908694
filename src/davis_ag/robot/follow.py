"""A robot that follows a camera moving anywhere (TVMContinuous-v0 with ``robot=``): each new pose
solved from the configuration the arm is in, so a move is what the arm would do.

The robot and its collision pairs are the grid's (:mod:`davis_ag.robot.model`), built once per
scene on both base lines with the scene's trunks as obstacles (:mod:`davis_ag.robot.obstacles`).
A start pose is solved from the robot's home beside it, then from random restarts drawn from the
caller's generator; a move only from the current configuration (no restarts: a new arm each time
would jump). A pose on the other side of the plants' line than the arm's base is out of reach: the
base would have to cross the row. Each move costs :func:`davis_ag.robot.ik.move_seconds`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from davis_ag.robot.base_line import side_of
from davis_ag.robot.definitions import RobotDefinition
from davis_ag.robot.ik import move_seconds, random_seeds, reach_pose
from davis_ag.robot.model import RobotModel, build_robot, camera_in_tool, view_placement
from davis_ag.robot.obstacles import trunk_points
from davis_ag.robot.reach import RESTARTS, home_configuration, scene_lines, view_poses

if TYPE_CHECKING:
    from davis_ag.data.reader import Scene


@dataclass(frozen=True)
class ArmPose:
    """Where the arm is: the base line's side and its configuration."""

    side: int
    q: np.ndarray


@dataclass
class ArmFollower:
    """One scene's robot on both base lines (see the module docstring).

    Attributes:
        definition: The robot.
        robots: Its model on each side's line (``+1`` north, ``-1`` south).
        camera_in_tool: The camera's 4x4 placement in the tool frame (nested lists).
    """

    definition: RobotDefinition
    robots: dict[int, RobotModel]
    camera_in_tool: list[list[float]]

    @classmethod
    def for_scene(cls, scene: Scene, definition: RobotDefinition) -> ArmFollower:
        """Build the robot beside a generated scene (its views' poses set the rails' travel)."""
        lines, _ = scene_lines(scene, view_poses(scene))
        obstacles = trunk_points(scene)
        robots = {side: build_robot(definition, lines[side], obstacles) for side in (-1, 1)}
        return cls(definition, robots, camera_in_tool(definition).homogeneous.tolist())

    def start(self, pose: list[float], rng: np.random.Generator) -> tuple[ArmPose | None, str]:
        """Solve a start pose ``[x, y, z, yaw, pitch]`` from home, then random restarts.

        Returns:
            The arm's pose, or None and why (``out of reach``, ``self``, ``ground``, ``platform``, ``obstacle``).
        """
        side = side_of(float(pose[1]))
        robot = self.robots[side]
        seeds = [home_configuration(robot, float(pose[0]), float(pose[2]))]
        seeds += random_seeds(robot, float(pose[0]), RESTARTS, rng)
        solution = reach_pose(robot, view_placement(pose), seeds)
        if solution.ok:
            return ArmPose(side, np.asarray(solution.q)), ""
        return None, solution.blocked or "out of reach"

    def follow(self, arm: ArmPose, pose: list[float]) -> tuple[ArmPose | None, str]:
        """Solve a new pose from the arm's configuration.

        Returns:
            The new arm pose, or None and why (``other side`` where the pose lies across the row).
        """
        if side_of(float(pose[1])) != arm.side:
            return None, "other side"
        solution = reach_pose(self.robots[arm.side], view_placement(pose), [arm.q])
        if solution.ok:
            return ArmPose(arm.side, np.asarray(solution.q)), ""
        return None, solution.blocked or "out of reach"

    def seconds(self, before: ArmPose, after: ArmPose) -> float:
        """Seconds of the move between two configurations of one side."""
        return move_seconds(self.robots[before.side], before.q, after.q)

    def info(self, arm: ArmPose, seconds: float, total: float) -> dict[str, Any]:
        """``info["robot"]``, as TVM-v0's (:mod:`davis_ag.benchmark.robot_moves`)."""
        robot = self.robots[arm.side]
        return self.definition.step_info(self.camera_in_tool, robot.mount(arm.q), robot.urdf_q(arm.q), seconds, total)

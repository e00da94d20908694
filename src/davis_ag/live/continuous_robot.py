"""TVMContinuous-v0 with a robot: the camera rides on an arm that follows it (:mod:`davis_ag.robot.follow`).

A start pose counts only where the robot reaches it; a move the arm cannot make from where it is
(out of reach, a collision, across the row) is refused as a move out of bounds is, and each move
made costs the arm's seconds. With ``budget_s`` a move that would overrun the seconds is not made
and ends the episode. Every step's ``info["robot"]`` is TVM-v0's (:mod:`davis_ag.benchmark.robot_moves`).
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.errors import UserError


class RobotOnPoses:
    """One robot following the camera of an environment's scenes, and the episode's seconds."""

    def __init__(self, robot: str, folders: list[Path], budget_s: float | None = None) -> None:
        """Args:
        robot: A robot name (``davis-ag robots``) or YAML file.
        folders: The environment's scene folders, in its order.
        budget_s: End an episode when the robot's seconds are spent (None: never).

        Raises:
            UserError: for an unknown robot or a budget that is not a positive number.
        """
        from davis_ag.data.reader import open_dataset
        from davis_ag.robot.definitions import load_robot
        from davis_ag.robot.follow import ArmFollower

        if budget_s is not None and not budget_s > 0:
            raise UserError(f"budget_s={budget_s}: give a positive number of seconds")
        definition = load_robot(robot)
        self.followers = [ArmFollower.for_scene(open_dataset(folder).scenes[0], definition) for folder in folders]
        self.budget_s = budget_s
        self.arm: Any = None
        self._planned: tuple[Any, float] | None = None
        self._budget_hit = False
        self.seconds = self.total = 0.0
        self.over_budget = False

    @classmethod
    def made(cls, robot: str | None, folders: list[Path], budget_s: float | None) -> RobotOnPoses | None:
        """The robot, or None without one.

        Raises:
            UserError: for ``budget_s`` without a robot, and as the constructor does.
        """
        if robot is None:
            if budget_s is not None:
                raise UserError(f"budget_s={budget_s} needs a robot")
            return None
        return cls(robot, folders, budget_s)

    def start(self, scene: int, pose: list[float], rng: np.random.Generator) -> bool:
        """Put the arm at a start pose; False where it cannot be."""
        arm, _ = self.followers[scene].start(pose, rng)
        if arm is None:
            return False
        self.arm, self.seconds, self.total, self.over_budget = arm, 0.0, 0.0, False
        return True

    def plan(self, scene: int, pose: list[float]) -> str:
        """Solve the arm for ``pose`` from where it is, without moving it: "" when it can go (the
        move is kept for :meth:`settle`), else why not (``robot: ...`` or ``budget``)."""
        follower = self.followers[scene]
        self._planned, self._budget_hit = None, False
        arm, why = follower.follow(self.arm, pose)
        if arm is None:
            return f"robot: {why}"
        seconds = follower.seconds(self.arm, arm)
        self._budget_hit = self.budget_s is not None and self.total + seconds > self.budget_s
        if self._budget_hit:
            return "budget"
        self._planned = (arm, seconds)
        return ""

    def settle(self, moved: bool) -> None:
        """End a step: the planned move is made when the camera moved, else the arm stays and the
        step costs no seconds (a move refused for the budget ends the episode: :attr:`over_budget`)."""
        self.over_budget = self.over_budget or (not moved and self._budget_hit)
        if moved and self._planned is not None:
            self.arm, self.seconds = self._planned
            self.total += self.seconds
        else:
            self.seconds = 0.0
        self._planned = None

    def info(self, scene: int) -> dict[str, Any]:
        """``info["robot"]`` now."""
        return self.followers[scene].info(self.arm, self.seconds, self.total)

    def record(self) -> dict[str, str]:
        """What a results file records of the robot."""
        return self.followers[0].definition.results_record()

"""Inverse kinematics of the camera frame, and the seconds a move between two configurations takes.

The solver is pinocchio's own closed-loop IK example in damped least-squares form: the error is
``log6`` of the camera's placement against the target (in the camera's frame), the Jacobian the
camera frame's, premultiplied by ``Jlog6``; each step ``v = -J^T (J J^T + damping I)^-1 e`` is
integrated with ``pinocchio.integrate`` and clipped to the joint limits. A pose is reached when
the error falls under :data:`POSITION_TOLERANCE` and :data:`ROTATION_TOLERANCE`; a solution
then counts only within the limits and clear of every collision pair (:meth:`RobotModel.collision`).
"""

from __future__ import annotations

from dataclasses import dataclass
from math import sqrt

import numpy as np

from davis_ag.robot.model import LIFT, RAIL, RobotModel, import_pinocchio

#: A camera pose is reached within 1 mm and 2 mrad (0.11 degrees).
POSITION_TOLERANCE = 1e-3
ROTATION_TOLERANCE = 2e-3
#: Iterations of one attempt at most, and the damping of the least-squares step. An attempt also
#: stops when its error has not fallen by :data:`STALL_GAIN` (relative) in :data:`STALL_ITERATIONS`:
#: a pose out of reach costs a few dozen iterations, one near a joint limit may take hundreds.
MAX_ITERATIONS = 600
DAMPING = 1e-6
STALL_ITERATIONS = 30
STALL_GAIN = 0.02


@dataclass(frozen=True)
class Solution:
    """One IK attempt's outcome.

    Attributes:
        q: The configuration (``None`` when the pose was not reached).
        blocked: Why a reached pose was refused (``self``, ``ground``, ``platform``, ``obstacle``),
            ``None`` when it is clear (or was not reached).
    """

    q: np.ndarray | None
    blocked: str | None = None

    @property
    def ok(self) -> bool:
        return self.q is not None and self.blocked is None


def solve_pose(robot: RobotModel, target, seed: np.ndarray) -> np.ndarray | None:
    """Solve for a camera placement from one seed configuration.

    Args:
        robot: The robot on its line.
        target: The camera's world placement (``pinocchio.SE3``).
        seed: Where the iteration starts.

    Returns:
        A configuration within limits that puts the camera at ``target``, or ``None``.
    """
    pin, _ = import_pinocchio()
    model, data, frame = robot.model, robot.data, robot.camera_frame
    lower, upper = robot.lower, robot.upper
    q = np.clip(seed, lower, upper)
    eye = np.eye(6) * DAMPING
    best, best_at = np.inf, 0
    still = upper - lower < 1e-9
    # Norms as sqrt(x . x) and clips as min(max()): what np.linalg.norm and np.clip compute, bit
    # for bit, without their Python wrappers, which cost a third of an attempt (cProfile).
    for iteration in range(MAX_ITERATIONS):
        pin.framesForwardKinematics(model, data, q)
        current_from_target = data.oMf[frame].actInv(target)  # type: ignore[attr-defined]
        error = pin.log(current_from_target).vector
        position, rotation = error[:3], error[3:]
        if sqrt(position.dot(position)) < POSITION_TOLERANCE and sqrt(rotation.dot(rotation)) < ROTATION_TOLERANCE:
            return q
        size = sqrt(error.dot(error))
        if size < best * (1 - STALL_GAIN):
            best, best_at = size, iteration
        elif iteration - best_at > STALL_ITERATIONS:
            return None
        jacobian = pin.computeFrameJacobian(model, data, q, frame)
        jacobian = -pin.Jlog6(current_from_target.inverse()) @ jacobian
        jacobian[:, still] = 0.0  # a joint without travel (no lift) must not take a share of the step
        step = -jacobian.T @ np.linalg.solve(jacobian @ jacobian.T + eye, error)
        q = np.minimum(np.maximum(pin.integrate(model, q, step), lower), upper)
    return None


def reach_pose(robot: RobotModel, target, seeds: list[np.ndarray]) -> Solution:
    """The first seed whose solution is clear of collisions.

    Args:
        robot: The robot on its line.
        target: The camera's world placement.
        seeds: Configurations to start from, in order of preference.

    Returns:
        The clear solution, else the last reached-but-blocked one (its reason), else ``Solution(None)``.
    """
    blocked: Solution = Solution(None)
    for seed in seeds:
        q = solve_pose(robot, target, seed)
        if q is None:
            continue
        hit = robot.collision(q)
        if hit is None:
            return Solution(q)
        blocked = Solution(q, hit)
    return blocked


def random_seeds(robot: RobotModel, x: float, count: int, rng: np.random.Generator) -> list[np.ndarray]:
    """Random starting configurations for a camera at ``x`` along the line: the base beside it,
    the lift anywhere in its travel, every arm joint within its limits and within +-pi."""
    lower = np.maximum(robot.lower, -np.pi)
    upper = np.minimum(robot.upper, np.pi)
    seeds = []
    for _ in range(count):
        q = rng.uniform(lower, upper)
        q[RAIL] = x + rng.uniform(-0.3, 0.3)
        q[LIFT] = rng.uniform(robot.lower[LIFT], robot.upper[LIFT])
        seeds.append(q)
    return seeds


def move_seconds(robot: RobotModel, q_from: np.ndarray, q_to: np.ndarray) -> float:
    """Seconds of a synchronised joint-space move: every coordinate (rail, lift, arm joints) at
    its speed (:attr:`RobotModel.speeds`), all arriving together, so the slowest sets the time.
    No acceleration: a lower bound on a real controller's time, and symmetric by construction."""
    return float(np.max(np.abs(np.asarray(q_to) - np.asarray(q_from)) / robot.speeds))

"""Inverse kinematics: poses the arm can take are found again, to the tolerance; moves cost symmetric seconds."""

from __future__ import annotations

import math

import numpy as np
import pinocchio as pin
import pytest
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st

from davis_ag.robot.base_line import base_lines
from davis_ag.robot.definitions import load_robot
from davis_ag.robot.ik import POSITION_TOLERANCE, move_seconds, random_seeds, reach_pose, solve_pose
from davis_ag.robot.model import build_robot, camera_rotation, view_placement

ROBOTS = {
    name: build_robot(load_robot(name), base_lines("row", "apple-wall", (-2.0, 2.0))[1])
    for name in ("ur5-trolley", "panda-trolley")
}


@given(yaw=st.floats(-180, 180), pitch=st.floats(-89, 89))
def test_a_view_rotation_has_opencv_axes_and_a_level_horizon(yaw: float, pitch: float) -> None:
    rotation = camera_rotation(yaw, pitch)
    assert np.allclose(rotation.T @ rotation, np.eye(3), atol=1e-9)
    assert np.linalg.det(rotation) == pytest.approx(1.0)
    assert rotation[2, 0] == pytest.approx(0.0, abs=1e-12)  # +x (right) has no height: a level horizon
    assert rotation[2, 1] <= 1e-12  # +y (down in the image) never points up
    forward = rotation[:, 2]
    assert math.degrees(math.asin(forward[2])) == pytest.approx(pitch, abs=1e-6)


@settings(max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(name=st.sampled_from(sorted(ROBOTS)), seed=st.integers(0, 2**32 - 1))
def test_a_pose_the_arm_takes_is_solved_again_from_another_seed(name: str, seed: int) -> None:
    robot = ROBOTS[name]
    rng = np.random.default_rng(seed)
    q_true = random_seeds(robot, 0.0, 1, rng)[0]
    jacobian = pin.computeFrameJacobian(robot.model, robot.data, q_true, robot.camera_frame)
    assume(np.linalg.svd(jacobian, compute_uv=False)[-1] > 0.05)  # a pose away from a singularity
    target = robot.camera(q_true)
    solution = None
    # The reach's seeds: a neighbour's configuration (here q_true disturbed by 0.2 rad and 10 cm),
    # then random restarts. A redundant arm: any solution counts, not q_true.
    nearby = np.clip(
        q_true + rng.normal(0.0, 0.2, q_true.shape) * np.r_[0.5, 0.5, np.ones(len(q_true) - 2)],
        robot.lower,
        robot.upper,
    )
    for start in [nearby, *random_seeds(robot, 0.0, 12, rng)]:
        solution = solve_pose(robot, target, start)
        if solution is not None:
            break
    assert solution is not None, "a pose the arm took was not found again from 12 seeds"
    assert np.all(solution >= robot.lower - 1e-12) and np.all(solution <= robot.upper + 1e-12)
    found = robot.camera(solution)
    assert np.linalg.norm(found.translation - target.translation) < POSITION_TOLERANCE
    angle = np.arccos(np.clip((np.trace(found.rotation.T @ target.rotation) - 1) / 2, -1, 1))
    assert math.degrees(angle) < 0.2


def test_a_pose_beyond_the_arm_is_not_reached() -> None:
    robot = ROBOTS["ur5-trolley"]
    far = view_placement([0.0, 1.75, 3.0, -90.0, 0.0])  # 2.3 m above a 0.85 m arm's shoulder
    seeds = random_seeds(robot, 0.0, 6, np.random.default_rng(0))
    assert not reach_pose(robot, far, seeds).ok


@settings(max_examples=30, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_move_seconds_are_positive_symmetric_and_set_by_the_slowest_joint(seed: int) -> None:
    robot = ROBOTS["ur5-trolley"]
    a, b = random_seeds(robot, 0.0, 2, np.random.default_rng(seed))
    there, back = move_seconds(robot, a, b), move_seconds(robot, b, a)
    assert there > 0 and there == back
    assert there == pytest.approx(max(abs(b - a) / robot.speeds))
    assert move_seconds(robot, a, a) == 0.0

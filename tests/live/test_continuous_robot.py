"""TVMContinuous-v0 with a robot: the arm follows the camera, every step's info["robot"] puts the
camera at its pose by forward kinematics on the URDF alone, moves it cannot make are refused."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from davis_ag.errors import UserError
from davis_ag.live.tvm_continuous import TVMContinuousEnv
from davis_ag.robot.model import camera_rotation
from real_scenes import ROBOT_VINE, generate_config

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return generate_config(tmp_path_factory, "vine", ROBOT_VINE)


def test_the_arm_follows_the_camera_by_forward_kinematics(root: Path) -> None:
    import example_robot_data

    env = TVMContinuousEnv(root, scenario="sp", split="all", robot="ur5-trolley", size=64)
    urdf = "ur_description/urdf/ur5_robot.urdf"
    model = pin.buildModelFromUrdf(str(Path(example_robot_data.getModelPath(urdf)) / urdf))
    data = model.createData()
    refused: dict[str, int] = {}
    moved = 0
    rng = np.random.default_rng(0)  # small seeded moves: most stay in the arm's reach
    for episode in range(6):
        _, info = env.reset(seed=episode)
        while True:
            robot = info["robot"]
            pin.framesForwardKinematics(model, data, np.array(robot["q"]))
            tool = data.oMf[model.getFrameId(robot["tool_frame"])].homogeneous
            camera = np.array(robot["mount"]) @ tool @ np.array(robot["camera_in_tool"])
            pose = info["path"][-1]
            assert np.linalg.norm(camera[:3, 3] - pose[:3]) < 0.01
            cosine = (np.trace(camera_rotation(pose[3], pose[4]).T @ camera[:3, :3]) - 1) / 2
            assert math.degrees(math.acos(min(1.0, cosine))) < 1.0
            _, _, over, _, info = env.step(rng.uniform(-0.3, 0.3, env.action_space.shape))
            refused[info["refused"]] = refused.get(info["refused"], 0) + 1
            if info["refused"]:
                assert info["robot"]["seconds"] == 0 and info["path"][-1] == info["path"][-2]
            else:
                moved += 1
                assert info["robot"]["seconds"] > 0
            if over:
                break
    assert moved > 0
    assert env.describe()["robot"]["name"] == "ur5-trolley"
    env.close()


def test_a_budget_of_seconds_ends_the_episode_and_needs_a_robot(root: Path) -> None:
    env = TVMContinuousEnv(root, scenario="sp", split="all", robot="ur10-lift", budget_s=1e-6, tau=50, size=64)
    env.reset(seed=0)
    env.action_space.seed(0)
    steps, over = 0, False
    while not over:
        _, _, over, _, info = env.step(env.action_space.sample())
        steps += 1
    assert steps < 50 and info["refused"] == "budget" and info["robot"]["seconds_total"] == 0
    env.close()
    with pytest.raises(UserError, match="needs a robot"):
        TVMContinuousEnv(root, scenario="sp", split="all", budget_s=10.0)

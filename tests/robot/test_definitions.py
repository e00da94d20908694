"""Robot definitions: the built-in robots load as pinocchio models; bad YAML is one line, not a traceback."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest

from davis_ag.errors import UserError
from davis_ag.robot.base_line import base_lines
from davis_ag.robot.definitions import builtin_robots, load_robot
from davis_ag.robot.model import build_robot

#: The built-in UR5 trolley's YAML, to write changed copies of.
UR5_YAML = (Path(__file__).parents[2] / "src/davis_ag/robot/robots/ur5-trolley.yaml").read_text()


def test_the_three_named_robots_are_built_in_and_build() -> None:
    assert {"ur5-trolley", "ur10-lift", "panda-trolley"} <= set(builtin_robots())
    for name in builtin_robots():
        definition = load_robot(name)
        assert definition.sources, f"{name}: its mount needs a documented source"
        robot = build_robot(definition, base_lines("row", "apple-wall", (-2.0, 2.0))[1])
        # rail, lift, then the arm's free joints; the URDF order keeps the locked ones
        assert robot.model.nq == 2 + len(robot.free)
        assert len(robot.arm_joints) == len(robot.locked)
        assert "self" in robot.pair_kinds and "ground" in robot.pair_kinds


def test_an_unknown_robot_is_one_line_listing_the_robots() -> None:
    with pytest.raises(UserError, match="ur10-lift"):
        load_robot("ur7-hovercraft")


def test_a_yaml_robot_loads_and_its_digest_follows_its_content(tmp_path: Path) -> None:
    text = UR5_YAML
    mine = tmp_path / "mine.yaml"
    mine.write_text(
        text.replace("name: ur5-trolley", "name: my-ur5").replace("mount_height_m: 0.69", "mount_height_m: 0.8")
    )
    definition = load_robot(str(mine))
    assert definition.name == "my-ur5" and definition.mount_height_m == 0.8
    assert definition.digest != load_robot("ur5-trolley").digest


@pytest.mark.parametrize(
    ("change", "message"),
    [
        (("arm: ur5", "urdf: missing/arm.urdf"), "is not a file"),
        (("tool_frame: tool0", "tool_frame: flange9"), "tool frame 'flange9' not in"),
        (("lift_m: [0.0, 0.0]", "lift_m: [1.0, 0.0]"), "lift_m"),
        (("arm: ur5", "arm: ur5\nwheels: 4"), "wheels"),
    ],
)
def test_a_broken_yaml_is_one_line(tmp_path: Path, change: tuple[str, str], message: str) -> None:
    text = UR5_YAML
    broken = tmp_path / "broken.yaml"
    broken.write_text(text.replace(*change))
    with pytest.raises(UserError, match=message):
        definition = load_robot(str(broken))
        build_robot(definition, base_lines("sp", None, (-1.0, 1.0))[1])


def test_a_urdf_that_does_not_parse_is_one_line(tmp_path: Path) -> None:
    (tmp_path / "arm.urdf").write_text("<robot name='x'><link name='a'/><joint name='j' type='revolute'></robot>")
    text = UR5_YAML
    (tmp_path / "bad.yaml").write_text(text.replace("arm: ur5", "urdf: arm.urdf"))
    with pytest.raises(UserError, match="does not load"):
        build_robot(load_robot(str(tmp_path / "bad.yaml")), base_lines("sp", None, (-1.0, 1.0))[1])


def test_robots_lists_each_robot_with_its_reach_by_height() -> None:
    done = subprocess.run(
        [sys.executable, "-m", "davis_ag.cli", "robots", "ur10-lift"], capture_output=True, text=True, check=False
    )
    assert done.returncode == 0, done.stderr
    assert "ur10-lift: example-robot-data:ur10" in done.stdout
    shares = [float(v) for v in done.stdout.splitlines()[-1].split()[2:]]
    assert max(shares) == 100 and len(shares) == 10


def test_the_robot_lowers_with_its_lift() -> None:
    definition = load_robot("ur10-lift")
    robot = build_robot(definition, base_lines("row", "apple", (0.0, 1.0))[1])
    q = np.concatenate([[0.5, 0.0], robot.locked[robot.free]])
    low = robot.mount(q)[2, 3]
    q[1] = 1.0
    assert robot.mount(q)[2, 3] == pytest.approx(low + 1.0)
    assert low == pytest.approx(definition.mount_height_m)

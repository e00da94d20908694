"""Robot definitions: which arm, on what base, with which camera, at what speeds (one YAML each).

A robot is an arm of example-robot-data (or any URDF), mounted on a base that drives along the
scenario's base line (:mod:`davis_ag.robot.base_line`), optionally on a vertical lift, with a
camera at a fixed offset from one of the arm's frames. The built-in robots are YAML files in
``robot/robots/``; a user's YAML with the same fields describes another:

.. code-block:: yaml

    name: my-arm
    urdf: my_arm/urdf/arm.urdf     # relative to the YAML; or `arm: ur5` (example-robot-data)
    tool_frame: tool0              # the URDF frame the camera is fixed to
    mount_height_m: 0.69           # the arm's base above the ground, lift down
    lift_m: [0.0, 1.0]             # the lift's travel; [0, 0] for none
    base_speed_m_s: 1.0            # along the base line
    lift_speed_m_s: 0.2
    joint_speed_scale: 0.5         # share of the URDF's joint velocity limits used
    camera_in_tool: {xyz_m: [0, 0, 0.1], rpy_deg: [0, 0, 0]}
    platform_m: [1.0, 0.7, 0.5]    # the base's box: along the line, across, high
    locked_joints: {}              # joints held still (a gripper's fingers), by name
    home_q: null                   # a first guess for the IK, the arm's joints in URDF order
    sources: ["where the numbers come from"]

The camera frame follows OpenCV (+z along the optical axis, +x right, +y down in the image). Its
intrinsics are the dataset's (scene.json's ``camera``): a robot never changes what a view shows,
only which views it may take and what moving between them costs.
"""

from __future__ import annotations

import hashlib
import json
from functools import cache
from importlib import resources
from pathlib import Path
from typing import Any

import numpy as np
import yaml
from pydantic import BaseModel, ConfigDict, Field, ValidationError, field_validator

from davis_ag.errors import UserError, yaml_problem
from davis_ag.formats.models import one_line


class CameraMount(BaseModel):
    """Where the camera sits on the tool frame: a translation and roll-pitch-yaw angles (degrees)."""

    model_config = ConfigDict(extra="forbid")
    xyz_m: tuple[float, float, float] = (0.0, 0.0, 0.1)
    rpy_deg: tuple[float, float, float] = (0.0, 0.0, 0.0)


class RobotDefinition(BaseModel):
    """One robot: see the module docstring for each field's meaning."""

    model_config = ConfigDict(extra="forbid")
    name: str
    description: str = ""
    arm: str | None = Field(default=None, description="an example-robot-data robot (ur5, ur10, panda, ...)")
    urdf: str | None = Field(default=None, description="a URDF file, relative to the YAML")
    tool_frame: str
    mount_height_m: float = Field(ge=0.0, le=5.0)
    lift_m: tuple[float, float] = (0.0, 0.0)
    base_speed_m_s: float = Field(gt=0.0)
    lift_speed_m_s: float = Field(gt=0.0)
    joint_speed_scale: float = Field(default=0.5, gt=0.0, le=1.0)
    camera_in_tool: CameraMount = CameraMount()
    platform_m: tuple[float, float, float] = (1.0, 0.7, 0.5)
    locked_joints: dict[str, float] = Field(default_factory=dict)
    home_q: list[float] | None = None
    sources: list[str] = Field(default_factory=list)
    #: The folder a user's YAML came from (its relative ``urdf`` is read from there); not a field.
    folder: str | None = Field(default=None, exclude=True)

    @field_validator("lift_m")
    @classmethod
    def _lift_ordered(cls, value: tuple[float, float]) -> tuple[float, float]:
        if not 0.0 <= value[0] <= value[1] <= 5.0:
            raise ValueError("lift_m must be [low, high] with 0 <= low <= high <= 5 m")
        return value

    @property
    def digest(self) -> str:
        """SHA-256 (first 16 hex digits) of the definition as written: what a results file records."""
        text = json.dumps(self.model_dump(mode="json"), sort_keys=True)
        return hashlib.sha256(text.encode()).hexdigest()[:16]

    def results_record(self) -> dict[str, str]:
        """What a results file records of the robot: name, definition digest and URDF."""
        return {"name": self.name, "digest": self.digest, "urdf": self.urdf_source}

    def step_info(
        self, camera_in_tool: list[list[float]], mount: np.ndarray, urdf_q: np.ndarray, seconds: float, total: float
    ) -> dict[str, Any]:
        """A step's ``info["robot"]``: what anyone can check with pinocchio on the URDF alone
        (:mod:`davis_ag.benchmark.robot_moves` lists the fields)."""
        return {
            "name": self.name,
            "urdf": self.urdf_source,
            "digest": self.digest,
            "mount": np.asarray(mount).tolist(),
            "q": np.asarray(urdf_q).tolist(),
            "tool_frame": self.tool_frame,
            "camera_in_tool": camera_in_tool,
            "seconds": seconds,
            "seconds_total": total,
        }

    @property
    def urdf_source(self) -> str:
        """The URDF, in words a reader can find it by: example-robot-data's name, or the file."""
        return f"example-robot-data:{self.arm}" if self.arm else str(self.urdf_path())

    def urdf_path(self) -> Path:
        """The URDF file this robot loads.

        Raises:
            UserError: when neither ``arm`` nor ``urdf`` names one that exists.
        """
        if self.urdf:
            path = Path(self.urdf)
            if not path.is_absolute() and self.folder:
                path = Path(self.folder) / path
            if not path.is_file():
                raise UserError(f"robot {self.name}: its urdf {path} is not a file; fix `urdf:` in its YAML")
            return path
        if not self.arm:
            raise UserError(f"robot {self.name}: its YAML names no `arm:` (example-robot-data) and no `urdf:`")
        return _example_robot_urdf(self.arm)


#: URDF files of example-robot-data's arms, by its names. Loaded by path: ``load("ur3")``
#: returns the UR5 (a loader bug, ../shared/notes/robot.md).
EXAMPLE_ROBOT_URDFS = {
    "ur3": "ur_description/urdf/ur3_robot.urdf",
    "ur5": "ur_description/urdf/ur5_robot.urdf",
    "ur10": "ur_description/urdf/ur10_robot.urdf",
    "panda": "panda_description/urdf/panda.urdf",
    "z1": "z1_description/urdf/z1.urdf",
}


def _example_robot_urdf(arm: str) -> Path:
    try:
        import example_robot_data
    except ImportError as error:
        raise UserError(
            "the robot stage needs pinocchio and example-robot-data: pip install 'davis-ag[robot]'"
        ) from error
    if arm not in EXAMPLE_ROBOT_URDFS:
        raise UserError(
            f"arm {arm!r} is not one davis-ag loads from example-robot-data; use one of "
            f"{', '.join(sorted(EXAMPLE_ROBOT_URDFS))} or give `urdf:` a file"
        )
    return Path(example_robot_data.getModelPath(EXAMPLE_ROBOT_URDFS[arm])) / EXAMPLE_ROBOT_URDFS[arm]


def builtin_robots() -> tuple[str, ...]:
    """The names of the robots davis-ag ships, sorted."""
    folder = resources.files("davis_ag.robot") / "robots"
    return tuple(sorted(p.name.removesuffix(".yaml") for p in folder.iterdir() if p.name.endswith(".yaml")))


def _parse(text: str, where: str, folder: str | None) -> RobotDefinition:
    try:
        raw = yaml.safe_load(text)
    except yaml.YAMLError as error:
        raise UserError(f"{where}: {yaml_problem(error)}; fix the file") from None
    if not isinstance(raw, dict):
        raise UserError(f"{where} holds no robot (a YAML mapping of the fields in docs/robot.md)")
    try:
        return RobotDefinition.model_validate({**raw, "folder": folder})
    except ValidationError as error:
        raise UserError(f"{one_line(error, where)}; see docs/robot.md for the fields") from None


@cache
def load_robot(name_or_path: str) -> RobotDefinition:
    """A robot by its built-in name (``ur10-lift``) or from a YAML file.

    Args:
        name_or_path: One of :func:`builtin_robots`, or a path to a YAML file.

    Returns:
        The definition.

    Raises:
        UserError: for an unknown name (the line lists the robots) or a YAML that does not parse.
    """
    if name_or_path in builtin_robots():
        text = (resources.files("davis_ag.robot") / "robots" / f"{name_or_path}.yaml").read_text()
        return _parse(text, f"robot {name_or_path}", None)
    path = Path(name_or_path)
    if path.suffix in (".yaml", ".yml"):
        if not path.is_file():
            raise UserError(
                f"robot file {path} does not exist; give a YAML file or one of {', '.join(builtin_robots())}"
            )
        return _parse(path.read_text(), str(path), str(path.resolve().parent))
    raise UserError(f"unknown robot {name_or_path!r}: use one of {', '.join(builtin_robots())} or a YAML file")

"""A robot as pinocchio models it: a rail joint, a lift joint, the URDF's arm, a camera frame.

The kinematic chain, from the world: ``rail`` (prismatic along x, the base driving along its
line, placed at the line's y), ``lift`` (prismatic along z), the arm's base at
``mount_height_m`` above the ground turned to face the plants, then the URDF's joints (those in
``locked_joints`` held at their values: :func:`pinocchio.buildReducedModel`), and a frame
``camera`` fixed to the tool frame at ``camera_in_tool``. Configuration ``q`` is
``[rail x, lift, arm joints...]`` (:data:`RAIL`, :data:`LIFT`).

Collision geometry (coal, through pinocchio's GeometryModel): the URDF's collision meshes, the
camera (a 9 x 2.5 x 2.5 cm box, a RealSense D435's size), the base's platform box, the ground
(a half-space ``z <= 0``) and the scene's obstacles (:mod:`davis_ag.robot.obstacles`, an octree).
Pairs checked: the arm's links with each other but for neighbours and pairs that touch at rest;
every arm link but the first, and the camera, with the ground and the platform; everything with
the obstacles.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numpy as np

from davis_ag.errors import UserError
from davis_ag.robot.base_line import BaseLine
from davis_ag.robot.definitions import RobotDefinition

#: Indices of the rail and lift joints in ``q``.
RAIL, LIFT = 0, 1
#: The camera's collision box, m (a RealSense D435: 90 x 25 x 25 mm).
CAMERA_BOX = (0.09, 0.025, 0.025)


def import_pinocchio():
    """pinocchio and coal, or one line saying how to install them."""
    try:
        import coal
        import pinocchio as pin
    except ImportError as error:
        raise UserError("the robot stage needs pinocchio and coal: pip install 'davis-ag[robot]'") from error
    return pin, coal


def camera_rotation(yaw_deg: float, pitch_deg: float) -> np.ndarray:
    """World-from-camera rotation of a view (OpenCV axes: columns right, down, forward).

    Args:
        yaw_deg: Degrees counter-clockwise from +x.
        pitch_deg: Degrees above the horizon.

    Returns:
        A 3x3 rotation matrix; its image's horizon is level (right has no z).
    """
    yaw, pitch = math.radians(yaw_deg), math.radians(pitch_deg)
    forward = np.array([math.cos(pitch) * math.cos(yaw), math.cos(pitch) * math.sin(yaw), math.sin(pitch)])
    right = np.array([math.sin(yaw), -math.cos(yaw), 0.0])
    down = np.cross(forward, right)
    return np.column_stack([right, down, forward])


def view_placement(pose: list[float] | tuple[float, ...]):
    """The camera's world placement (a ``pinocchio.SE3``) of a published pose ``[x, y, z, yaw, pitch]``."""
    pin, _ = import_pinocchio()
    x, y, z, yaw, pitch = (float(v) for v in pose[:5])
    return pin.SE3(camera_rotation(yaw, pitch), np.array([x, y, z]))


def camera_in_tool(definition: RobotDefinition):
    """The camera's placement in the tool frame (a ``pinocchio.SE3``) from the definition's
    translation and roll-pitch-yaw."""
    pin, _ = import_pinocchio()
    mount = definition.camera_in_tool
    return pin.SE3(pin.rpy.rpyToMatrix(*np.radians(mount.rpy_deg)), np.asarray(mount.xyz_m, dtype=float))


@dataclass
class RobotModel:
    """A robot on one base line: model, data, geometry and the frames the reach needs.

    Attributes:
        definition: What it was built from.
        line: The base line it drives along.
        model, data: The pinocchio model of rail, lift and arm, and its data.
        geometry, geometry_data: Its collision model (pairs as in the module docstring) and data.
        camera_frame: Id of the ``camera`` frame.
        tool_frame: Id of the tool frame.
        mount_frame: Id of the frame where the arm's base sits.
        arm_joints: The URDF's joint names, in the URDF model's order (``info["robot"]["q"]``).
        locked: The URDF model's configuration with locked joints at their values (for expanding).
        free: Indices into the URDF model's ``q`` of the joints this model moves.
        speeds: Speed of each coordinate of ``q``: m/s for rail and lift, rad/s for the arm.
    """

    definition: RobotDefinition
    line: BaseLine
    model: object
    data: object
    geometry: object
    geometry_data: object
    camera_frame: int
    tool_frame: int
    mount_frame: int
    arm_joints: tuple[str, ...]
    locked: np.ndarray
    free: np.ndarray
    speeds: np.ndarray
    pair_kinds: list[str] = field(default_factory=list)

    @property
    def lower(self) -> np.ndarray:
        return self.model.lowerPositionLimit  # type: ignore[attr-defined]

    @property
    def upper(self) -> np.ndarray:
        return self.model.upperPositionLimit  # type: ignore[attr-defined]

    def urdf_q(self, q: np.ndarray) -> np.ndarray:
        """The URDF model's joint positions (locked joints included) of a configuration ``q``."""
        full = self.locked.copy()
        full[self.free] = q[2:]
        return full

    def mount(self, q: np.ndarray) -> np.ndarray:
        """The 4x4 world-from-arm-base matrix at ``q`` (base and lift where ``q`` puts them)."""
        pin, _ = import_pinocchio()
        pin.framesForwardKinematics(self.model, self.data, q)
        return self.data.oMf[self.mount_frame].homogeneous.copy()  # type: ignore[attr-defined]

    def camera(self, q: np.ndarray):
        """The camera's world placement at ``q``."""
        pin, _ = import_pinocchio()
        pin.framesForwardKinematics(self.model, self.data, q)
        return self.data.oMf[self.camera_frame].copy()  # type: ignore[attr-defined]

    def collision(self, q: np.ndarray) -> str | None:
        """What ``q`` hits (``self``, ``ground``, ``platform``, ``obstacle``), or ``None`` when clear."""
        pin, _ = import_pinocchio()
        if not pin.computeCollisions(self.model, self.data, self.geometry, self.geometry_data, q, True):
            return None
        for k, result in enumerate(self.geometry_data.collisionResults):  # type: ignore[attr-defined]
            if result.isCollision():
                return self.pair_kinds[k]
        return "self"


def _package_dirs(path) -> list[str]:
    """Folders a URDF's ``package://`` meshes may be under: its ancestors (example-robot-data's
    meshes are ``package://example-robot-data/robots/...``, four folders above the URDF)."""
    return [str(folder) for folder in list(path.resolve().parents)[:6]]


def _urdf_model(definition: RobotDefinition):
    """The URDF's model and collision model, locked joints removed."""
    pin, _ = import_pinocchio()
    path = definition.urdf_path()
    try:
        model = pin.buildModelFromUrdf(str(path))
        geometry = pin.buildGeomFromUrdf(model, str(path), pin.GeometryType.COLLISION, package_dirs=_package_dirs(path))
    except Exception as error:  # pinocchio raises plain ValueError/RuntimeError on a bad URDF
        raise UserError(f"robot {definition.name}: its URDF {path} does not load ({error}); fix the file") from error
    names = tuple(model.names[1:])
    unknown = [j for j in definition.locked_joints if j not in names]
    if unknown or not model.existFrame(definition.tool_frame):
        what = f"locked joints {unknown}" if unknown else f"tool frame {definition.tool_frame!r}"
        raise UserError(f"robot {definition.name}: {what} not in {path.name} (joints: {', '.join(names)})")
    if definition.home_q is not None and len(definition.home_q) != model.nq - len(definition.locked_joints):
        raise UserError(
            f"robot {definition.name}: home_q has {len(definition.home_q)} values, the arm moves "
            f"{model.nq - len(definition.locked_joints)} joints ({', '.join(names)})"
        )
    reference = pin.neutral(model)
    lock_ids = []
    for joint, value in definition.locked_joints.items():
        jid = model.getJointId(joint)
        reference[model.idx_qs[jid]] = value
        lock_ids.append(jid)
    free = np.array([model.idx_qs[j] for j in range(1, model.njoints) if j not in lock_ids], dtype=np.int64)
    if lock_ids:
        model_r, geometry = pin.buildReducedModel(model, geometry, lock_ids, reference)
    else:
        model_r = model
    return model_r, geometry, names, reference, free


def _adjacent(model, a: int, b: int) -> bool:
    return a == b or model.parents[a] == b or model.parents[b] == a


def build_robot(definition: RobotDefinition, line: BaseLine, obstacles: np.ndarray | None = None) -> RobotModel:
    """The robot on one base line, with the scene's obstacles.

    Args:
        definition: The robot.
        line: Where its base drives.
        obstacles: ``(n, 3)`` world points the robot must not touch (trunks), or ``None``.

    Returns:
        The :class:`RobotModel`.
    """
    pin, coal = import_pinocchio()
    arm, arm_geometry, names, reference, free = _urdf_model(definition)
    base = pin.Model()
    rail = base.addJoint(0, pin.JointModelPX(), pin.SE3(np.eye(3), np.array([0.0, line.y, 0.0])), "rail")
    lift = base.addJoint(rail, pin.JointModelPZ(), pin.SE3.Identity(), "lift")
    base.addJointFrame(rail)
    base.addJointFrame(lift)
    mount_placement = pin.SE3(
        pin.rpy.rpyToMatrix(0.0, 0.0, line.facing), np.array([0.0, 0.0, definition.mount_height_m])
    )
    mount = base.addFrame(pin.Frame("mount", lift, base.getFrameId("lift"), mount_placement, pin.FrameType.OP_FRAME))
    base_geometry = pin.GeometryModel()
    length, width, height = definition.platform_m
    base_geometry.addGeometryObject(
        pin.GeometryObject(
            "platform", rail, pin.SE3(np.eye(3), np.array([0.0, 0.0, height / 2])), coal.Box(length, width, height)
        )
    )
    model, geometry = pin.appendModel(base, arm, base_geometry, arm_geometry, mount, pin.SE3.Identity())
    tool = model.getFrameId(definition.tool_frame)
    tool_frame = model.frames[tool]
    camera_in_joint = tool_frame.placement * camera_in_tool(definition)
    camera = model.addFrame(pin.Frame("camera", tool_frame.parentJoint, tool, camera_in_joint, pin.FrameType.OP_FRAME))
    geometry.addGeometryObject(
        pin.GeometryObject("camera_box", tool_frame.parentJoint, camera_in_joint, coal.Box(*CAMERA_BOX))
    )
    geometry.addGeometryObject(
        pin.GeometryObject("ground", 0, pin.SE3.Identity(), coal.Halfspace(np.array([0.0, 0.0, 1.0]), 0.0))
    )
    if obstacles is not None and len(obstacles):
        octree = coal.makeOctree(np.asarray(obstacles, dtype=float), 0.03)
        geometry.addGeometryObject(pin.GeometryObject("obstacles", 0, pin.SE3.Identity(), octree))
    model.lowerPositionLimit[RAIL], model.upperPositionLimit[RAIL] = line.x_range
    model.lowerPositionLimit[LIFT], model.upperPositionLimit[LIFT] = definition.lift_m
    speeds = np.concatenate(
        [[definition.base_speed_m_s, definition.lift_speed_m_s], model.velocityLimit[2:] * definition.joint_speed_scale]
    )
    robot = RobotModel(
        definition, line, model, model.createData(), geometry, None, camera, tool, mount, names, reference, free, speeds
    )
    _add_pairs(robot, pin)
    robot.geometry_data = pin.GeometryData(geometry)
    return robot


def _add_pairs(robot: RobotModel, pin) -> None:
    """The collision pairs of the module docstring, and what each one means (``pair_kinds``)."""
    model, geometry = robot.model, robot.geometry
    objects = list(geometry.geometryObjects)  # type: ignore[attr-defined]
    index = {o.name: k for k, o in enumerate(objects)}
    links = [k for k, o in enumerate(objects) if o.parentJoint >= 2 and o.name not in ("platform",)]
    first_joint = min(objects[k].parentJoint for k in links)
    kinds = []
    rest = np.concatenate([[0.5 * sum(robot.line.x_range), robot.definition.lift_m[0]], robot.locked[robot.free]])
    home = rest.copy()
    if robot.definition.home_q is not None:
        home[2:] = robot.definition.home_q
    candidates: list[tuple[int, int, str]] = []
    for i, a in enumerate(links):
        for b in links[i + 1 :]:
            if not _adjacent(model, objects[a].parentJoint, objects[b].parentJoint):
                candidates.append((a, b, "self"))
    for a in links:
        if objects[a].parentJoint != first_joint:
            candidates.append((index["ground"], a, "ground"))
            if objects[a].parentJoint > first_joint + 1:
                candidates.append((index["platform"], a, "platform"))
        if "obstacles" in index:
            candidates.append((index["obstacles"], a, "obstacle"))
    if "obstacles" in index:
        candidates.append((index["obstacles"], index["platform"], "obstacle"))
    # Self pairs that touch at rest (the arm as built, and its home) are contact by design: dropped.
    geometry.removeAllCollisionPairs()  # type: ignore[attr-defined]
    for a, b, kind in candidates:
        geometry.addCollisionPair(pin.CollisionPair(a, b))  # type: ignore[attr-defined]
        kinds.append(kind)
    data = pin.GeometryData(geometry)
    touching = set()
    for q in (rest, home):
        pin.computeCollisions(model, model.createData(), geometry, data, q, False)  # type: ignore[attr-defined]
        touching |= {k for k, r in enumerate(data.collisionResults) if r.isCollision() and kinds[k] == "self"}
    for k in sorted(touching, reverse=True):
        geometry.removeCollisionPair(geometry.collisionPairs[k])  # type: ignore[attr-defined]
        del kinds[k]
    robot.pair_kinds = kinds

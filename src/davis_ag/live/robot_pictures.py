"""The robot drawn in its scene by our renderer: a third-person view of the arm at a view's
configuration, beside what its camera saw there.

The arm is drawn from the URDF's collision meshes (STL, read by trimesh) placed by pinocchio at
the view's configuration (:class:`davis_ag.robot.reach.SceneReach`), with the base's platform
and the camera as boxes, all added to the scene's own triangles (:class:`SceneGeometry`) so the
sun shades them and the plants hide them as they hide each other. The scene is reopened with
:func:`davis_ag.live.scene.open_live_scene` (its geometry cache, or a regrow).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from davis_ag.render.scene_geometry import COLOUR, SceneGeometry

if TYPE_CHECKING:
    from davis_ag.robot.model import RobotModel

#: Colours of the arm's links, its platform and its camera (RGBA, 0-1).
ARM_COLOUR = (0.75, 0.78, 0.82, 1.0)
PLATFORM_COLOUR = (0.20, 0.35, 0.65, 1.0)
CAMERA_COLOUR = (0.10, 0.10, 0.10, 1.0)


def robot_triangles(robot: RobotModel, q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The robot's surfaces at ``q``: ``(n, 3, 3)`` world triangles and ``(n, 4)`` colours."""
    import trimesh

    from davis_ag.robot.model import import_pinocchio

    pin, _ = import_pinocchio()
    pin.updateGeometryPlacements(robot.model, robot.data, robot.geometry, robot.geometry_data, q)
    triangles, colours = [], []
    for k, item in enumerate(robot.geometry.geometryObjects):  # type: ignore[attr-defined]
        if item.name == "platform" or item.name == "camera_box":
            mesh = trimesh.creation.box(extents=[item.geometry.halfSide[i] * 2 for i in range(3)])
            colour = PLATFORM_COLOUR if item.name == "platform" else CAMERA_COLOUR
        elif item.meshPath and Path(item.meshPath).suffix.lower() in (".stl", ".obj", ".ply"):
            mesh = trimesh.load(item.meshPath, force="mesh")
            mesh.apply_scale(np.asarray(item.meshScale))
            colour = ARM_COLOUR
        else:  # the ground and the obstacles are the scene's own
            continue
        mesh.apply_transform(robot.geometry_data.oMg[k].homogeneous)  # type: ignore[attr-defined]
        triangles.append(np.asarray(mesh.triangles, dtype=np.float32))
        colours.append(np.tile(np.array(colour, dtype=np.float32), (len(mesh.triangles), 1)))
    # The lift's column, from the platform's top to the arm's base: drawn only (it stands inside
    # the platform's footprint, under the arm's first link, so it is no collision body).
    pin.framesForwardKinematics(robot.model, robot.data, q)
    base = robot.data.oMf[robot.mount_frame].translation  # type: ignore[attr-defined]
    top, bottom = float(base[2]), robot.definition.platform_m[2]
    if top > bottom + 0.01:
        column = trimesh.creation.box(extents=[0.2, 0.2, top - bottom])
        column.apply_translation([base[0], base[1], (top + bottom) / 2])
        triangles.append(np.asarray(column.triangles, dtype=np.float32))
        colours.append(np.tile(np.array(PLATFORM_COLOUR, dtype=np.float32), (len(column.triangles), 1)))
    return np.concatenate(triangles), np.concatenate(colours)


def with_triangles(geometry: SceneGeometry, triangles: np.ndarray, colours: np.ndarray, uuid: int) -> SceneGeometry:
    """The scene's geometry with plain-coloured triangles added (flat-shaded, casting shadows),
    all carrying primitive id ``uuid`` (one no fruit has)."""
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-12)
    n = len(triangles)
    return SceneGeometry(
        positions=np.concatenate([geometry.positions, triangles.astype(np.float32)]),
        uvs=np.concatenate([geometry.uvs, np.zeros((n, 3, 2), np.float32)]),
        normals=np.concatenate([geometry.normals, np.repeat(normals[:, None].astype(np.float32), 3, axis=1)]),
        uuids=np.concatenate([geometry.uuids, np.full(n, uuid, geometry.uuids.dtype)]),
        colours=np.concatenate([geometry.colours, colours.astype(np.float32)]),
        texture=np.concatenate([geometry.texture, np.full(n, -1, geometry.texture.dtype)]),
        mode=np.concatenate([geometry.mode, np.full(n, COLOUR, geometry.mode.dtype)]),
        caster=np.concatenate([geometry.caster, np.ones(n, bool)]),
        patch=np.concatenate([geometry.patch, np.zeros(n, bool)]),
        texture_files=list(geometry.texture_files),
    )


def onlooker_pose(mount: np.ndarray, camera: np.ndarray, line_y: float) -> tuple[float, float, float, float, float]:
    """A third-person pose: on the alley's line 3 m behind the base and 0.8 m above the arm's
    middle, looking at that middle (between the arm's base and its camera).

    Args:
        mount: 4x4 world-from-arm-base.
        camera: 3-vector, the wrist camera's position.
        line_y: The base line's y, m (the alley's centre in a row).
    """
    target = (mount[:3, 3] + camera) / 2
    eye = np.array([target[0] - 3.0, line_y, target[2] + 0.8])
    dx, dy, dz = target - eye
    return (*eye.tolist(), math.degrees(math.atan2(dy, dx)), math.degrees(math.atan2(dz, math.hypot(dx, dy))))


@dataclass(frozen=True)
class RobotFrame:
    """One step of a robot's episode, drawn.

    Attributes:
        view: The view's image name.
        onlooker: The third-person image of the robot at the view's configuration (H x W x 3).
        camera: What its camera saw there: the dataset's own image of the view (H x W x 3).
    """

    view: str
    onlooker: np.ndarray
    camera: np.ndarray


def robot_frames(
    scene_dir: str | Path, robot: str, views: list[str], size: tuple[int, int] = (640, 360), cache_dir: Any = None
) -> list[RobotFrame]:
    """Draw the robot at each of ``views`` (a reachable view each) in its reopened scene.

    Args:
        scene_dir: The scene folder (``<root>/<group>/<NNN>``), made by ``davis-ag generate``.
        robot: A robot name or YAML file.
        views: Image names (``0001.jpeg``), e.g. an episode's path.
        size: The third-person images' width and height, pixels.
        cache_dir: The caches' base folder, as ``reach`` took it.

    Returns:
        One :class:`RobotFrame` per view.

    Raises:
        UserError: for a view the robot does not reach.
    """
    from davis_ag.data.reader import open_dataset
    from davis_ag.errors import UserError
    from davis_ag.live.scene import LiveScene, open_live_scene
    from davis_ag.render.opengl import OpenGLRenderer
    from davis_ag.robot.definitions import load_robot
    from davis_ag.robot.model import build_robot
    from davis_ag.robot.reach import load_reach, scene_lines, view_poses
    from davis_ag.scene.camera import Camera

    folder = Path(scene_dir)
    scene = open_dataset(folder.parents[1]).scene(f"{folder.parent.name}/{folder.name}")
    definition = load_robot(robot)
    reach = load_reach(scene, folder.parents[1], definition, cache_dir)
    lines, sides = scene_lines(scene, view_poses(scene))
    live = open_live_scene(folder)
    frames = []
    try:
        for name in views:
            i = reach.view_names.index(name)
            if not reach.reachable[i]:
                raise UserError(f"{scene.id}/{name}: {definition.name} does not reach it; choose a reachable view")
            side = int(sides[i])
            model = build_robot(definition, lines[side])
            triangles, colours = robot_triangles(model, reach.q[i])
            geometry = with_triangles(live.assets.geometry, triangles, colours, live.assets.uuid_count)
            camera = Camera(*size, live.settings.camera.vfov)
            renderer = OpenGLRenderer(geometry, camera, live.assets.lighting, look=live.settings.look)
            try:
                pose = onlooker_pose(reach.mount[i], model.camera(reach.q[i]).translation, lines[side].y)
                onlooker = renderer.render(LiveScene.pose(*pose), depth=False)[0]
            finally:
                renderer.close()
            frames.append(RobotFrame(name, onlooker, scene.view(name).image()))
    finally:
        live.close()
    return frames

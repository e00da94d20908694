"""Which views of a scene a robot reaches, with what configuration, and the seconds of each move.

A view is reachable when the camera frame can be put at its recorded pose (after slip; position,
optical axis and a level horizon: :func:`davis_ag.robot.model.view_placement`) within joint
limits and clear of every collision pair (:mod:`davis_ag.robot.model`), the base on the view's
side's line (:mod:`davis_ag.robot.base_line`).

Each view gets one configuration, found by continuation: the views of a side are visited in
breadth-first order over the move graph from the view nearest the middle of the line, and each is
solved first from its solved neighbours' configurations (so a move is what the arm would do from
where it was, not a new arm each time), then from the robot's home pose beside it, then from
random restarts (:data:`RESTARTS`, from the scene seed's ``REACH_STREAM``). A move between two
reachable views then costs :func:`davis_ag.robot.ik.move_seconds` of their configurations: the
same both ways.

The result is cached per scene and robot in ``<cache base>/.reach/<robot>-<digest>/<scene id>.npz``
(the observation caches' base: ``<dataset>/.davis_ag_cache`` or a ``cache_dir``), written
atomically and keyed by the scene's annotations.json digest and :data:`REACH_VERSION`; nothing is
written inside what ``generate`` wrote.
"""

from __future__ import annotations

import hashlib
import json
import os
from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from davis_ag.atomic_files import atomic_output
from davis_ag.errors import UserError
from davis_ag.formats.layout import CACHE_FOLDER
from davis_ag.robot.base_line import BaseLine, base_lines, side_of
from davis_ag.robot.definitions import RobotDefinition, load_robot
from davis_ag.robot.ik import move_seconds, random_seeds, reach_pose
from davis_ag.robot.model import LIFT, RAIL, RobotModel, build_robot, view_placement
from davis_ag.robot.obstacles import trunk_points
from davis_ag.scene.specs import ALL_ACTIONS
from davis_ag.seeds import REACH_STREAM, stream_rng

if TYPE_CHECKING:
    from davis_ag.data.reader import Scene

#: Bumped when what the cache holds changes meaning.
REACH_VERSION = 2
#: Random restarts after the neighbours' and the home seeds.
RESTARTS = 6
#: Why a view is out of reach, by code (``SceneReach.blocked``).
BLOCKED = ("reached", "out of reach", "self", "ground", "platform", "obstacle")


@dataclass(frozen=True)
class SceneReach:
    """One robot's reach of one scene.

    Attributes:
        robot: The robot's name.
        digest: Its definition's digest (:attr:`RobotDefinition.digest`).
        view_names: The scene's views, in image order.
        reachable: ``(n,)`` bool.
        blocked: ``(n,)`` uint8 index into :data:`BLOCKED` (0 where reachable).
        q: ``(n, 2 + arm joints)`` the configuration ``[rail, lift, arm...]``, NaN where unreachable.
        urdf_q: ``(n, URDF joints)`` the arm's joints in the URDF model's order (locked ones included).
        mount: ``(n, 4, 4)`` world-from-arm-base at each view's configuration.
        seconds: ``(n, len(ALL_ACTIONS))`` seconds of the move each pointer names, NaN where the
            pointer is "" or either end is out of reach.
        obstacle_points: How many trunk points the scene's obstacles held.
    """

    robot: str
    digest: str
    view_names: tuple[str, ...]
    reachable: np.ndarray
    blocked: np.ndarray
    q: np.ndarray
    urdf_q: np.ndarray
    mount: np.ndarray
    seconds: np.ndarray
    obstacle_points: int

    @property
    def share(self) -> float:
        """Share of the scene's views the robot reaches."""
        return float(self.reachable.mean()) if len(self.reachable) else 0.0


def pointer_table(scene: Scene) -> np.ndarray:
    """``(n, len(ALL_ACTIONS))`` int32: the view index each pointer names, -1 for ""."""
    views = list(scene)
    position = {view.name: i for i, view in enumerate(views)}
    table = np.full((len(views), len(ALL_ACTIONS)), -1, dtype=np.int32)
    for i, view in enumerate(views):
        for j, action in enumerate(ALL_ACTIONS):
            target = view.pointers.get(action, "")
            table[i, j] = position.get(target, -1) if target else -1
    return table


def view_poses(scene: Scene) -> np.ndarray:
    """``(n, 5)`` every view's recorded pose ``[x, y, z, yaw, pitch]``, in image order.

    Raises:
        UserError: for a view without a pose.
    """
    poses = []
    for view in scene:
        if view.pose is None:
            raise UserError(f"{scene.annotations_path}: {view.name} has no pose; a robot needs every view's pose")
        poses.append(view.pose[:5])
    return np.array(poses, dtype=float)


def _nominal_y(scene: Scene, poses: np.ndarray) -> np.ndarray:
    """Each view's y before slip where scene.json has it (the side never flips on slip), else its pose's."""
    places = (scene.metadata.views or {}) if scene.metadata else {}
    ys = []
    for view, pose in zip(scene, poses):
        place = places.get(view.name)
        nominal = getattr(place, "nominal", None) if place is not None else None
        ys.append(float(nominal[1]) if nominal else float(pose[1]))
    return np.array(ys)


def scene_lines(scene: Scene, poses: np.ndarray) -> tuple[dict[int, BaseLine], np.ndarray]:
    """A scene's two base lines (:func:`davis_ag.robot.base_line.base_lines`) and the side
    (``+1``/``-1``) each view is served from.

    Args:
        scene: The scene.
        poses: Its views' poses (:func:`view_poses`).
    """
    meta = scene.metadata
    scenario = (meta.scenario if meta and meta.scenario else scene.scenario) or "sp"
    crop = (meta.crop if meta and meta.crop else scene.crop) or None
    lines = base_lines(scenario, crop, (float(poses[:, 0].min()), float(poses[:, 0].max())))
    return lines, np.array([side_of(y) for y in _nominal_y(scene, poses)])


def _visit_order(members: np.ndarray, pointers: np.ndarray, xs: np.ndarray) -> list[int]:
    """Breadth-first over the move graph (both directions) from the member nearest the middle x."""
    member = np.zeros(len(pointers), dtype=bool)
    member[members] = True
    neighbours: list[set[int]] = [set() for _ in range(len(pointers))]
    for i in members:
        for j in pointers[i]:
            if j >= 0 and member[j]:
                neighbours[i].add(int(j))
                neighbours[int(j)].add(int(i))
    order: list[int] = []
    seen = np.zeros(len(pointers), dtype=bool)
    middle = float(np.median(xs[members]))
    for start in sorted(members.tolist(), key=lambda i: (abs(xs[i] - middle), i)):
        if seen[start]:
            continue
        seen[start] = True
        queue = deque([start])
        while queue:
            i = queue.popleft()
            order.append(i)
            for j in sorted(neighbours[i]):
                if not seen[j]:
                    seen[j] = True
                    queue.append(j)
    return order


def home_configuration(robot: RobotModel, x: float, z: float) -> np.ndarray:
    """The robot's home pose beside a camera at ``(x, z)``: the lift as near ``z`` as it goes."""
    q = np.zeros(robot.model.nq)  # type: ignore[attr-defined]
    q[RAIL] = x
    q[LIFT] = np.clip(z - robot.definition.mount_height_m, robot.lower[LIFT], robot.upper[LIFT])
    home = robot.definition.home_q
    q[2:] = home if home is not None else np.clip(robot.locked[robot.free], robot.lower[2:], robot.upper[2:])
    return q


def compute_reach(
    scene: Scene, definition: RobotDefinition, progress: Callable[[int, int], None] | None = None
) -> SceneReach:
    """Solve every view of a scene for one robot (see the module docstring).

    Args:
        scene: A generated scene (poses, pointers, depth and class images, scene.json).
        definition: The robot.
        progress: Called with ``(views done, views)`` as the work goes on.

    Returns:
        The :class:`SceneReach`.
    """
    views = list(scene)
    n = len(views)
    poses = view_poses(scene)
    pointers = pointer_table(scene)
    meta = scene.metadata
    lines, sides = scene_lines(scene, poses)
    obstacles = trunk_points(scene)
    seed = int(meta.seed) if meta and meta.seed is not None else 0
    robots = {side: build_robot(definition, lines[side], obstacles) for side in (-1, 1)}
    q = np.full((n, robots[1].model.nq), np.nan)  # type: ignore[attr-defined]
    blocked = np.ones(n, dtype=np.uint8)
    done = 0
    for side_index, side in enumerate((-1, 1)):
        members = np.flatnonzero(sides == side)
        if not len(members):
            continue
        robot = robots[side]
        rng = stream_rng(seed, REACH_STREAM, side_index)
        for i in _visit_order(members, pointers, poses[:, 0]):
            near = [int(j) for j in pointers[i] if j >= 0 and not np.isnan(q[j, 0])]
            near.sort(key=lambda j: float(np.linalg.norm(poses[j, :3] - poses[i, :3])))
            seeds = [q[j] for j in near] + [home_configuration(robot, poses[i, 0], poses[i, 2])]
            seeds += random_seeds(robot, poses[i, 0], RESTARTS, rng)
            solution = reach_pose(robot, view_placement(poses[i]), seeds)
            if solution.ok:
                q[i], blocked[i] = solution.q, 0
            elif solution.blocked is not None:
                blocked[i] = BLOCKED.index(solution.blocked)
            done += 1
            if progress is not None:
                progress(done, n)
    reachable = blocked == 0
    urdf_q = np.full((n, len(robots[1].locked)), np.nan)
    mount = np.full((n, 4, 4), np.nan)
    seconds = np.full(pointers.shape, np.nan, dtype=np.float32)
    for i in np.flatnonzero(reachable).tolist():
        mover = robots[int(sides[i])]
        urdf_q[i] = mover.urdf_q(q[i])
        mount[i] = mover.mount(q[i])
        for j, target in enumerate(pointers[i]):
            if target >= 0 and reachable[target]:
                seconds[i, j] = move_seconds(mover, q[i], q[target])
    return SceneReach(
        definition.name,
        definition.digest,
        tuple(v.name for v in views),
        reachable,
        blocked,
        q,
        urdf_q,
        mount,
        seconds,
        len(obstacles),
    )


def scene_digest(scene: Scene) -> str:
    """SHA-256 of the scene's annotations.json: the reach cache's key (poses and pointers)."""
    return hashlib.sha256(scene.annotations_path.read_bytes()).hexdigest()


def reach_path(scene: Scene, root: Path, definition: RobotDefinition, cache_dir: str | os.PathLike[str] | None) -> Path:
    """Where a scene's reach for a robot is cached (see the module docstring)."""
    base = Path(cache_dir) if cache_dir is not None else Path(root) / CACHE_FOLDER
    return base / ".reach" / f"{definition.name}-{definition.digest}" / f"{scene.id}.npz"


_FIELDS = ("reachable", "blocked", "q", "urdf_q", "mount", "seconds")


def _load(path: Path, key: str) -> SceneReach | None:
    try:
        with np.load(path, allow_pickle=False) as saved:
            meta = json.loads(str(saved["meta"]))
            if meta.get("key") != key:
                return None
            arrays = {f: saved[f] for f in _FIELDS}
            return SceneReach(
                robot=meta["robot"],
                digest=meta["digest"],
                view_names=tuple(meta["views"]),
                obstacle_points=int(meta["obstacle_points"]),
                **arrays,
            )
    except (OSError, ValueError, KeyError):
        return None


def load_reach(
    scene: Scene,
    root: Path,
    robot: str | RobotDefinition,
    cache_dir: str | os.PathLike[str] | None = None,
    progress: Callable[[int, int], None] | None = None,
) -> SceneReach:
    """A scene's reach for a robot: from the cache, else computed and cached.

    Args:
        scene: A generated scene.
        root: Its dataset's root.
        robot: A robot name or YAML path, or a definition.
        cache_dir: Base folder of the caches (default ``<root>/.davis_ag_cache``).
        progress: As :func:`compute_reach`'s, when it must be computed.

    Returns:
        The :class:`SceneReach`.

    Raises:
        UserError: when the cache folder cannot be written.
    """
    definition = load_robot(robot) if isinstance(robot, str) else robot
    path = reach_path(scene, root, definition, cache_dir)
    key = f"{REACH_VERSION}:{scene_digest(scene)}"
    found = _load(path, key) if path.is_file() else None
    if found is not None:
        return found
    reach = compute_reach(scene, definition, progress)
    meta = {
        "key": key,
        "robot": reach.robot,
        "digest": reach.digest,
        "views": list(reach.view_names),
        "obstacle_points": reach.obstacle_points,
    }
    try:
        path.parent.mkdir(parents=True, exist_ok=True)
        with atomic_output(path) as handle:
            np.savez_compressed(handle, meta=np.array(json.dumps(meta)), **{f: getattr(reach, f) for f in _FIELDS})
    except OSError as error:
        raise UserError(
            f"cannot write the reach cache {path}: {error.strerror}; pass a writable --cache-dir"
        ) from error
    return reach

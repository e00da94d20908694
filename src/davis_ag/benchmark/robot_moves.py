"""TVM-v0 with a robot: the grid's moves restricted to the views a robot reaches, and their seconds.

With ``robot=`` (:class:`davis_ag.benchmark.tvm.TVMEnv`), each scene's reach
(:func:`davis_ag.robot.reach.load_reach`, cached) turns every pointer into or out of a view the
robot cannot reach into "" in the environment's copy of the scene's tables: such a move is
refused as a move off the grid is, and the exact Oracle, the Best fixed action and every
baseline play the restricted grid with no change of their own. Starts are drawn only from
reachable views. Each move the robot makes costs the seconds of its configurations
(:func:`davis_ag.robot.ik.move_seconds`); a refused move costs none.

Every step's ``info["robot"]`` holds what anyone can check with pinocchio on the URDF alone:
``name``, ``urdf``, ``digest``, ``mount`` (4x4 world-from-arm-base), ``q`` (the arm's joints in the
URDF model's order), ``tool_frame``, ``camera_in_tool`` (4x4, OpenCV camera axes), ``seconds``
(this step's move) and ``seconds_total`` (the episode's so far).
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from davis_ag.benchmark.cache import SceneCache
from davis_ag.errors import UserError

if TYPE_CHECKING:
    from davis_ag.data.reader import Scene
    from davis_ag.robot.definitions import RobotDefinition
    from davis_ag.robot.reach import SceneReach


def restrict(cache: SceneCache, reach: SceneReach) -> SceneCache:
    """A scene's tables with every pointer into or out of an unreachable view made "" (-1).

    Raises:
        UserError: when the reach was computed for other views (a stale cache).
    """
    if tuple(reach.view_names) != tuple(cache.view_names):
        raise UserError(
            f"the reach of {cache.scene_id} lists other views than its annotations; delete the .reach cache folder and retry"
        )
    ok = reach.reachable
    pointers = np.array(cache.pointers)
    pointers[~ok] = -1
    pointers[(pointers >= 0) & ~ok[np.maximum(pointers, 0)]] = -1
    return dataclasses.replace(cache, pointers=pointers)


@dataclass
class RobotOnGrid:
    """A robot's reach of every scene of an environment, and what its steps report.

    Attributes:
        definition: The robot.
        reaches: One :class:`davis_ag.robot.reach.SceneReach` per environment scene.
        camera_in_tool: The camera's 4x4 placement in the tool frame (as a nested list).
    """

    definition: RobotDefinition
    reaches: list[SceneReach]
    camera_in_tool: list[list[float]]

    def record(self) -> dict[str, str]:
        """What a results file records of the robot: name, definition digest and URDF."""
        return self.definition.results_record()

    def seconds(self, scene: int, view: int, column: int) -> float:
        """Seconds of the move from ``view`` along pointer column ``column`` (the robot reaches both)."""
        return float(self.reaches[scene].seconds[view, column])

    def info(self, scene: int, view: int, seconds: float, total: float) -> dict[str, Any]:
        """``info["robot"]`` at ``view`` of ``scene`` (see the module docstring)."""
        reach = self.reaches[scene]
        return self.definition.step_info(self.camera_in_tool, reach.mount[view], reach.urdf_q[view], seconds, total)


def attach_robot(
    robot: str,
    scenes: list[Scene],
    caches: list[SceneCache],
    root: Path,
    cache_dir: Any,
) -> tuple[RobotOnGrid, list[SceneCache]]:
    """Load (or compute) every scene's reach and restrict its tables.

    Args:
        robot: A robot name or YAML file.
        scenes: The environment's scenes.
        caches: Their observation caches, in the same order.
        root: The dataset root.
        cache_dir: The caches' base folder (``None``: the dataset's own).

    Returns:
        The robot and the restricted tables.
    """
    from davis_ag.robot.definitions import load_robot
    from davis_ag.robot.model import camera_in_tool
    from davis_ag.robot.reach import load_reach

    definition = load_robot(robot)
    reaches = [load_reach(scene, root, definition, cache_dir) for scene in scenes]
    restricted = [restrict(cache, reach) for cache, reach in zip(caches, reaches)]
    return RobotOnGrid(definition, reaches, camera_in_tool(definition).homogeneous.tolist()), restricted


def no_reachable_start(robot: RobotOnGrid, scenes: list[Scene], split: str, root: Path) -> UserError:
    """The one line for a robot that reaches no eligible start: the heights it does reach."""
    from davis_ag.robot.reach import view_poses

    heights = sorted(
        {
            round(float(pose[2]), 2)
            for scene, reach in zip(scenes, robot.reaches)
            for pose, ok in zip(view_poses(scene), reach.reachable)
            if ok
        }
    )
    reached = f"camera heights {', '.join(f'{h:g}' for h in heights)} m" if heights else "no view at all"
    return UserError(
        f"robot {robot.definition.name} reaches no eligible start in the {split} split of {root} "
        f"(it reaches {reached}); use a robot with a lift (davis-ag robots) or another scenario"
    )

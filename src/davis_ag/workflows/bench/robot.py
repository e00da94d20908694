"""``davis-ag bench --only robot``: what a robot costs: the reach of a row scene, and a grid step with it.

An apple-wall row (the scene docs/robot.md shows: dataset seed 5, 320x180) is drawn here; then,
in this process, each built-in robot's reach of it is computed from nothing (no cache: the IK of
every view, the trunk obstacles and the move seconds), and TVM-v0 steps with random moves and
resets are timed without a robot and with ``ur10-lift`` (its reach loaded from the cache), the
same actions on both: the step's cost is the ratio of the two, read in the same process.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.atomic_files import write_marked_section
from davis_ag.workflows.bench.report import doc_section

#: The scene: docs/robot.md's apple-wall row.
CROP, SCENARIO = "apple-wall", "row"
SEED = 5
SIZE = (320, 180)
#: Steps timed each way, and the robot the step is timed with.
STEPS = 20_000
STEP_ROBOT = "ur10-lift"
#: The issue's targets: a 1,536-view row's reach in at most this many seconds; a step at most this
#: many microseconds slower with a robot.
REACH_TARGET_S = 30.0
STEP_TARGET_US = 100.0


def steps_per_second(env: Any, actions: np.ndarray) -> float:
    """Steps a second of a discrete environment playing ``actions``, resetting at each episode's end."""
    env.reset(seed=0)
    began = time.perf_counter()
    for action in actions:
        if env.step(int(action))[2]:
            env.reset()
    return len(actions) / (time.perf_counter() - began)


def robot_speed(scratch: Path) -> dict[str, Any]:
    """Draw the row, then time each robot's reach and the grid step with and without a robot.

    Returns:
        The views, each robot's reach (seconds, share, per view), and the two step rates.
    """
    from davis_ag.benchmark import TVMEnv
    from davis_ag.data.reader import open_dataset
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.robot.definitions import builtin_robots, load_robot
    from davis_ag.robot.reach import compute_reach, load_reach
    from davis_ag.scene.camera import Camera
    from davis_ag.scene.specs import CROPS, scenario_spec
    from davis_ag.workflows.stages import generate_scenes

    crop = CROPS[CROP]
    root = scratch / "robot"
    generate_scenes([SceneRequest(scenario_spec(SCENARIO, crop), crop, 0, SEED, Camera(*SIZE))], root, progress=False)
    scene = next(iter(open_dataset(root)))
    reaches = {}
    for name in builtin_robots():
        began = time.perf_counter()
        reach = compute_reach(scene, load_robot(name))
        seconds = time.perf_counter() - began
        reaches[name] = {
            "seconds": round(seconds, 1),
            "ms_per_view": round(seconds / len(reach.reachable) * 1000, 1),
            "reached": round(reach.share, 3),
            "for_1536_views_s": round(seconds / len(reach.reachable) * 1536, 1),
        }
    load_reach(scene, root, STEP_ROBOT)  # the step loads its reach from the cache, as a user's does
    free = TVMEnv(root, SCENARIO, split="all")
    robot = TVMEnv(root, SCENARIO, split="all", robot=STEP_ROBOT)
    actions = np.random.default_rng(0).integers(len(free.action_names), size=STEPS)
    without = steps_per_second(free, actions)
    with_robot = steps_per_second(robot, actions)
    return {
        "scene": scene.id,
        "views": len(scene),
        "reach": reaches,
        "step_robot": STEP_ROBOT,
        "steps": STEPS,
        "steps_per_second_without": round(without, 0),
        "steps_per_second_with": round(with_robot, 0),
        "step_us_added": round((1 / with_robot - 1 / without) * 1e6, 1),
    }


def robot_table(result: dict[str, Any], load: tuple[float, float]) -> str:
    """The reach times and the step rates as Markdown."""
    rows = "\n".join(
        f"| {name} | {r['seconds']} | {r['ms_per_view']} | {r['for_1536_views_s']} | {r['reached'] * 100:.1f} % |"
        for name, r in result["reach"].items()
    )
    return (
        f"{result['scene']} ({result['views']} views, {SIZE[0]}x{SIZE[1]}, dataset seed {SEED}), drawn in this "
        f"run; load average {load[0]:.2f} at the start, {load[1]:.2f} at the end, {os.cpu_count()} CPUs.\n\n"
        f"| robot | reach, s | ms a view | a 1,536-view row, s (target {REACH_TARGET_S:g}) | views reached |\n"
        "|---|---|---|---|---|\n"
        f"{rows}\n\n"
        f"TVM-v0, {result['steps']:,} random moves and resets: {result['steps_per_second_without']:,.0f} steps/s "
        f"without a robot, {result['steps_per_second_with']:,.0f} with {result['step_robot']}: "
        f"**{result['step_us_added']} us** more a step (target at most {STEP_TARGET_US:g} us)."
    )


def write_robot(result: dict[str, Any], load: tuple[float, float], doc: Path | None, gpu_machine: bool = False) -> None:
    """Write the table into the doc's robot section."""
    if doc:
        write_marked_section(doc, doc_section("bench-robot", gpu_machine), robot_table(result, load))

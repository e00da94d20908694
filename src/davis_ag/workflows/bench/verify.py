"""``davis-ag bench --only verify``: how fast a leaderboard maintainer checks a results file.

Section V-D's protocol (3 sessions x 200 episodes) with eight policies (the grid's five baselines
and three fixed moves) is evaluated on a single-plant strawberry scene drawn here; then the two
checks every reader and ``davis-ag verify`` run are timed: every summary made again from the
episodes (:func:`davis_ag.benchmark.summaries.check_summaries`, paired-gap bootstraps included)
and every episode replayed on the dataset (:func:`davis_ag.benchmark.replay.replay_grid`).
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import write_marked_section
from davis_ag.workflows.bench.report import doc_section

#: The dataset seed and the image size of the scene the checks are timed on.
SEED = 0
SIZE = (160, 90)
#: The protocol timed: section V-D's.
SESSIONS, EPISODES = 3, 200
#: Fixed moves played beside the baselines, for the eight policies the issue names.
MOVES = ("up", "down", "left")


def always_up(observation: Any, info: dict[str, Any]) -> str:
    """Always up (a module-level function, so ``verify --policy`` can name it as code to re-run)."""
    return "up"


def always_down(observation: Any, info: dict[str, Any]) -> str:
    """Always down."""
    return "down"


def always_left(observation: Any, info: dict[str, Any]) -> str:
    """Always left."""
    return "left"


#: The fixed moves' policies, by name, as a SPEC names them.
FIXED = {f"always_{move}": f"{__name__}:always_{move}" for move in MOVES}


def verify_speed(scratch: Path) -> dict[str, Any]:
    """Draw the scene, evaluate, then time the summary check and the replay.

    Returns:
        The episodes and policies checked, the seconds of each check and the episodes per second.
    """
    from davis_ag.benchmark import evaluate
    from davis_ag.benchmark.replay import replay_grid
    from davis_ag.benchmark.results import load_results
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.scene.camera import Camera
    from davis_ag.scene.specs import CROPS, scenario_spec
    from davis_ag.workflows.stages import generate_scenes
    from davis_ag.workflows.stages.rerun import rerun_row

    crop = CROPS["strawberry"]
    root = scratch / "verify"
    generate_scenes([SceneRequest(scenario_spec("sp", crop), crop, 0, SEED, Camera(*SIZE))], root)
    began = time.perf_counter()
    results = evaluate(list(FIXED.values()), root, "sp", split="all", sessions=SESSIONS, episodes=EPISODES, seed=SEED)
    evaluated = time.perf_counter() - began
    path = results.write(scratch / "results.json")
    began = time.perf_counter()
    load_results(path)
    summaries = time.perf_counter() - began
    report = replay_grid(load_results(path, check=False), root, str(path))
    if not report.sound:  # a bench of a check that fails measures nothing
        raise RuntimeError(report.text())
    name, spec = next(iter(FIXED.items()))
    rerun = rerun_row(path, results, root, name, spec)
    if not rerun.sound:
        raise RuntimeError(rerun.text())
    return {
        "policies": report.policies,
        "episodes": report.episodes,
        "starts": results.protocol.starts,
        "evaluate_s": round(evaluated, 2),
        "summaries_s": round(summaries, 2),
        "replay_s": round(report.seconds, 2),
        "summaries_episodes_per_second": round(report.episodes / summaries),
        "replay_episodes_per_second": round(report.episodes / report.seconds),
        "rerun_episodes": rerun.episodes,
        "rerun_s": round(rerun.seconds, 2),
        "rerun_episodes_per_second": round(rerun.episodes / rerun.seconds),
    }


def verify_table(result: dict[str, Any], load: tuple[float, float]) -> str:
    """The two checks' times as Markdown."""
    total = result["summaries_s"] + result["replay_s"]
    return (
        f"A results file of {result['policies']} policies x {SESSIONS} sessions x {EPISODES} episodes "
        f"({result['episodes']:,} episodes) on a single-plant strawberry scene at {SIZE[0]}x{SIZE[1]} "
        f"({result['starts']} eligible starts), seed {SEED}; load average {load[0]:.2f} at the start, "
        f"{load[1]:.2f} at the end, {os.cpu_count()} CPUs.\n\n"
        "| check | seconds | episodes/s |\n"
        "|---|---|---|\n"
        f"| every summary made again from the episodes (`compare`, `plot`, `verify`) | {result['summaries_s']} | "
        f"{result['summaries_episodes_per_second']:,} |\n"
        f"| every episode replayed on the dataset (`verify --dataset`) | {result['replay_s']} | "
        f"{result['replay_episodes_per_second']:,} |\n"
        f"| both (the evaluation itself took {result['evaluate_s']} s) | {round(total, 2)} | "
        f"{round(result['episodes'] / total):,} |"
        + (
            f"\n| one row's {result['rerun_episodes']:,} episodes played again with its code "
            f"(`verify --policy always_up=...`) | {result['rerun_s']} | {result['rerun_episodes_per_second']:,} |"
            if "rerun_s" in result
            else ""
        )
    )


def write_verify(
    result: dict[str, Any], load: tuple[float, float], doc: Path | None, gpu_machine: bool = False
) -> None:
    """Write the table into the doc's verify section."""
    if doc:
        write_marked_section(doc, doc_section("bench-verify", gpu_machine), verify_table(result, load))

"""``davis-ag bench --only mapping``: what row mapping costs: a step beside TVM-v0's, the coverage
update alone, and the segment's ceiling and the budget's bound of a row scene.

The apple-wall row docs/robot.md and docs/mapping.md show (dataset seed 5, 320x180) is drawn here;
then, in this process, RowMapping-v0 and TVM-v0 play the same random moves with resets (TVM's
``done`` left out of its draw, so both move every step), and the coverage update of a mapping step
(the fruit a view sees first, the memory channel's dots) is timed alone on the same views: the issue's
target is a mapping step no slower than a TVM-v0 step plus that update. The segment's tables (which
view sees which fruit, from scene.json), the grid's exact ceiling and each alley's bound at the
default budget are timed from nothing.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.atomic_files import write_marked_section
from davis_ag.workflows.bench.report import doc_section
from davis_ag.workflows.bench.robot import steps_per_second

#: The scene: docs/robot.md's apple-wall row.
CROP, SCENARIO = "apple-wall", "row"
SEED = 5
SIZE = (320, 180)
#: Steps timed each way.
STEPS = 20_000


def _update_us(env: Any, views: np.ndarray) -> float:
    """Microseconds of a mapping step's coverage update alone, over ``views`` in turn."""
    coverage, plan = env.coverage[0], env._plans[0]
    seen = np.zeros(coverage.fruit, dtype=bool)
    seen_ids: list[int] = []
    canvas = np.zeros((224, 224), dtype=np.uint8)
    began = time.perf_counter()
    for i, view in enumerate(views):
        if i % 25 == 0:  # an episode of the default budget
            seen[:], seen_ids = False, []
        fresh = coverage.seen[view] & ~seen
        if int(fresh.sum()):
            seen |= fresh
            seen_ids = sorted(seen_ids + coverage.fruit_ids[fresh].tolist())
            for r, c in plan.dots[fresh]:
                canvas[r : r + 2, c : c + 2] = 192
        _ = list(seen_ids), len(seen_ids) / coverage.fruit
    return (time.perf_counter() - began) / len(views) * 1e6


def mapping_speed(scratch: Path) -> dict[str, Any]:
    """Draw the row, then time the steps, the update, the tables, the ceiling and the bound.

    Returns:
        The views and fruit, the step rates, the update's cost and the tables' seconds.
    """
    from davis_ag.benchmark import TVMEnv
    from davis_ag.benchmark.cache import load_scene_cache
    from davis_ag.data.reader import open_dataset
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.mapping.bound import best_views
    from davis_ag.mapping.coverage import segment_coverage
    from davis_ag.mapping.env import RowMappingEnv
    from davis_ag.scene.camera import Camera
    from davis_ag.scene.specs import CROPS, scenario_spec
    from davis_ag.workflows.stages import generate_scenes

    crop = CROPS[CROP]
    root = scratch / "mapping"
    generate_scenes([SceneRequest(scenario_spec(SCENARIO, crop), crop, 0, SEED, Camera(*SIZE))], root, progress=False)
    scene = next(iter(open_dataset(root)))
    cache = load_scene_cache(scene, root)
    began = time.perf_counter()
    coverage = segment_coverage(scene, cache, cache.pointers)
    tables_s = time.perf_counter() - began
    began = time.perf_counter()
    ceiling = float(coverage.seen.any(axis=0).mean())
    ceiling_s = time.perf_counter() - began
    mapping = RowMappingEnv(root, SCENARIO, split="all")
    tvm = TVMEnv(root, SCENARIO, split="all")
    moves = np.random.default_rng(0).integers(len(mapping.action_names), size=STEPS)
    tvm_rate, mapping_rate = steps_per_second(tvm, moves), steps_per_second(mapping, moves)
    update = _update_us(mapping, np.random.default_rng(1).integers(cache.n_views, size=STEPS))
    bounds = []
    for part in np.unique(coverage.part):
        began = time.perf_counter()
        bound = best_views(coverage.seen[coverage.part_views(int(part))], mapping.budget + 1)
        bounds.append({"seconds": round(time.perf_counter() - began, 2), "fruit": bound.fruit, "exact": bound.exact})
    return {
        "scene": scene.id,
        "views": cache.n_views,
        "fruit": coverage.fruit,
        "steps": STEPS,
        "tvm_steps_per_second": round(tvm_rate, 0),
        "mapping_steps_per_second": round(mapping_rate, 0),
        "tvm_step_us": round(1e6 / tvm_rate, 1),
        "mapping_step_us": round(1e6 / mapping_rate, 1),
        "update_us": round(update, 1),
        "tables_s": round(tables_s, 3),
        "ceiling_s": round(ceiling_s, 5),
        "ceiling": round(ceiling, 3),
        "budget": mapping.budget,
        "bounds": bounds,
    }


def mapping_table(result: dict[str, Any], load: tuple[float, float]) -> str:
    """The rates and the tables' seconds as Markdown."""
    target = result["tvm_step_us"] + result["update_us"]
    verdict = "within" if result["mapping_step_us"] <= target else "over"
    bounds = ", ".join(
        f"{b['seconds']} s ({b['fruit']} fruit, {'exact' if b['exact'] else 'bound'})" for b in result["bounds"]
    )
    return (
        f"{result['scene']} ({result['views']:,} views, {result['fruit']} fruit on its segment, {SIZE[0]}x{SIZE[1]}, "
        f"dataset seed {SEED}), drawn in this run; load average {load[0]:.2f} at the start, {load[1]:.2f} at the "
        f"end, {os.cpu_count()} CPUs.\n\n"
        "| | us a step | steps/s |\n|---|---|---|\n"
        f"| TVM-v0 | {result['tvm_step_us']} | {result['tvm_steps_per_second']:,.0f} |\n"
        f"| RowMapping-v0 | {result['mapping_step_us']} | {result['mapping_steps_per_second']:,.0f} |\n"
        f"| the coverage update alone | {result['update_us']} | - |\n\n"
        f"{result['steps']:,} random moves and resets each. A mapping step costs {result['mapping_step_us']} us, "
        f"{verdict} TVM-v0's step plus the coverage update ({target:.1f} us, the target). The segment's tables "
        f"from scene.json: {result['tables_s']} s; the grid's exact ceiling ({result['ceiling']}): "
        f"{result['ceiling_s'] * 1000:.2f} ms; each alley's bound at the default budget of {result['budget']} moves: "
        f"{bounds}."
    )


def write_mapping(
    result: dict[str, Any], load: tuple[float, float], doc: Path | None, gpu_machine: bool = False
) -> None:
    """Write the table into the doc's mapping section."""
    if doc:
        write_marked_section(doc, doc_section("bench-mapping", gpu_machine), mapping_table(result, load))

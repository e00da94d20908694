"""``davis-ag bench`` (``make bench``): what a labelled view costs with our renderer, against pyhelios's
documented path on a stock Helios Visualizer, and what the paper-scale dataset would take.

For each crop (a single-plant strawberry and a single goblet vine, dataset seed 0, scene 0, at
1280x720), the scene is grown once and the same views are timed on three paths, interleaved
(ours, documented, floor; again; again), each repetition's first view untimed:

- ours: the real generate path (:func:`davis_ag.generate.one_scene.draw_scene`: our OpenGL renderer
  draws colour, ids and depth, then labels, visible fractions, JPEG, segmentation PNG, depth PNG,
  annotations and the atomic publish), seconds per view from the first view done to the scene
  published, so writes still queued at the end are paid for;
- documented: pyhelios as its documentation shows, on a stock Visualizer (the one
  :class:`davis_ag.render.helios.HeliosRenderer` sets up): ``printWindow`` to a JPEG, then
  ``writeImageBoundingBoxes`` and ``writeImageSegmentationMasks``, fruit labelled with object data;
- floor: our renderer's draw and read-back alone (colour, ids, depth), nothing else;
- no classes: ours without the organ class images (``NNNN_class.png``), to price that label:
  it is a look-up on the id image the same pass drew, not a second render.

Per path the median over repetitions of the mean seconds per view is reported. With strawberry,
also the grid environment's steps/s, TVMContinuous-v0's at 224x224 (``--only continuous``
measures only the latter, in about a minute) and each learner's training steps/s
(:mod:`davis_ag.workflows.bench.training`, ``--only training``). Then the hours the
``paper`` preset would take on one machine like this one and on a Ray cluster of such machines.
With ``--doc docs/performance.md`` the tables are written into that file between its
``<!-- bench:start -->`` and ``<!-- bench:end -->`` markers.
"""

from __future__ import annotations

import dataclasses
import os
import platform
import statistics
import tempfile
import time
from functools import partial
from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.atomic_files import write_json_atomic
from davis_ag.benchmark.cache import OBS_SIZE
from davis_ag.errors import UserError
from davis_ag.formats.layout import view_name, view_stem
from davis_ag.generate.one_scene import SceneRequest, draw_scene, grow_scene
from davis_ag.generate.run_progress import count_views
from davis_ag.render.egl_context import renderer_name
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CROPS, SCENARIOS
from davis_ag.scene.view_grid import Viewpoint
from davis_ag.workflows.bench.report import (
    PAPER_HOURS_TARGET,
    SEED,
    TARGETS,
    continuous_table,
    projection,
    write_continuous,
)
from davis_ag.workflows.bench.timing import time_loop, time_ours
from davis_ag.workflows.bench.training import training_speed, training_table, write_training

CAMERA = Camera(1280, 720)
#: Views timed per crop: the strawberry's grid every 0.5 m at the middle altitude, the others'
#: every 1 m at the lowest (the first ``VIEWS`` of each).
GRIDS = {
    "strawberry": dataclasses.replace(SCENARIOS["sp"], extent=(2.5, 3.0), step=0.5, altitude_levels=(1,)),
    "tomato": dataclasses.replace(SCENARIOS["sp"], step=1.0, altitude_levels=(0,)),
    "vine": dataclasses.replace(SCENARIOS["sp"], step=1.0, altitude_levels=(0,)),
}
VIEWS = {"strawberry": 12, "tomato": 8, "vine": 8}
REPEATS = 3


def bench_crop(
    crop: str,
    scratch: Path,
    repeats: int,
    documented: bool = True,
    antialiasing: str = "fxaa",
    camera: Camera = CAMERA,
    view_count: int | None = None,
) -> dict:
    """Grow one scene and time ours, the documented path and the floor on the same views.

    Args:
        crop: The crop (its :data:`GRIDS` scene).
        scratch: A folder for what the paths write.
        repeats: Interleaved repetitions.
        documented: Time pyhelios's documented path too.
        antialiasing: Our renderer's.
        camera: The image size (the bench's: 1280x720; tests: smaller).
        view_count: Views timed (default :data:`VIEWS` of the crop), the first of each repetition untimed.
    """
    from davis_ag.render.helios import HeliosRenderer
    from davis_ag.render.opengl import OpenGLRenderer

    request = SceneRequest(GRIDS[crop], CROPS[crop], 0, SEED, camera, antialiasing=antialiasing)
    started = time.perf_counter()
    model, grid = grow_scene(request)
    grow_s = time.perf_counter() - started
    views = list(grid.viewpoints[: view_count or VIEWS[crop]])
    for fruit in model.fruits:  # the documented route labels fruit with object data (a cluster: its berries)
        for object_id in {model.context.getPrimitiveParentObjectID(int(u)) for u in fruit.uuids}:
            model.context.setObjectDataInt(object_id, "fruit_id", fruit.id)
    images = scratch / f"{crop}-documented"
    images.mkdir(parents=True)
    times: dict[str, list[float]] = {"ours": [], "documented": [], "floor": [], "no_classes": []}
    setup: list[float] = []
    helios = HeliosRenderer(model.context, request.camera, model.lighting) if documented else None
    ours_renderer = OpenGLRenderer(model.context, request.camera, model.lighting, antialiasing=antialiasing)
    try:

        def documented_view(view: Viewpoint) -> None:
            assert helios is not None  # timed only with the documented renderer
            name = view_name(view.number)
            helios.set_view(view)
            jpeg = str(images / name)
            helios._vis.printWindow(jpeg)
            helios._vis.writeImageBoundingBoxes(
                object_data_labels="fruit_id", object_class_ids=0, image_file=name, image_path=str(images)
            )
            helios._vis.writeImageSegmentationMasks(
                object_data_labels="fruit_id",
                object_class_ids=0,
                json_filename=str(images / f"{view_stem(name)}.json"),
                image_file=jpeg,
            )

        for repeat in range(repeats):
            per_view, before = time_ours(request, model, grid, views, scratch / f"{crop}-ours-{repeat}")
            times["ours"].append(per_view)
            setup.append(before)
            if helios is not None:
                times["documented"].append(time_loop(views, documented_view))
            times["floor"].append(time_loop(views, lambda v: ours_renderer.render(v)))
            no_classes = dataclasses.replace(request, classes=False)
            times["no_classes"].append(time_ours(no_classes, model, grid, views, scratch / f"{crop}-plain-{repeat}")[0])
    finally:
        ours_renderer.close()
        if helios is not None:
            helios.close()
    median = {path: statistics.median(values) for path, values in times.items() if values}
    result = {
        "views_timed": len(views) - 1,
        "repeats": repeats,
        "primitives": len(model.context.getAllUUIDs()),
        "grow_s": round(grow_s, 2),
        "setup_and_first_view_s": round(statistics.median(setup), 2),
        "seconds_per_view": median,
        "all_repeats": times,
    }
    result["classes_cost"] = median["ours"] / median["no_classes"]
    if "documented" in median:
        result["documented_over_ours"] = median["documented"] / median["ours"]
        result["ours_over_floor"] = median["ours"] / median["floor"]
    return result


def pool_gain(scratch: Path) -> dict:
    """How many more views two scene processes (the default ``--workers`` here) make than one
    process drawing with every core: the same two single-plant strawberry scenes (seed 0, scenes
    0-1, the full grid) made by the runner with one worker and then with two, growing included."""
    from davis_ag.generate.run_progress import RunOptions
    from davis_ag.generate.runner import run_dataset
    from davis_ag.scene.specs import scenario_spec

    crop = CROPS["strawberry"]
    requests = [SceneRequest(scenario_spec("sp", crop), crop, index, SEED, CAMERA) for index in range(2)]
    seconds = {}
    for workers in (1, 2):
        start = time.perf_counter()
        run_dataset(requests, scratch / f"pool-{workers}", RunOptions(workers=workers, progress=False))
        seconds[workers] = time.perf_counter() - start
    return {
        "scenes": len(requests),
        "views": len(requests) * count_views(requests[0].scenario, crop),
        "seconds_one_worker": round(seconds[1], 1),
        "seconds_two_workers": round(seconds[2], 1),
        "gain": round(seconds[1] / seconds[2], 3),
    }


def env_speed(dataset: Path, steps: int = 20_000) -> dict:
    """Steps per second of the TVM environment on a scene just drawn (cache built first)."""
    import gymnasium

    from davis_ag.benchmark import TVM_ID, benchmark_steps

    try:
        env = gymnasium.make(TVM_ID, dataset=str(dataset), scenario="sp", split="all")
    except UserError as error:
        return {"skipped": str(error)}
    env.reset(seed=SEED)
    rate = benchmark_steps(env, steps, seed=SEED)
    env.close()
    return {"steps_per_second": round(rate), "steps": steps, "target_min": 5000}


#: TVMContinuous-v0's rate target at 224x224 on this 2-core machine (issue 14).
CONTINUOUS_TARGET = 50.0


def continuous_scene(root: Path) -> Path:
    """A single-plant strawberry scene (seed 0, scene 0, the crop's full grid area) with one view
    drawn and its geometry cached from the growth, so that reopening it live grows nothing."""
    from davis_ag.formats.layout import LIVE_GEOMETRY
    from davis_ag.generate.recorded_settings import read_settings
    from davis_ag.live.reopen import assets_from_model, cache_key, save_cache
    from davis_ag.scene.specs import scenario_spec

    crop = CROPS["strawberry"]
    request = SceneRequest(scenario_spec("sp", crop), crop, 0, SEED, Camera(320, 180))
    model, grid = grow_scene(request)
    scene_dir, _ = draw_scene(request, model, grid, root / "continuous", views=list(grid.viewpoints[:1]))
    save_cache(scene_dir / LIVE_GEOMETRY, cache_key(read_settings(scene_dir)), assets_from_model(model, grid))
    return scene_dir


def steps_per_second(env: Any, n: int = 500, seed: int = 0) -> dict[str, float]:
    """Measure environment steps per second with uniformly random actions, resets included (as in
    training); actions are drawn before the clock starts.

    Args:
        env: A TVMContinuous-v0 environment (wrapped or not).
        n: Steps to time.
        seed: Seeds the first reset and the action draw.

    Returns:
        ``steps_per_second`` (wall clock), ``cpu_ms_per_step`` (CPU time of every thread of the
        process, so less sensitive to other jobs on the machine), ``steps``, ``resets``,
        ``refused`` (share of refused moves), ``draws_per_step`` (views drawn per timed step,
        resets' included) and ``draws_per_reset`` (the random start's tries that were drawn).
    """
    actions = np.random.default_rng(seed).uniform(-1, 1, size=(n, env.action_space.shape[0])).astype(np.float32)
    env.reset(seed=seed)
    counted = env.unwrapped
    resets = refused = reset_draws = 0
    first_draw = counted.draws
    cpu = os.times()
    start = time.perf_counter()
    for action in actions:
        _, _, terminated, truncated, info = env.step(action)
        refused += bool(info["refused"])
        if terminated or truncated:
            before = counted.draws
            env.reset()
            reset_draws += counted.draws - before
            resets += 1
    seconds = time.perf_counter() - start
    used = os.times()
    cpu_s = (used.user - cpu.user) + (used.system - cpu.system)  # every thread, Mesa's included
    return {
        "steps_per_second": n / seconds,
        "cpu_ms_per_step": 1000 * cpu_s / n,
        "steps": n,
        "resets": resets,
        "refused": refused / n,
        "draws_per_step": (counted.draws - first_draw) / n,
        "draws_per_reset": reset_draws / max(resets, 1),
    }


#: The robot TVMContinuous-v0's rate is also timed with (docs/robot.md's target: 50 steps/s).
CONTINUOUS_ROBOT = "ur10-lift"


def continuous_env_speed(scratch: Path, steps: int = 600) -> dict:
    """Steps per second of TVMContinuous-v0 at 224x224 on a single-plant strawberry scene (the
    crop's full grid area; one view drawn, the geometry cached from the growth, so nothing
    regrows), random actions, resets included, without a robot and with :data:`CONTINUOUS_ROBOT`;
    and the time one 224x224 render takes."""
    from davis_ag.live.scene import merge_ground
    from davis_ag.live.tvm_continuous import TVMContinuousEnv

    scene_dir = continuous_scene(scratch)
    started = time.perf_counter()
    env = TVMContinuousEnv(scene_dir, "sp")
    env.reset(seed=SEED)  # the renderer's set-up (textures, shadow map) is paid here
    setup_s = time.perf_counter() - started
    try:
        view = env.scene.aimed_pose(1.0, -1.0, 0.4)
        env.scene.render(view, OBS_SIZE, OBS_SIZE, antialiasing="none", fractions=False, fast_ground=True, depth=False)
        begun = time.perf_counter()
        for _ in range(50):  # as the environment draws
            env.scene.render(
                view, OBS_SIZE, OBS_SIZE, antialiasing="none", fractions=False, fast_ground=True, depth=False
            )
        render_ms = (time.perf_counter() - begun) / 50 * 1000
        rate = steps_per_second(env, steps, seed=SEED)
    finally:
        env.close()
    # The same scene, seed and random actions with the camera on a robot (docs/robot.md).
    riding = TVMContinuousEnv(scene_dir, "sp", robot=CONTINUOUS_ROBOT)
    try:
        robot_rate = steps_per_second(riding, steps, seed=SEED)
    finally:
        riding.close()
    return {
        "steps_per_second": round(rate["steps_per_second"], 1),
        "cpu_ms_per_step": round(rate["cpu_ms_per_step"], 1),
        "steps": steps,
        "resets": rate["resets"],
        "refused_share": round(rate["refused"], 3),
        "render_and_label_ms": round(render_ms, 1),
        "draws_per_step": round(rate["draws_per_step"], 2),
        "draws_per_reset": round(rate["draws_per_reset"], 2),
        "open_and_first_reset_s": round(setup_s, 2),
        "target_min": CONTINUOUS_TARGET,
        "gl_renderer": renderer_name(),
        "triangles": int(env.scenes[0].assets.geometry.triangle_count),
        "triangles_drawn": int(merge_ground(env.scenes[0].assets.geometry).triangle_count),
        "robot": {
            "name": CONTINUOUS_ROBOT,
            "steps_per_second": round(robot_rate["steps_per_second"], 1),
            "cpu_ms_per_step": round(robot_rate["cpu_ms_per_step"], 1),
            "refused_share": round(robot_rate["refused"], 3),
        },
    }


def run_only(
    what: str,
    out: Path,
    doc: Path | None,
    devices: tuple[str, ...] = ("cpu",),
    gpu_machine: bool = False,
    crops: list[str] | None = None,
) -> dict:
    """One measurement alone (``--only continuous``: TVMContinuous-v0's rate, about a minute;
    ``--only training``: the learners' training rates, about 8 minutes, on each of ``devices``;
    ``--only crops``: the plant-library crops' SP and row scenes, :mod:`davis_ag.workflows.bench.crops`,
    ``crops`` of them, the others' rows kept from an earlier report at ``out``; ``--only verify``:
    how fast a results file is checked, :mod:`davis_ag.workflows.bench.verify`, about a minute;
    ``--only play``: a trained model's episodes one at a time and in step,
    :mod:`davis_ag.workflows.bench.play`, about a minute; ``--only robot``: the robots' reach of a row
    and the grid step with a robot, :mod:`davis_ag.workflows.bench.robot`, about five minutes;
    ``--only mapping``: a row-mapping step beside TVM-v0's and the segment's ceiling and bound,
    :mod:`davis_ag.workflows.bench.mapping`, about five minutes; ``--only sharing``: two trainings on
    one machine with torch's threads and with half the cores each, :mod:`davis_ag.workflows.bench.sharing`,
    about five minutes):
    JSON, the doc's section (its GPU section on a ``gpu_machine``) and the line another page shows
    of it."""
    from davis_ag.scene.library_crops import LIBRARY_CROPS
    from davis_ag.workflows.bench.crops import crops_speed, crops_table, merged, write_crops
    from davis_ag.workflows.bench.mapping import mapping_speed, mapping_table, write_mapping
    from davis_ag.workflows.bench.play import play_speed, play_table, write_play
    from davis_ag.workflows.bench.robot import robot_speed, robot_table, write_robot
    from davis_ag.workflows.bench.sharing import sharing_speed, sharing_table, write_sharing
    from davis_ag.workflows.bench.verify import verify_speed, verify_table, write_verify

    measurements: dict[str, tuple[str, Any, Any, Any]] = {
        "continuous": ("continuous_env", continuous_env_speed, continuous_table, write_continuous),
        "training": ("training", partial(training_speed, devices=devices), training_table, write_training),
        "crops": (
            "crops",
            lambda _scratch: merged(out, crops_speed(crops or list(LIBRARY_CROPS))),
            crops_table,
            write_crops,
        ),
        "verify": ("verify", verify_speed, verify_table, write_verify),
        "play": ("play", play_speed, play_table, write_play),
        "robot": ("robot", robot_speed, robot_table, write_robot),
        "mapping": ("mapping", mapping_speed, mapping_table, write_mapping),
        "sharing": ("sharing", sharing_speed, sharing_table, write_sharing),
    }
    key, measure, table_of, write = measurements[what]
    start = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="davis-ag-bench-") as scratch:
        result = measure(Path(scratch))
    load = (start, os.getloadavg()[0])
    print(table_of(result, load))
    out.parent.mkdir(parents=True, exist_ok=True)
    write_json_atomic(out, {key: result})
    write(result, load, doc, gpu_machine)
    return result


def training_devices() -> tuple[str, ...]:
    """The torch devices the whole bench times the learners on: the CPU, and CUDA where torch has it."""
    import torch

    return ("cpu", "cuda") if torch.cuda.is_available() else ("cpu",)


def fill_unmeasured_paper_crops(*costs: dict[str, float]) -> list[str]:
    """Give each of the paper's crops not measured this time (``bench --crops strawberry``) the
    slowest measured crop's cost in every one of ``costs``, for the paper preset's projection,
    which grows only the paper's crops.

    Returns:
        The crops so filled in, for the page to name.
    """
    assumed = [name for name, crop in CROPS.items() if crop.source != "library" and name not in costs[0]]
    for name in assumed:
        for cost in costs:
            cost[name] = max(cost.values())
    return assumed


def run(out: Path, crops: list[str], repeats: int, antialiasing: str = "fxaa") -> dict:
    """Run every measurement; return the JSON report."""
    load_start = os.getloadavg()
    report: dict = {
        "machine": {
            "cpus": os.cpu_count(),
            "platform": platform.platform(),
            "LP_NUM_THREADS": os.environ.get("LP_NUM_THREADS"),
            "gl_renderer": renderer_name(),
        },
        "image_size": [CAMERA.width, CAMERA.height],
        "seed": SEED,
        "antialiasing": antialiasing,
        "crops": {},
    }
    per_view: dict[str, float] = {}
    overhead: dict[str, float] = {}
    floor: dict[str, float] = {}
    grow: dict[str, float] = {}
    with tempfile.TemporaryDirectory(prefix="davis-ag-bench-") as scratch:
        for crop in crops:
            result = bench_crop(crop, Path(scratch), repeats, documented=crop in TARGETS, antialiasing=antialiasing)
            report["crops"][crop] = result
            per_view[crop] = result["seconds_per_view"]["ours"]
            overhead[crop] = result["grow_s"] + result["setup_and_first_view_s"]
            floor[crop] = result["seconds_per_view"]["floor"]
            grow[crop] = result["grow_s"]
        if "strawberry" in crops:
            report["env_steps_per_second"] = env_speed(Path(scratch) / "strawberry-ours-0")
            report["continuous_env"] = continuous_env_speed(Path(scratch))
            report["pool"] = pool_gain(Path(scratch))
            # On a GPU machine each learner is timed on the CPU and then on the GPU.
            report["training"] = training_speed(Path(scratch), devices=training_devices())
    report["scene_overhead_s"] = {k: round(v, 1) for k, v in overhead.items()}
    report["assumed_as_slowest"] = fill_unmeasured_paper_crops(per_view, overhead, floor, grow)
    report["paper_projection"] = projection(per_view, overhead, floor, grow, report.get("pool", {}).get("gain"))
    report["targets"] = {"documented_over_ours_min": TARGETS, "paper_hours_one_machine_max": PAPER_HOURS_TARGET}
    report["machine"]["load_average"] = {
        "start": [round(x, 2) for x in load_start],
        "end": [round(x, 2) for x in os.getloadavg()],
    }
    out.parent.mkdir(parents=True, exist_ok=True)
    write_json_atomic(out, report)
    return report

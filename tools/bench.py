"""``python tools/bench.py``: what a labelled view costs with our renderer, against pyhelios's
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
also the grid environment's steps/s and TVMContinuous-v0's at 224x224 (``--only continuous``
measures only the latter, in about a minute). Then the hours the
``paper`` preset would take on one machine like this one and on a Ray cluster of such machines.
With ``--doc docs/performance.md`` the tables are written into that file between its
``<!-- bench:start -->`` and ``<!-- bench:end -->`` markers.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import platform
import statistics
import tempfile
import time
from pathlib import Path
from typing import Callable

from davis_ag.atomic_files import write_marked_section
from davis_ag.errors import UserError
from davis_ag.generate.one_scene import SceneRequest, draw_scene, grow_scene
from davis_ag.generate.run_config import load_dataset_config
from davis_ag.generate.run_progress import count_views
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CROPS, SCENARIOS

SEED = 0
CAMERA = Camera(1280, 720)
#: Views timed per crop: the strawberry's grid every 0.5 m at the middle altitude, the others'
#: every 1 m at the lowest (the first ``VIEWS`` of each).
GRIDS = {"strawberry": dataclasses.replace(SCENARIOS["sp"], extent=(2.5, 3.0), step=0.5, altitude_levels=(1,)),
         "tomato": dataclasses.replace(SCENARIOS["sp"], step=1.0, altitude_levels=(0,)),
         "vine": dataclasses.replace(SCENARIOS["sp"], step=1.0, altitude_levels=(0,))}
VIEWS = {"strawberry": 12, "tomato": 8, "vine": 8}
TARGETS = {"strawberry": 10.0, "vine": 8.0}
REPEATS = 3
CLUSTER_MACHINES = 16
#: Scene processes per machine like this one (one per core) and the throughput two of them were
#: measured to give against one process drawing with both cores (docs/performance.md).
POOL_SLOTS = 2
POOL_GAIN = 1.18
PAPER_HOURS_TARGET = 24.0


def cpu_seconds() -> float:
    """CPU time of this process, every thread (Mesa's rasteriser threads included)."""
    times = os.times()
    return times.user + times.system


def time_loop(views: list, step: Callable[[object], None]) -> float:
    """Run ``step`` on every view; seconds per view of all but the first."""
    step(views[0])
    start = time.perf_counter()
    for view in views[1:]:
        step(view)
    return (time.perf_counter() - start) / (len(views) - 1)


def time_ours(request: SceneRequest, model, grid, views: list, root: Path) -> tuple[float, float]:
    """The generate path on the chosen views: seconds per view (views 2..n, publishing included)
    and the seconds before the first view was done (renderer set-up and the first view)."""
    marks: dict[str, float] = {}

    def on_view(done: int, total: int) -> None:
        if done == 1:
            marks["first"] = time.perf_counter()

    start = time.perf_counter()
    draw_scene(request, model, grid, root, on_view, views=views)
    end = time.perf_counter()
    return (end - marks["first"]) / (len(views) - 1), marks["first"] - start


def bench_crop(crop: str, scratch: Path, repeats: int, documented: bool = True, antialiasing: str = "fxaa") -> dict:
    """Grow one scene and time ours, the documented path and the floor on the same views."""
    from davis_ag.render.helios import HeliosRenderer
    from davis_ag.render.opengl import OpenGLRenderer

    request = SceneRequest(GRIDS[crop], CROPS[crop], 0, SEED, CAMERA, antialiasing=antialiasing)
    started = time.perf_counter()
    model, grid = grow_scene(request)
    grow_s = time.perf_counter() - started
    views = list(grid.viewpoints[: VIEWS[crop]])
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
        def documented_view(view) -> None:
            helios.set_view(view)
            jpeg = str(images / view.image_name)
            helios._vis.printWindow(jpeg)
            helios._vis.writeImageBoundingBoxes(object_data_labels="fruit_id", object_class_ids=0,
                                                image_file=view.image_name, image_path=str(images))
            helios._vis.writeImageSegmentationMasks(object_data_labels="fruit_id", object_class_ids=0,
                                                    json_filename=str(images / f"{view.image_name[:-5]}.json"),
                                                    image_file=jpeg)

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
    result = {"views_timed": len(views) - 1, "repeats": repeats, "primitives": len(model.context.getAllUUIDs()),
              "grow_s": round(grow_s, 2), "setup_and_first_view_s": round(statistics.median(setup), 2),
              "seconds_per_view": median, "all_repeats": times}
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
    return {"scenes": len(requests), "views": len(requests) * count_views(requests[0].scenario, crop),
            "seconds_one_worker": round(seconds[1], 1), "seconds_two_workers": round(seconds[2], 1),
            "gain": round(seconds[1] / seconds[2], 3)}


def projection(per_view: dict[str, float], overhead: dict[str, float], floor: dict[str, float] | None = None,
               grow: dict[str, float] | None = None, gain: float | None = None) -> dict:
    """Hours to make the ``paper`` preset on one machine and on a cluster of such machines.

    Each scene costs its views times the crop's seconds per view, plus the crop's per-scene
    overhead (growing, renderer set-up) times the plants it grows. One process is what was
    measured; the default ``--workers`` (one single-threaded process per core) is scaled by
    :data:`POOL_GAIN`. A cluster machine runs ``POOL_SLOTS`` scenes at once, each slot taking the
    longest scene left (longest-first list scheduling). With ``floor`` and ``grow`` (seconds per
    view of the draw and read-back alone, seconds to grow one plant), also the hours that growing
    plus drawing alone would take on one machine: what no work around the draw can go below.
    ``gain`` replaces :data:`POOL_GAIN` with a measured one (:func:`pool_gain`).
    """
    gain = gain or POOL_GAIN
    config = load_dataset_config("paper")
    durations: list[float] = []
    bound = 0.0
    images = 0
    for group in config.groups:
        views = count_views(group.scenario, group.crop)
        plants = 1 if group.scenario.name == "sp" else group.crop.mp_plants
        images += views * group.scenes
        durations += [views * per_view[group.crop.name] + overhead[group.crop.name] * plants] * group.scenes
        if floor and grow:
            bound += (views * floor[group.crop.name] + grow[group.crop.name] * plants) * group.scenes
    slots = [0.0] * (CLUSTER_MACHINES * POOL_SLOTS)
    for duration in sorted(durations, reverse=True):
        slots[slots.index(min(slots))] += duration * POOL_SLOTS / gain
    return {"images": images, "scenes": len(durations),
            "hours_one_machine_one_process": round(sum(durations) / 3600, 1),
            "hours_one_machine": round(sum(durations) / gain / 3600, 1),
            f"hours_{CLUSTER_MACHINES}_machines": round(max(slots) / 3600, 1),
            "target_hours_one_machine": PAPER_HOURS_TARGET,
            **({"hours_one_machine_grow_and_draw_only": round(bound / gain / 3600, 1)} if bound else {}),
            "assumptions": f"multi-plant views cost what single-plant views of the same crop cost (a lower "
                           f"bound: they draw 3-5 plants); growing costs the measured single-plant time per "
                           f"plant; {POOL_SLOTS} scene processes per machine make {gain:.2f}x the views of one "
                           + ("process (measured by this bench with our renderer)" if gain != POOL_GAIN
                              else "process (measured with Helios, docs/performance.md)")}


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
    from davis_ag.live.reopen import CACHE_FILE, assets_from_model, read_settings, save_cache
    from davis_ag.scene.specs import scenario_spec

    crop = CROPS["strawberry"]
    request = SceneRequest(scenario_spec("sp", crop), crop, 0, SEED, Camera(320, 180))
    model, grid = grow_scene(request)
    scene_dir, _ = draw_scene(request, model, grid, root / "continuous", views=list(grid.viewpoints[:1]))
    save_cache(scene_dir / CACHE_FILE, read_settings(scene_dir).cache_key, assets_from_model(model, grid))
    return scene_dir


def continuous_env_speed(scratch: Path, steps: int = 600) -> dict:
    """Steps per second of TVMContinuous-v0 at 224x224 on a single-plant strawberry scene (the
    crop's full grid area; one view drawn, the geometry cached from the growth, so nothing
    regrows), random actions, resets included; and the time one 224x224 render takes."""
    from davis_ag.live.scene import merge_ground
    from davis_ag.live.tvm_continuous import TVMContinuousEnv, steps_per_second

    scene_dir = continuous_scene(scratch)
    started = time.perf_counter()
    env = TVMContinuousEnv(scene_dir, "sp")
    env.reset(seed=SEED)  # the renderer's set-up (textures, shadow map) is paid here
    setup_s = time.perf_counter() - started
    try:
        view = env.scene.aimed_pose(1.0, -1.0, 0.4)
        env.scene.render(view, 224, 224, antialiasing="none", fractions=False, fast_ground=True, depth=False)
        begun = time.perf_counter()
        for _ in range(50):  # as the environment draws
            env.scene.render(view, 224, 224, antialiasing="none", fractions=False, fast_ground=True, depth=False)
        render_ms = (time.perf_counter() - begun) / 50 * 1000
        rate = steps_per_second(env, steps, seed=SEED)
    finally:
        env.close()
    return {"steps_per_second": round(rate["steps_per_second"], 1), "cpu_ms_per_step": round(rate["cpu_ms_per_step"], 1),
            "steps": steps, "resets": rate["resets"],
            "refused_share": round(rate["refused"], 3), "render_and_label_ms": round(render_ms, 1),
            "draws_per_step": round(rate["draws_per_step"], 2), "draws_per_reset": round(rate["draws_per_reset"], 2),
            "open_and_first_reset_s": round(setup_s, 2), "target_min": CONTINUOUS_TARGET,
            "triangles": int(env.scenes[0].assets.geometry.triangle_count),
            "triangles_drawn": int(merge_ground(env.scenes[0].assets.geometry).triangle_count)}


def continuous_table(result: dict, load: tuple[float, float]) -> str:
    """The TVMContinuous-v0 rate as Markdown."""
    met = "meets" if result["steps_per_second"] >= result["target_min"] else "misses"
    return (f"224x224 observations, single-plant strawberry (seed {SEED}, scene 0, {result['triangles']:,} triangles, "
            f"{result['triangles_drawn']:,} with the soil merged), "
            f"uniformly random actions, resets included; load average {load[0]:.2f} at the start, "
            f"{load[1]:.2f} at the end, {os.cpu_count()} CPUs.\n\n"
            "| steps timed | resets | refused moves | views drawn per step (per reset) | render + labels, ms | "
            "open + first reset, s | CPU ms/step | steps/s | target |\n"
            "|---|---|---|---|---|---|---|---|---|\n"
            f"| {result['steps']} | {result['resets']} | {result['refused_share']:.0%} | "
            f"{result['draws_per_step']} ({result['draws_per_reset']}) | "
            f"{result['render_and_label_ms']} | {result['open_and_first_reset_s']} | {result['cpu_ms_per_step']} | "
            f"**{result['steps_per_second']}** | >= {result['target_min']:.0f} ({met}) |")


def continuous_line(result: dict) -> str:
    """The rate in one sentence, for docs/views-on-demand.md."""
    return (f"Measured by `make bench` on this 2-core machine (shared, load average in docs/performance.md): "
            f"**{result['steps_per_second']} steps/s** at 224x224 with random actions, resets included "
            f"({result['render_and_label_ms']} ms to draw and label a view, {result['cpu_ms_per_step']} ms of CPU "
            f"per step; target >= {result['target_min']:.0f}).")


def write_continuous(result: dict, load: tuple[float, float], doc: Path | None) -> None:
    """Write the TVMContinuous-v0 rate into the doc and, beside it, docs/views-on-demand.md."""
    if doc:
        write_marked_section(doc, "bench-continuous", continuous_table(result, load))
        page = doc.absolute().parent / "views-on-demand.md"
        if page.is_file() and "<!-- continuous-rate:start -->" in page.read_text():
            write_marked_section(page, "continuous-rate", continuous_line(result))


def run_continuous(out: Path, doc: Path | None) -> dict:
    """Only the TVMContinuous-v0 measurement (``--only continuous``): JSON, the doc's section and
    docs/views-on-demand.md's line."""
    start = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="davis-ag-bench-") as scratch:
        result = continuous_env_speed(Path(scratch))
    load = (start, os.getloadavg()[0])
    print(continuous_table(result, load))
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"continuous_env": result}, indent=1) + "\n")
    write_continuous(result, load, doc)
    return result


def run(out: Path, crops: list[str], repeats: int, antialiasing: str = "fxaa") -> dict:
    """Run every measurement; return the JSON report."""
    load_start = os.getloadavg()
    report: dict = {"machine": {"cpus": os.cpu_count(), "platform": platform.platform(),
                                "LP_NUM_THREADS": os.environ.get("LP_NUM_THREADS")},
                    "image_size": [CAMERA.width, CAMERA.height], "seed": SEED, "antialiasing": antialiasing,
                    "crops": {}}
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
    for name in CROPS:  # a crop not measured this time: assume the slowest one measured
        for measured in (per_view, overhead, floor, grow):
            measured.setdefault(name, max(measured.values()))
    report["scene_overhead_s"] = {k: round(v, 1) for k, v in overhead.items()}
    report["paper_projection"] = projection(per_view, overhead, floor, grow, report.get("pool", {}).get("gain"))
    report["targets"] = {"documented_over_ours_min": TARGETS, "paper_hours_one_machine_max": PAPER_HOURS_TARGET}
    report["machine"]["load_average"] = {"start": [round(x, 2) for x in load_start],
                                         "end": [round(x, 2) for x in os.getloadavg()]}
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(report, indent=1) + "\n")
    return report


def table(report: dict) -> str:
    """The human-readable summary (Markdown)."""
    lines = [f"{report['image_size'][0]}x{report['image_size'][1]}, antialiasing {report['antialiasing']} (ours), "
             f"seed {report['seed']}, scene 0 of each crop, "
             f"median of {max(c['repeats'] for c in report['crops'].values())} interleaved repetitions; load "
             f"average {report['machine']['load_average']['start'][0]} at the start, "
             f"{report['machine']['load_average']['end'][0]} at the end, {report['machine']['cpus']} CPUs.", "",
             "| crop | primitives | views timed | ours s/view | documented s/view | floor s/view | "
             "documented / ours | target | ours / floor |",
             "|---|---|---|---|---|---|---|---|---|"]
    for crop, result in report["crops"].items():
        spv = result["seconds_per_view"]
        doc = f"{spv['documented']:.3f}" if "documented" in spv else "-"
        ratio = f"**{result['documented_over_ours']:.1f}x**" if "documented_over_ours" in result else "-"
        target = f">= {TARGETS[crop]:.0f}x" if crop in TARGETS else "-"
        over = f"{result['ours_over_floor']:.2f}" if "ours_over_floor" in result else "-"
        lines.append(f"| {crop} | {result['primitives']:,} | {result['views_timed']} x {result['repeats']} | "
                     f"{spv['ours']:.3f} | {doc} | {spv['floor']:.3f} | {ratio} | {target} | {over} |")
    p = report["paper_projection"]
    lines += ["", f"The `paper` preset ({p['images']:,} images, {p['scenes']} scenes): "
                  f"**{p['hours_one_machine']} h** on one machine like this one with the default workers "
                  f"(target <= {PAPER_HOURS_TARGET:.0f} h; {p['hours_one_machine_one_process']} h in one process), "
                  f"{p[f'hours_{CLUSTER_MACHINES}_machines']} h on {CLUSTER_MACHINES} such machines with Ray. "
                  f"Per-scene overhead (growing, renderer set-up), s: "
                  + ", ".join(f"{k} {v}" for k, v in report["scene_overhead_s"].items()) + ". "
                  + p["assumptions"] + "."]
    pool = report.get("pool")
    if pool:
        lines.append(f"\nTwo scene processes against one (the runner, {pool['scenes']} single-plant strawberry scenes, "
                     f"{pool['views']} views, growing included): {pool['seconds_one_worker']} s with one worker, "
                     f"{pool['seconds_two_workers']} s with two, a gain of **{pool['gain']:.2f}x**, used above.")
    if "hours_one_machine_grow_and_draw_only" in p:
        lines.append(f"\nGrowing the plants and our draw and read-back alone (the floor column, no labels, no "
                     f"files) would take **{p['hours_one_machine_grow_and_draw_only']} h** on one such machine: "
                     "the least any work around the draw could reach with these plants and this antialiasing.")
    lines.append("\nOrgan class images (`NNNN_class.png`, from the id image of the same pass), ours s/view with "
                 "and without: " + ", ".join(
                     f"{crop} {r['seconds_per_view']['ours']:.3f} / {r['seconds_per_view']['no_classes']:.3f} "
                     f"(**{r['classes_cost']:.3f}x**)" for crop, r in report["crops"].items()) + ".")
    env = report.get("env_steps_per_second", {})
    if "steps_per_second" in env:
        lines.append(f"\nTVM environment on the strawberry scene: {env['steps_per_second']} steps/s.")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Command line: ``python tools/bench.py --out out/bench.json [--doc docs/performance.md]``."""
    parser = argparse.ArgumentParser(prog="python tools/bench.py", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("out/bench.json"), help="JSON report")
    parser.add_argument("--crops", default="strawberry,tomato,vine",
                        help="crops to time (strawberry, tomato, vine); the documented path only where a target is set")
    parser.add_argument("--repeats", type=int, default=REPEATS, help=f"interleaved repetitions (default {REPEATS})")
    parser.add_argument("--antialiasing", choices=("fxaa", "msaa", "none"), default="fxaa",
                        help="our renderer's antialiasing (default fxaa)")
    parser.add_argument("--doc", type=Path, help="write the tables into this Markdown file's bench section")
    parser.add_argument("--only", choices=("all", "continuous"), default="all",
                        help="continuous: only TVMContinuous-v0's steps/s (about a minute)")
    args = parser.parse_args(argv)
    if args.only == "continuous":
        run_continuous(args.out, args.doc)
        print(f"written {args.out}" + (f" and {args.doc}" if args.doc else ""))
        return 0
    crops = [c for c in args.crops.split(",") if c]
    for name in crops:
        if name not in CROPS:
            parser.error(f"--crops: {name!r} is not strawberry, tomato or vine")
    if args.repeats < 1:
        parser.error("--repeats must be at least 1")
    report = run(args.out, crops, args.repeats, args.antialiasing)
    text = table(report)
    print(text)
    if args.doc:
        write_marked_section(args.doc, "bench", text)
        if "continuous_env" in report:
            load = report["machine"]["load_average"]
            write_continuous(report["continuous_env"], (load["start"][0], load["end"][0]), args.doc)
        print(f"written {args.doc}")
    print(f"written {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

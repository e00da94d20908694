"""``python -m davis_ag.bench``: what a labelled view costs, against pyhelios' documented path and
against drawing alone, and what the paper-scale dataset would take.

All in one process, on one single-plant strawberry scene at 1280x720 and a fixed set of its views
(the scene's own grid, thinned: every 0.5 m at the middle altitude):

- ours: the real generate path (:func:`davis_ag.generate.one_scene.generate_scene`: draw, labels, visible
  fractions, JPEG, PNG, annotations, atomic publish), seconds per view from the first view done
  to the scene published, so the writes still queued at the end are paid for;
- documented: the same views drawn by pyhelios as its documentation shows: ``printWindow`` to a
  JPEG, then ``writeImageBoundingBoxes`` and ``writeImageSegmentationMasks`` per view, the fruit
  labelled with object data;
- floor: only drawing the colour and primitive-id passes and reading the colour image
  (``HeliosRenderer.render``), no labels, no writes.

Then views per second of ours for tomato and vine (8 views each) and the projected hours for the
``paper`` preset on one machine like this one and on a 16-machine Ray cluster. The first view of
each path is not timed (it builds the shadow map and warms caches).
"""

from __future__ import annotations

import argparse
import contextlib
import cProfile
import dataclasses
import io
import json
import os
import platform
import pstats
import tempfile
import time
from pathlib import Path
from typing import Callable

import numpy as np

from davis_ag.errors import UserError
from davis_ag.generate.one_scene import SceneRequest, generate_scene
from davis_ag.generate.run_config import load_dataset_config
from davis_ag.generate.run_progress import count_views
from davis_ag.render.helios import HeliosRenderer
from davis_ag.scene.build import build_scene
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CROPS, SCENARIOS, plant_centres
from davis_ag.scene.view_grid import build_view_grid

SEED = 0
CAMERA = Camera(1280, 720)
#: The strawberry scene's views: its grid every 0.5 m at the middle altitude (24 views).
STRAWBERRY_GRID = dataclasses.replace(SCENARIOS["sp"], extent=(2.5, 3.0), step=0.5, altitude_levels=(1,))
#: Tomato and vine: every 1 m at the lowest altitude (8 views).
OTHER_GRID = dataclasses.replace(SCENARIOS["sp"], step=1.0, altitude_levels=(0,))
TARGETS = {"documented_over_ours_min": 3.5, "ours_over_floor_max": 1.3}
CLUSTER_MACHINES = 16
#: Scene processes per machine like this one (one per core) and the throughput they were measured
#: to give against one process drawing with every core (docs/performance.md: 1.90 / 1.61 views/s).
POOL_SLOTS = 2
POOL_GAIN = 1.18


def cpu_seconds() -> float:
    """CPU time of this process, every thread (Mesa's rasteriser threads included)."""
    times = os.times()
    return times.user + times.system


@dataclasses.dataclass
class Timed:
    """Wall and CPU seconds per view of one path, and the views timed."""

    wall: float
    cpu: float
    views: int


def time_ours(request: SceneRequest, root: Path) -> tuple[Timed, dict, float]:
    """The real generate path on one scene.

    Returns:
        Per-view timing (views 2..n, publishing included), the scene's stats, and the seconds of
        everything else (growing, setting up the renderer, the first view).
    """
    marks: dict[str, float] = {}

    def on_view(done: int, total: int) -> None:
        if done == 1:
            marks["wall"], marks["cpu"] = time.perf_counter(), cpu_seconds()

    start = time.perf_counter()
    _, stats = generate_scene(request, root, on_view)
    end, cpu_end = time.perf_counter(), cpu_seconds()
    timed = Timed((end - marks["wall"]) / (stats["views"] - 1), (cpu_end - marks["cpu"]) / (stats["views"] - 1),
                  stats["views"] - 1)
    return timed, stats, marks["wall"] - start


def time_loop(views: list, step: Callable[[object], None]) -> Timed:
    """Run ``step`` on every view; time all but the first."""
    step(views[0])
    wall, cpu = time.perf_counter(), cpu_seconds()
    for view in views[1:]:
        step(view)
    n = len(views) - 1
    return Timed((time.perf_counter() - wall) / n, (cpu_seconds() - cpu) / n, n)


def documented_and_floor(request: SceneRequest, root: Path, expected_poses: dict[str, list]) -> tuple[Timed, Timed]:
    """Time pyhelios' documented path and the floor on the same scene and views as ours.

    Args:
        request: The scene ours made.
        root: Scratch folder for the documented path's files.
        expected_poses: Ours' poses by image name, to check the views are the same.

    Returns:
        Documented and floor timings.
    """
    # The same draws of the scene's generator, in the same order, as generate_scene.
    rng = np.random.default_rng(request.seed)
    model = build_scene(request.scenario, request.crop, rng)
    grid = build_view_grid(request.scenario, request.crop, plant_centres(request.scenario, request.crop),
                           model.aim_height, rng)
    poses = {v.image_name: [round(x, 5) for x in v.pose] for v in grid.viewpoints}
    if poses != expected_poses:
        raise RuntimeError("the benchmark's views differ from generate_scene's: keep its draws in step")
    fruit_id = 0
    for plant in model.plants:  # the documented route labels fruit with object data
        for object_id in plant.fruit_objects:
            model.context.setObjectDataInt(object_id, "fruit_id", fruit_id)
            fruit_id += 1
    images = root / "documented"
    images.mkdir(parents=True)
    views = list(grid.viewpoints)
    # One Visualizer per path, set up like ours, drawn in turn: floor then documented phases twice
    # each, so a change in the machine's load hits both alike.
    with HeliosRenderer(model.context, request.camera, model.lighting) as renderer:
        vis = renderer._vis  # the documented calls are the Visualizer's own methods

        def documented(view) -> None:
            renderer.set_view(view)
            jpeg = str(images / view.image_name)
            vis.printWindow(jpeg)
            vis.writeImageBoundingBoxes(object_data_labels="fruit_id", object_class_ids=0,
                                        image_file=view.image_name, image_path=str(images))
            vis.writeImageSegmentationMasks(object_data_labels="fruit_id", object_class_ids=0,
                                            json_filename=str(images / f"{view.image_name[:-5]}.json"),
                                            image_file=jpeg)

        half = len(views) // 2
        floors, docs = [], []
        for part in (views[:half + 1], views[half:]):
            floors.append(time_loop(part, renderer.render))
            docs.append(time_loop(part, documented))
    return combine(docs), combine(floors)


def combine(parts: list[Timed]) -> Timed:
    """Per-view means over several timed runs."""
    n = sum(p.views for p in parts)
    return Timed(sum(p.wall * p.views for p in parts) / n, sum(p.cpu * p.views for p in parts) / n, n)


def projection(per_view: dict[str, float], overhead: dict[str, float]) -> dict:
    """Hours to make the ``paper`` preset on one machine and on a cluster of such machines.

    Each scene costs its views times the crop's seconds per view, plus the crop's per-scene
    overhead (growing, renderer set-up) times the plants it grows. One process is what was
    measured here; the default ``--workers`` (one single-threaded process per core) is scaled by
    :data:`POOL_GAIN`. A cluster machine runs ``POOL_SLOTS`` scenes at once, each slot taking the
    longest scene left (longest-first list scheduling).
    """
    config = load_dataset_config("paper")
    durations: list[float] = []
    images = 0
    for group in config.groups:
        views = count_views(group.scenario, group.crop)
        plants = 1 if group.scenario.name == "sp" else group.crop.mp_plants
        images += views * group.scenes
        durations += [views * per_view[group.crop.name] + overhead[group.crop.name] * plants] * group.scenes
    # A slot of a pool is POOL_SLOTS / POOL_GAIN times slower than one process owning the machine.
    slots = [0.0] * (CLUSTER_MACHINES * POOL_SLOTS)
    for duration in sorted(durations, reverse=True):
        slots[slots.index(min(slots))] += duration * POOL_SLOTS / POOL_GAIN
    return {"images": images, "scenes": len(durations),
            "hours_one_machine_one_process": round(sum(durations) / 3600, 1),
            "hours_one_machine": round(sum(durations) / POOL_GAIN / 3600, 1),
            f"hours_{CLUSTER_MACHINES}_machines": round(max(slots) / 3600, 1),
            "assumptions": f"multi-plant views cost what single-plant views of the same crop cost (a lower "
                           f"bound: they draw 3-5 plants); {POOL_SLOTS} single-threaded scene processes per "
                           f"machine make {POOL_GAIN}x the views of one process (measured, docs/performance.md)"}


def env_speed(dataset: Path, steps: int = 20_000) -> dict:
    """Steps per second of the TVM environment on the scene just drawn (cache built first).

    Returns:
        Steps per second through ``gymnasium.make`` and the target, or the reason it could not
        run (a scene of few views may hold no eligible start).
    """
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


def run(out: Path, crops: list[str], profile: bool) -> dict:
    """Run every measurement; return the JSON report."""
    load_start = os.getloadavg()
    report: dict = {"machine": {"cpus": os.cpu_count(), "platform": platform.platform(),
                                "LP_NUM_THREADS": os.environ.get("LP_NUM_THREADS")},
                    "image_size": [CAMERA.width, CAMERA.height], "seed": SEED}
    per_view: dict[str, float] = {}
    overhead: dict[str, float] = {}
    with tempfile.TemporaryDirectory(prefix="davis-ag-bench-") as scratch:
        root = Path(scratch)
        request = SceneRequest(STRAWBERRY_GRID, CROPS["strawberry"], 0, SEED, CAMERA)
        profiler = cProfile.Profile() if profile else None
        with profiler or contextlib.nullcontext():
            ours, stats, rest = time_ours(request, root / "ours")
        poses = {k: v["pose"] for k, v in json.loads((root / "ours" / request.folder / "annotations.json")
                                                    .read_text()).items()}
        documented, floor = documented_and_floor(request, root, poses)
        per_view["strawberry"], overhead["strawberry"] = ours.wall, rest
        report["strawberry"] = {"views_timed": ours.views, "grow_s": round(stats["grow_s"], 2),
                                "seconds_per_view": {"ours": ours.wall, "documented": documented.wall,
                                                     "floor": floor.wall},
                                "cpu_seconds_per_view": {"ours": ours.cpu, "documented": documented.cpu,
                                                         "floor": floor.cpu}}
        report["ratios"] = {"documented_over_ours": documented.wall / ours.wall,
                            "ours_over_floor": ours.wall / floor.wall,
                            "cpu_documented_over_ours": documented.cpu / ours.cpu,
                            "cpu_ours_over_floor": ours.cpu / floor.cpu, "targets": TARGETS}
        report["views_per_second"] = {"strawberry": 1 / ours.wall}
        report["env_steps_per_second"] = env_speed(root / "ours")
        for name in crops:
            crop = CROPS[name]
            timed, stats, rest = time_ours(SceneRequest(OTHER_GRID, crop, 0, SEED, CAMERA), root / name)
            per_view[name], overhead[name] = timed.wall, rest
            report["views_per_second"][name] = 1 / timed.wall
            report[name] = {"views_timed": timed.views, "grow_s": round(stats["grow_s"], 2),
                            "seconds_per_view": timed.wall, "cpu_seconds_per_view": timed.cpu}
    for name in CROPS:  # a crop not measured this time: assume the slowest one measured
        per_view.setdefault(name, max(per_view.values()))
        overhead.setdefault(name, max(overhead.values()))
    report["scene_overhead_s"] = {k: round(v, 1) for k, v in overhead.items()}
    report["paper_projection"] = projection(per_view, overhead)
    report["machine"]["load_average"] = {"start": [round(x, 2) for x in load_start],
                                         "end": [round(x, 2) for x in os.getloadavg()]}
    if profiler:
        text = io.StringIO()
        pstats.Stats(profiler, stream=text).sort_stats("tottime").print_stats(15)
        report["profile_ours"] = text.getvalue()
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps(report, indent=1) + "\n")
    return report


def table(report: dict) -> str:
    """The human-readable summary."""
    spv, cpu, ratios = (report["strawberry"]["seconds_per_view"], report["strawberry"]["cpu_seconds_per_view"],
                        report["ratios"])
    lines = [f"single strawberry plant, {report['image_size'][0]}x{report['image_size'][1]}, "
             f"{report['strawberry']['views_timed']} views timed per path",
             f"{'path':<12}{'s/view':>10}{'cpu s/view':>12}{'views/s':>10}"]
    for path in ("ours", "documented", "floor"):
        lines.append(f"{path:<12}{spv[path]:>10.3f}{cpu[path]:>12.3f}{1 / spv[path]:>10.2f}")
    lines.append(f"documented/ours {ratios['documented_over_ours']:.2f} (target >= "
                 f"{TARGETS['documented_over_ours_min']}), ours/floor {ratios['ours_over_floor']:.2f} "
                 f"(target <= {TARGETS['ours_over_floor_max']})")
    lines.append("views/s (ours): " + ", ".join(f"{k} {v:.2f}" for k, v in report["views_per_second"].items()))
    env = report.get("env_steps_per_second", {})
    if "steps_per_second" in env:
        lines.append(f"TVM environment: {env['steps_per_second']} steps/s (target >= {env['target_min']})")
    p = report["paper_projection"]
    lines.append(f"paper preset: {p['images']} images in {p['scenes']} scenes: {p['hours_one_machine']} h on one "
                 f"machine like this ({p['hours_one_machine_one_process']} h in one process), "
                 f"{p[f'hours_{CLUSTER_MACHINES}_machines']} h on {CLUSTER_MACHINES}")
    lines.append(f"load average at start {report['machine']['load_average']['start'][0]}, "
                 f"at end {report['machine']['load_average']['end'][0]}")
    return "\n".join(lines)


def main(argv: list[str] | None = None) -> int:
    """Command line: ``python -m davis_ag.bench --out out/bench.json``."""
    parser = argparse.ArgumentParser(prog="python -m davis_ag.bench", description=__doc__,
                                     formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--out", type=Path, default=Path("out/bench.json"), help="JSON report")
    parser.add_argument("--crops", default="tomato,vine", help="crops timed besides strawberry ('' for none)")
    parser.add_argument("--profile", action="store_true", help="profile ours (cProfile, in the JSON)")
    args = parser.parse_args(argv)
    crops = [c for c in args.crops.split(",") if c]
    for name in crops:
        if name not in CROPS or name == "strawberry":
            parser.error(f"--crops: {name!r} is not tomato or vine")
    report = run(args.out, crops, args.profile)
    print(table(report))
    if args.profile:
        print(report["profile_ours"])
    print(f"written {args.out}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

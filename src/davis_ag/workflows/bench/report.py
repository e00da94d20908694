"""``davis-ag bench``'s tables and projection: the paper-scale hours from the measured costs, and the
Markdown that docs/performance.md and docs/views-on-demand.md show (between their ``bench`` markers)."""

from __future__ import annotations

import os
from pathlib import Path

from davis_ag.atomic_files import read_page, write_marked_section
from davis_ag.generate.run_config import load_dataset_config
from davis_ag.generate.run_progress import count_views

SEED = 0
#: Documented path over ours, at least (crops timed on the documented path).
TARGETS = {"strawberry": 10.0, "vine": 8.0}
CLUSTER_MACHINES = 16
#: Scene processes per machine like this one (one per core) and the throughput two of them were
#: measured to give against one process drawing with both cores (docs/performance.md).
POOL_SLOTS = 2
POOL_GAIN = 1.18
PAPER_HOURS_TARGET = 24.0


def projection(
    per_view: dict[str, float],
    overhead: dict[str, float],
    floor: dict[str, float] | None = None,
    grow: dict[str, float] | None = None,
    gain: float | None = None,
) -> dict:
    """Hours to make the ``paper`` preset on one machine and on a cluster of such machines.

    Each scene costs its views times the crop's seconds per view, plus the crop's per-scene
    overhead (growing, renderer set-up) times the plants it grows. One process is what was
    measured; the default ``--workers`` (one single-threaded process per core) is scaled by
    :data:`POOL_GAIN`. A cluster machine runs ``POOL_SLOTS`` scenes at once, each slot taking the
    longest scene left (longest-first list scheduling). With ``floor`` and ``grow`` (seconds per
    view of the draw and read-back alone, seconds to grow one plant), also the hours that growing
    plus drawing alone would take on one machine: what no work around the draw can go below.
    ``gain`` replaces :data:`POOL_GAIN` with a measured one (:func:`davis_ag.workflows.bench.run.pool_gain`).
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
    return {
        "images": images,
        "scenes": len(durations),
        "hours_one_machine_one_process": round(sum(durations) / 3600, 1),
        "hours_one_machine": round(sum(durations) / gain / 3600, 1),
        f"hours_{CLUSTER_MACHINES}_machines": round(max(slots) / 3600, 1),
        "target_hours_one_machine": PAPER_HOURS_TARGET,
        **({"hours_one_machine_grow_and_draw_only": round(bound / gain / 3600, 1)} if bound else {}),
        "assumptions": f"multi-plant views cost what single-plant views of the same crop cost (a lower "
        f"bound: they draw 3-5 plants); growing costs the measured single-plant time per "
        f"plant; {POOL_SLOTS} scene processes per machine make {gain:.2f}x the views of one "
        + (
            "process (measured by this bench with our renderer)"
            if gain != POOL_GAIN
            else "process (measured with Helios, docs/performance.md)"
        ),
    }


def doc_section(marker: str, gpu_machine: bool) -> str:
    """The marker a measurement is written between: a GPU machine's go to the page's ``MARKER-gpu``
    sections, beside the 2-core machine's, so ``make bench`` on either never replaces the other's."""
    return f"{marker}-gpu" if gpu_machine else marker


def is_gpu_machine() -> bool:
    """Whether this machine trains or draws on a GPU (CUDA in torch, or a GPU's EGL driver)."""
    import torch

    from davis_ag.render.egl_context import draws_on_gpu, renderer_name

    return torch.cuda.is_available() or draws_on_gpu(renderer_name())


def _drawn_by(renderer: str | None) -> str:
    return f", drawn by {renderer}" if renderer else ""


def continuous_table(result: dict, load: tuple[float, float]) -> str:
    """The TVMContinuous-v0 rate as Markdown."""
    met = "meets" if result["steps_per_second"] >= result["target_min"] else "misses"
    return (
        f"224x224 observations, single-plant strawberry (seed {SEED}, scene 0, {result['triangles']:,} triangles, "
        f"{result['triangles_drawn']:,} with the soil merged), "
        f"uniformly random actions, resets included; load average {load[0]:.2f} at the start, "
        f"{load[1]:.2f} at the end, {os.cpu_count()} CPUs{_drawn_by(result.get('gl_renderer'))}.\n\n"
        "| steps timed | resets | refused moves | views drawn per step (per reset) | render + labels, ms | "
        "open + first reset, s | CPU ms/step | steps/s | target |\n"
        "|---|---|---|---|---|---|---|---|---|\n"
        f"| {result['steps']} | {result['resets']} | {result['refused_share']:.0%} | "
        f"{result['draws_per_step']} ({result['draws_per_reset']}) | "
        f"{result['render_and_label_ms']} | {result['open_and_first_reset_s']} | {result['cpu_ms_per_step']} | "
        f"**{result['steps_per_second']}** | >= {result['target_min']:.0f} ({met}) |" + _with_robot(result.get("robot"))
    )


def _with_robot(robot: dict | None) -> str:
    """The rate with the camera on a robot, as a sentence under the table (none in older reports)."""
    if not robot:
        return ""
    return (
        f"\n\nWith the camera on {robot['name']} (docs/robot.md: the arm solved from its configuration "
        f"at every move): **{robot['steps_per_second']} steps/s**, {robot['cpu_ms_per_step']} ms of CPU per "
        f"step, {robot['refused_share']:.0%} of moves refused (the robot issue's target: at least 50)."
    )


def continuous_line(result: dict) -> str:
    """The rate in one sentence, for docs/views-on-demand.md."""
    return (
        f"Measured by `make bench` on this 2-core machine (shared, load average in docs/performance.md): "
        f"**{result['steps_per_second']} steps/s** at 224x224 with random actions, resets included "
        f"({result['render_and_label_ms']} ms to draw and label a view, {result['cpu_ms_per_step']} ms of CPU "
        f"per step; target >= {result['target_min']:.0f})."
    )


def write_continuous(result: dict, load: tuple[float, float], doc: Path | None, gpu_machine: bool = False) -> None:
    """Write the TVMContinuous-v0 rate into the doc and, beside it, docs/views-on-demand.md (whose
    sentence is the 2-core machine's: a GPU machine's rate goes to the doc's GPU section only)."""
    if doc:
        write_marked_section(doc, doc_section("bench-continuous", gpu_machine), continuous_table(result, load))
        page = doc.absolute().parent / "views-on-demand.md"
        if not gpu_machine and page.is_file() and "<!-- continuous-rate:start -->" in read_page(page, "page"):
            write_marked_section(page, "continuous-rate", continuous_line(result))


def table(report: dict) -> str:
    """The human-readable summary (Markdown)."""
    lines = [
        f"{report['image_size'][0]}x{report['image_size'][1]}, antialiasing {report['antialiasing']} (ours), "
        f"seed {report['seed']}, scene 0 of each crop, "
        f"median of {max(c['repeats'] for c in report['crops'].values())} interleaved repetitions; load "
        f"average {report['machine']['load_average']['start'][0]} at the start, "
        f"{report['machine']['load_average']['end'][0]} at the end, {report['machine']['cpus']} CPUs"
        f"{_drawn_by(report['machine'].get('gl_renderer'))}.",
        "",
        "| crop | primitives | views timed | ours s/view | documented s/view | floor s/view | "
        "documented / ours | target | ours / floor |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for crop, result in report["crops"].items():
        spv = result["seconds_per_view"]
        doc = f"{spv['documented']:.3f}" if "documented" in spv else "-"
        ratio = f"**{result['documented_over_ours']:.1f}x**" if "documented_over_ours" in result else "-"
        target = f">= {TARGETS[crop]:.0f}x" if crop in TARGETS else "-"
        over = f"{result['ours_over_floor']:.2f}" if "ours_over_floor" in result else "-"
        lines.append(
            f"| {crop} | {result['primitives']:,} | {result['views_timed']} x {result['repeats']} | "
            f"{spv['ours']:.3f} | {doc} | {spv['floor']:.3f} | {ratio} | {target} | {over} |"
        )
    p = report["paper_projection"]
    # The projection runs POOL_SLOTS scene processes a machine: the default workers on 2 cores only.
    workers = "the default workers" if report["machine"]["cpus"] == POOL_SLOTS else f"{POOL_SLOTS} scene processes"
    lines += [
        "",
        f"The `paper` preset ({p['images']:,} images, {p['scenes']} scenes): "
        f"**{p['hours_one_machine']} h** on one machine like this one with {workers} "
        f"(target <= {PAPER_HOURS_TARGET:.0f} h; {p['hours_one_machine_one_process']} h in one process), "
        f"{p[f'hours_{CLUSTER_MACHINES}_machines']} h on {CLUSTER_MACHINES} such machines with Ray. "
        f"Per-scene overhead (growing, renderer set-up), s: "
        + ", ".join(f"{k} {v}" for k, v in report["scene_overhead_s"].items())
        + (
            f" ({', '.join(report['assumed_as_slowest'])}, not measured: as the slowest measured)"
            if report.get("assumed_as_slowest")
            else ""
        )
        + ". "
        + p["assumptions"]
        + ".",
    ]
    pool = report.get("pool")
    if pool:
        lines.append(
            f"\nTwo scene processes against one (the runner, {pool['scenes']} single-plant strawberry scenes, "
            f"{pool['views']} views, growing included): {pool['seconds_one_worker']} s with one worker, "
            f"{pool['seconds_two_workers']} s with two, a gain of **{pool['gain']:.2f}x**, used above."
        )
    if "hours_one_machine_grow_and_draw_only" in p:
        lines.append(
            f"\nGrowing the plants and our draw and read-back alone (the floor column, no labels, no "
            f"files) would take **{p['hours_one_machine_grow_and_draw_only']} h** on one such machine: "
            "the least any work around the draw could reach with these plants and this antialiasing."
        )
    lines.append(
        "\nOrgan class images (`NNNN_class.png`, from the id image of the same pass), ours s/view with "
        "and without: "
        + ", ".join(
            f"{crop} {r['seconds_per_view']['ours']:.3f} / {r['seconds_per_view']['no_classes']:.3f} "
            f"(**{r['classes_cost']:.3f}x**)"
            for crop, r in report["crops"].items()
        )
        + "."
    )
    env = report.get("env_steps_per_second", {})
    if "steps_per_second" in env:
        lines.append(f"\nTVM environment on the strawberry scene: {env['steps_per_second']} steps/s.")
    return "\n".join(lines)

"""``davis-ag bench --only crops``: what the plant-library crops cost, single plant and row.

Per crop and scenario (``sp`` and ``row``, dataset seed 0, scene 0, 640x360: the crops run's size)
a fresh process grows the scene and draws its first :data:`VIEWS` views on the generate path
(:func:`davis_ag.workflows.bench.timing.time_ours`: colour, ids, depth, labels, files, publish), and reports the
seconds to grow, the scene's primitives and fruit, the seconds per view (all but the first) and the
process's peak memory, which :mod:`davis_ag.scene.scene_size`'s bytes per primitive is checked
against; on the single plant, our fruit boxes beside Helios's Visualizer's on three views (peak
memory is taken before that). The reference, in the same process as each row: the paper's SP strawberry, so the table
gives each crop's seconds per view as a ratio to it, which a busy machine moves less than seconds.
"""

from __future__ import annotations

import multiprocessing
import resource
import tempfile
import time
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import write_marked_section
from davis_ag.scene.camera import Camera

#: The crops run's image size.
CAMERA = Camera(640, 360)
#: Views drawn per scene (the first untimed).
VIEWS = 6
#: The page's section.
MARKER = "bench-crops"


def helios_agreement(model, grid, crop) -> dict[str, int]:
    """Our fruit boxes against Helios's Visualizer's on three views of a single plant (low, middle,
    high, three sides): boxes both drew, the largest corner difference, fruit only one boxed."""
    import numpy as np

    from davis_ag.labels.fruit_labels import fruit_lookup, label_view
    from davis_ag.render.backends import open_renderer

    views = [grid.viewpoints[i] for i in (20, 150, 290) if i < len(grid.viewpoints)]
    lookup = fruit_lookup({f.id: f.uuids for f in model.fruits}, model.uuid_count)
    threshold = crop.min_fruit_pixels_at(CAMERA.width, CAMERA.height)
    boxes = {}
    for renderer in ("helios", "opengl"):
        with open_renderer(renderer, model.context, CAMERA, model.lighting, "helios") as drawing:
            boxes[renderer] = [
                {b[4]: b[:4] for b in label_view(drawing.render(v)[1], lookup, threshold).boxes} for v in views
            ]
    both = [(ours[i], theirs[i]) for ours, theirs in zip(boxes["opengl"], boxes["helios"]) for i in ours if i in theirs]
    return {
        "boxes_compared": len(both),
        "max_corner_px": int(max((np.abs(np.subtract(a, b)).max() for a, b in both), default=0)),
        "boxed_by_one": sum(len(set(o) ^ set(t)) for o, t in zip(boxes["opengl"], boxes["helios"])),
    }


def _measure(crop_name: str, scenario_name: str) -> dict[str, Any]:
    """Grow one scene and draw its first views (in a process of its own: its peak memory is its);
    a single plant's boxes are checked against Helios's Visualizer's too."""
    from davis_ag.generate.one_scene import SceneRequest, grow_scene
    from davis_ag.scene.specs import CROPS, scenario_spec
    from davis_ag.workflows.bench.timing import time_ours

    crop = CROPS[crop_name]
    request = SceneRequest(scenario_spec(scenario_name, crop), crop, 0, 0, CAMERA)
    started = time.perf_counter()
    model, grid = grow_scene(request)
    grow_s = time.perf_counter() - started
    primitives = len(model.context.getAllUUIDs())
    with tempfile.TemporaryDirectory(prefix="davis-ag-bench-crops-") as scratch:
        per_view, first = time_ours(request, model, grid, list(grid.viewpoints[:VIEWS]), Path(scratch))
    peak = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss * 1024
    agreement = helios_agreement(model, grid, crop) if scenario_name == "sp" else {}
    return {
        **agreement,
        "plants": len(model.plants),
        "primitives": primitives,
        "fruit": len(model.fruits),
        "views_in_scene": len(grid.viewpoints),
        "grow_s": round(grow_s, 1),
        "seconds_per_view": round(per_view, 3),
        "first_view_s": round(first, 1),
        "peak_gb": round(peak / 1e9, 2),
        "bytes_per_primitive": round(peak / primitives),
    }


def measure(crop_name: str, scenario_name: str) -> dict[str, Any]:
    """:func:`_measure` in a fresh process (spawned: no memory of this one's counted)."""
    with multiprocessing.get_context("spawn").Pool(1) as pool:
        return pool.apply(_measure, (crop_name, scenario_name))


def crops_speed(crops: list[str]) -> dict[str, Any]:
    """Every crop's SP and row scene, each beside a reference SP strawberry measured just before it.

    Returns:
        ``{"crops": {crop: {scenario: result}}, "reference": [strawberry results]}``.
    """
    out: dict[str, Any] = {"image_size": [CAMERA.width, CAMERA.height], "views": VIEWS, "crops": {}, "reference": []}
    for crop in crops:
        reference = measure("strawberry", "sp")
        out["reference"].append(reference)
        rows = {}
        for scenario in ("sp", "row"):
            result = measure(crop, scenario)
            result["over_strawberry"] = round(result["seconds_per_view"] / reference["seconds_per_view"], 2)
            rows[scenario] = result
            print(f"{crop} {scenario}: {result}", flush=True)
        out["crops"][crop] = rows
    return out


def merged(report: Path, fresh: dict[str, Any]) -> dict[str, Any]:
    """``fresh`` with the crops it did not measure taken from an earlier ``--only crops`` report at
    ``report`` (so one crop can be measured again alone), in ``specs.CROPS``'s order."""
    import json

    from davis_ag.scene.specs import CROPS

    try:
        before = json.loads(Path(report).read_text()).get("crops", {})
    except (OSError, ValueError, AttributeError):
        before = {}
    earlier = (
        before.get("crops", {}) if isinstance(before, dict) and before.get("image_size") == fresh["image_size"] else {}
    )
    every = {**earlier, **fresh["crops"]}
    return {**fresh, "crops": {name: every[name] for name in CROPS if name in every}}


def crops_table(result: dict[str, Any], load: tuple[float, float]) -> str:
    """The Markdown table of :func:`crops_speed`'s result, each scene's peak memory beside what
    :func:`davis_ag.scene.scene_size.scene_bytes` estimates for it today."""
    from davis_ag.scene.scene_size import scene_bytes
    from davis_ag.scene.specs import CROPS, scenario_spec

    lines = [
        f"{result['image_size'][0]}x{result['image_size'][1]}, scene 0 of dataset seed 0, the first "
        f"{result['views']} views on the generate path (the first untimed), each scene in a process of "
        f"its own; load average {load[0]:.1f} at the start, {load[1]:.1f} at the end. `x strawberry`: "
        "seconds per view over an SP strawberry's measured just before (the same process's reference).",
        "",
        "| crop | scenario | plants | primitives | fruit | views a scene | grow s | s/view | x strawberry | "
        "peak GB (estimated) | bytes/primitive | boxes beside Helios's (compared, largest difference px, "
        "boxed by one) |",
        "|---|---|---|---|---|---|---|---|---|---|---|---|",
    ]
    for crop, rows in result["crops"].items():
        for scenario, r in rows.items():
            lines.append(
                f"| {crop} | {scenario} | {r['plants']} | {r['primitives']:,} | {r['fruit']} | {r['views_in_scene']} | "
                f"{r['grow_s']:.0f} | {r['seconds_per_view']:.3f} | {r['over_strawberry']:.1f} | {r['peak_gb']:.1f} "
                f"({scene_bytes(scenario_spec(scenario, CROPS[crop]), CROPS[crop]) / 1e9:.1f}) | "
                f"{r['bytes_per_primitive']:,} | "
                + (
                    f"{r['boxes_compared']}, {r['max_corner_px']}, {r['boxed_by_one']} |"
                    if "boxes_compared" in r
                    else "– |"
                )
            )
    return "\n".join(lines)


def write_crops(result: dict[str, Any], load: tuple[float, float], doc: Path | None, gpu_machine: bool = False) -> None:
    """Write the table into the doc's ``bench-crops`` section (a GPU machine's: ``bench-crops-gpu``)."""
    if doc:
        write_marked_section(doc, f"{MARKER}-gpu" if gpu_machine else MARKER, crops_table(result, load))

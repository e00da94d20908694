"""Measure our scenes against the paper and write docs/scenes.md (a tool, not shipped).

Three measurements, each saved to its own JSON file under docs/ so that a slow one is not redone
when another is refreshed; docs/scenes.md is rewritten from whichever exist:

- ``views``: images per scene for every crop and scenario, beside Table 3's (instant).
- ``plants N``: fruit per plant and the measured phenotype of N single plants per crop, grown as
  ``davis-ag generate`` grows them (scene seeds of dataset seed 0, indices 0..N-1).
- ``findings N WxH``: N single-plant strawberry scenes generated at WxH (dataset seed 0), and the
  paper's section IV and V-C findings measured on them: visible fruit per position (fruit that
  Helios's Synthetic Annotation plug-in would box: ``specs.SEEABLE_FRUIT_PIXELS``), whether any
  view sees every fruit, how often changing altitude at a fixed position loses or gains fruit
  (Fig. 3), and the share of the published boxes (the crop's 210 pixels) with OER below 0.4.

- ``refused N WxH``: N single-plant scenes per crop with each plant generator, and the share of
  moves TVM-v0 refuses from its episode starts (:mod:`davis_ag.benchmark.moves`).

Run: ``python tools/scene_stats.py views``, ``... plants 10 [tomato,vine]``, ``... refused 2 640x360``,
``... findings 10 1280x720 [0.5]`` (the last argument: the grid step, default the paper's 0.25 m;
one file per image size, docs/scenes-findings-WxH.json, since the OER share depends on it).
With no argument it only rewrites docs/scenes.md, e.g. after ``tools/strawberry_recipes.py``.
"""

from __future__ import annotations

import dataclasses
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from davis_ag.atomic_files import write_json_atomic, write_text_atomic
from davis_ag.scene.specs import (
    CROPS,
    PHENOTYPE_SPREAD,
    SEEABLE_FRUIT_PIXELS,
    group_name,
    scenario_spec,
)
from davis_ag.scene.view_grid import views_per_scene

DOCS = Path(__file__).resolve().parent.parent / "docs"
#: Table 3 of the paper: (images, scenes) per scenario and crop.
TABLE_3 = {("sp", "strawberry"): (24_510, 86), ("sp", "tomato"): (45_240, 130), ("sp", "vine"): (63_336, 182),
           ("mp", "strawberry"): (86_856, 77), ("mp", "tomato"): (203_400, 113), ("mp", "vine"): (79_200, 44)}


def measure_views() -> dict:
    """Our images per scene and the paper's, per scenario and crop."""
    rows = {}
    for (scenario, crop_name), (images, scenes) in TABLE_3.items():
        crop = CROPS[crop_name]
        rows[f"{scenario}-{crop_name}"] = {"ours": views_per_scene(scenario_spec(scenario, crop), crop),
                                            "paper": images // scenes}
    return rows


def measure_plants(count: int, crops: list[str]) -> dict:
    """Grow ``count`` single plants of each of ``crops``; their fruit counts and phenotypes."""
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.scene.build import build_scene

    out: dict = {"plants_per_crop": count, "crops": {}}
    for crop in (CROPS[name] for name in crops):
        scenario = scenario_spec("sp", crop)
        plants = []
        for index in range(count):
            started = time.perf_counter()
            seed = SceneRequest(scenario, crop, index, 0).seed
            model = build_scene(scenario, crop, np.random.default_rng(seed))
            plant = model.plants[0]
            plants.append({**plant.summary(), "build_s": None if plant.build_s is None else round(plant.build_s, 3),
                           "scene_seed": seed, "grow_s": round(time.perf_counter() - started, 1)})
            print(f"{crop.name} {index}: {plant.fruit_count} fruit", file=sys.stderr, flush=True)
            del model
        out["crops"][crop.name] = plants
    return out


def measure_findings(count: int, size: tuple[int, int], step: float) -> dict:
    """Generate ``count`` SP strawberry scenes at ``size`` and measure the Fig. 2-3 findings.

    Args:
        count: Scenes 0..count-1 of dataset seed 0.
        size: Image size.
        step: Grid step, m: 0.25 is the paper's; 0.5 keeps every other row and column (90 views).

    Returns:
        JSON-ready measurements.
    """
    from davis_ag.data.reader import open_dataset
    from davis_ag.generate.one_scene import SceneRequest, generate_scene
    from davis_ag.scene.camera import Camera

    crop = CROPS["strawberry"]
    scenario = dataclasses.replace(scenario_spec("sp", crop), step=step)
    scenes = []
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        for index in range(count):
            request = SceneRequest(scenario, seeable(crop), index, 0, Camera(*size))
            scene_dir, stats = generate_scene(request, root)
            scene = open_dataset(root).scene(f"Single-Strawberry/{index:03d}")
            scenes.append({**visibility_findings(scene, json.loads((scene_dir / "scene.json").read_text())),
                           "box_oer": published_oer(scene, root, request),
                           "seconds": round(stats["total_s"], 1)})
            print(f"scene {index}: {scenes[-1]['fruit']} fruit", file=sys.stderr, flush=True)
    return {"size": list(size), "step": step, "scenes": scenes}


def measure_refused(count: int, size: tuple[int, int], generators: list[str]) -> dict:
    """Generate ``count`` SP scenes per crop with each plant generator; TVM-v0's refused moves.

    Returns:
        Per generator and crop: the counts of :func:`davis_ag.benchmark.moves.refused_moves`
        summed over the scenes, and the seconds the scenes took.
    """
    from davis_ag.data.reader import open_dataset
    from davis_ag.figures.dataset_stats import refused_move_statistics
    from davis_ag.generate.one_scene import SceneRequest, generate_scene
    from davis_ag.scene.camera import Camera

    out: dict = {"size": list(size), "scenes_per_crop": count, "generators": {}}
    for generator in generators:
        with tempfile.TemporaryDirectory() as folder:
            root = Path(folder)
            seconds = {}
            for crop in CROPS.values():
                started = time.perf_counter()
                for index in range(count):
                    generate_scene(SceneRequest(scenario_spec("sp", crop), crop, index, 0, Camera(*size),
                                                plants=generator), root)
                seconds[crop.name] = round(time.perf_counter() - started, 1)
                print(f"{generator} {crop.name}: {count} scenes", file=sys.stderr, flush=True)
            groups = refused_move_statistics(open_dataset(root))
            out["generators"][generator] = {crop.name: {**groups[group_name(scenario_spec("sp"), crop)],
                                                        "seconds": seconds[crop.name]} for crop in CROPS.values()}
    return out


def saved(name: str) -> dict | None:
    """A measurement saved under docs/, or None before it was made."""
    path = DOCS / name
    return json.loads(path.read_text()) if path.exists() else None


def refused_table() -> list[str]:
    """Markdown: the share of moves TVM-v0 refuses from its episode starts, per crop and generator."""
    data = saved("scenes-refused.json")
    if data is None:
        return []
    lines = [f"{data['scenes_per_crop']} single-plant scenes per crop (dataset seed 0) at "
             f"{data['size'][0]}x{data['size'][1]}, every eligible start (a view and a target with OER "
             f"below 0.4 and the crop's visible pixels) and every move of TVM-v0 (`davis-ag stats`); "
             f"{data['machine']}.", "",
             "| crop | plants | starts | moves refused | no view there | target not boxed there |",
             "|---|---|---|---|---|---|"]
    for generator, crops in data["generators"].items():
        for crop, c in crops.items():
            share = f"{(c['no_view'] + c['target_lost']) / c['moves']:.1%}" if c["moves"] else "-"
            lines.append(f"| {crop} | {generator} | {c['starts']:,} | {share} | {c['no_view']:,} | "
                         f"{c['target_lost']:,} |")
    return lines


def seeable(crop):
    """The crop with every fruit that the Synthetic Annotation plug-in would box boxed (Fig. 2)."""
    return dataclasses.replace(crop, min_fruit_pixels=SEEABLE_FRUIT_PIXELS)


def published_pixels(request) -> int:
    """The box threshold a published dataset keeps for a request's crop: its 210 pixels (strawberry),
    ``CROPS``' own whatever :func:`seeable` lowered, scaled to the request's image."""
    return dataclasses.replace(request, crop=CROPS[request.crop.name]).min_fruit_pixels


def published_oer(scene, root: Path, request) -> list[float]:
    """OER of a scene's boxes that the published dataset keeps (:func:`published_pixels`).

    Args:
        scene: A scene generated with :func:`seeable`'s threshold.
        root: The dataset folder it lies in.
        request: Its request.
    """
    from davis_ag.benchmark.cache import load_scene_cache

    cache = load_scene_cache(scene, root)
    return [round(float(v), 4) for v in cache.box_oer[cache.box_pixels >= published_pixels(request)]]


def visibility_findings(scene, meta: dict) -> dict:
    """Visible fruit per position and altitude changes of one generated scene.

    Args:
        scene: The scene, from :func:`davis_ag.data.reader.open_dataset`.
        meta: Its scene.json.

    Returns:
        Fruit count, boxed fruit per view (``visible``; generated with :func:`seeable`, the fruit
        the Synthetic Annotation plug-in would box), views that box every fruit, and the
        (position, altitude) pairs where moving up loses and gains fruit.
    """
    seen: dict[tuple[int, int, int], set[int]] = {}
    for view in scene:
        ix, iy, level, _ = meta["views"][view.name]["grid"]
        seen[ix, iy, level] = {box.fruit_id for box in view.boxes}
    fruit = len(meta["fruits"])
    pairs = [(below, seen[ix, iy, level + 1]) for (ix, iy, level), below in seen.items()
             if (ix, iy, level + 1) in seen]
    return {
        "fruit": fruit,
        "fruit_per_plant": [p["fruit_count"] for p in meta["plants"]],
        "visible": [len(s) for s in seen.values()],
        "views_seeing_all": sum(len(s) == fruit for s in seen.values()),
        "up_pairs": len(pairs),
        "up_loses": sum(bool(low - high) for low, high in pairs),
        "up_gains": sum(bool(high - low) for low, high in pairs),
    }


def views_table() -> list[str]:
    """Markdown rows: images per scene, ours beside Table 3's."""
    views_file = DOCS / "scenes-views.json"
    if not views_file.exists():
        return []
    views = json.loads(views_file.read_text())
    lines = ["| images per scene | strawberry | tomato | vine |", "|---|---|---|---|"]
    for scenario, title in (("sp", "SP"), ("mp", "MP")):
        for who in ("ours", "paper (Table 3)"):
            cells = [f"{views[f'{scenario}-{c}'][who.split()[0]]:,}" for c in ("strawberry", "tomato", "vine")]
            lines.append(f"| {title}, {who} | {' | '.join(cells)} |")
    return lines


#: Plant measurements per generator: the default's, kept fresh by ``plants N``, and the
#: PlantArchitecture plants' as last measured (2026-11-22, before the Canopy Generator plants).
PLANT_FILES = {"canopy": "scenes-plants.json", "architecture": "scenes-plants-architecture.json"}


def plants_table() -> list[str]:
    """Markdown: fruit per plant, measured phenotypes and growing time, per crop and generator."""
    intro: list[str] = []
    lines: list[str] = []
    for generator, name in PLANT_FILES.items():
        plants_file = DOCS / name
        if not plants_file.exists():
            continue
        data = json.loads(plants_file.read_text())
        if not lines:
            lines = ["| crop | plants | fruit per plant: min / median / max | plant (vine: trunk) height, m | "
                     "fruit (vine: berry) radius, mm | leaf length, m | all in Table 1 +- spread | "
                     "seconds per plant, median (shared machine) |",
                     "|---|---|---|---|---|---|---|---|"]
        for crop_name, plants in data["crops"].items():
            crop = CROPS[crop_name]
            fruit = [p["fruit_count"] for p in plants]
            measured = {k: [p["phenotype_measured"][k] for p in plants]
                        for k in ("plant_height", "fruit_radius", "leaf_length")}
            # 0.1 % of slack: a canopy plant is built at its drawn phenotype, which may lie on the edge.
            inside = all(abs(p["phenotype_measured"][k] / getattr(crop, k) - 1) <= PHENOTYPE_SPREAD[k] + 1e-3
                         for p in plants for k in measured)
            span = {k: f"{min(v) * (1000 if k == 'fruit_radius' else 1):.{1 if k == 'fruit_radius' else 2}f}-"
                       f"{max(v) * (1000 if k == 'fruit_radius' else 1):.{1 if k == 'fruit_radius' else 2}f}"
                    for k, v in measured.items()}
            seconds = [p["build_s"] if p.get("build_s") is not None else p["grow_s"] for p in plants]
            lines.append(f"| {crop_name} | {generator} | {min(fruit)} / {np.median(fruit):g} / {max(fruit)} | "
                         f"{span['plant_height']} | {span['fruit_radius']} | {span['leaf_length']} | "
                         f"{'yes' if inside else 'no'} | {np.median(seconds):.1f} |")
        intro.append(f"- `{generator}`: {data['plants_per_crop']} single plants per crop, grown as `davis-ag "
                     f"generate --plants {generator}` grows them (scene seeds of dataset seed 0, scenes "
                     f"0-{data['plants_per_crop'] - 1}); {data['machine']}.")
    return [*intro, "", *lines] if lines else []


def findings_file(size: tuple[int, int]) -> Path:
    """Where the findings measured at one image size are kept (the OER share depends on it)."""
    return DOCS / f"scenes-findings-{size[0]}x{size[1]}.json"


def findings_table() -> list[str]:
    """Markdown: the findings measured at every image size measured, smallest first."""
    files = sorted(DOCS.glob("scenes-findings-*x*.json"), key=lambda f: int(f.stem.split("-")[-1].split("x")[0]))
    lines: list[str] = []
    for path in files:
        lines += findings_lines(json.loads(path.read_text()))
    return lines


def findings_lines(data: dict) -> list[str]:
    """Markdown: the section IV and V-C findings measured on generated strawberry scenes of one size."""
    scenes = data["scenes"]
    oer = np.concatenate([s["box_oer"] for s in scenes])
    lines = [f"{len(scenes)} scenes (dataset seed 0, scenes 0-{len(scenes) - 1}) generated at "
              f"{data['size'][0]}x{data['size'][1]} on the grid every {data.get('step', 0.25):g} m "
              "(the paper's: 0.25 m); a fruit is visible when the Synthetic Annotation plug-in would box "
              f"it ({SEEABLE_FRUIT_PIXELS} pixels at 1280x720), the boxes are those of at least 210 "
              "pixels (both scaled with the image area); "
              f"{data['machine']}. Section IV: one plant with 24 fruit; visible fruit from fewer than 5 "
              "to 16 or more across positions; no view sees all 24; Fig. 3: changing altitude at a "
              "position both loses and gains fruit. Section V-C: 4 % of boxes have OER < 0.4.", "",
              "| scene | fruit | visible per view: min / median / max | views < 5 | views >= 16 | "
              "views seeing all | going up loses / gains fruit (of pairs) | boxes | OER < 0.4 |",
              "|---|---|---|---|---|---|---|---|---|"]
    for index, s in enumerate(scenes):
        visible = np.asarray(s["visible"])
        box_oer = np.asarray(s["box_oer"])
        lines.append(f"| {index:03d} | {s['fruit']} | {visible.min()} / {np.median(visible):g} / {visible.max()} | "
                     f"{(visible < 5).sum()} | {(visible >= 16).sum()} | {s['views_seeing_all']} | "
                     f"{s['up_loses']} / {s['up_gains']} (of {s['up_pairs']}) | {len(box_oer)} | "
                     f"{(box_oer < 0.4).mean():.1%} |")
    skew = skewness(oer)
    per_scene = ", ".join(f"{skewness(np.asarray(scene['box_oer'])):.2f}" for scene in scenes)
    lines += ["", f"All scenes: {len(oer):,} boxes, {(oer < 0.4).mean():.1%} with OER < 0.4 (paper: 4 %); "
                  f"OER median {np.median(oer):.2f}, mean {oer.mean():.2f}, skewness {skew:.2f} (the "
                  "paper's \"right-skewed\": the mass to the right, a tail towards 0, i.e. skewness < 0, "
                  f"is {'true' if skew < 0 else 'false'}; per scene "
                  f"{per_scene}).", ""]
    return lines


def recipes_table() -> list[str]:
    """Markdown: the strawberry recipes tried for Fig. 2 and the OER share (tools/strawberry_recipes.py)."""
    data = saved("scenes-strawberry-recipes.json")
    if data is None:
        return []
    # Recipes are PlantArchitecture shoot parameters; a file from before the key existed measured those plants.
    plants = data.get("plants", "architecture")
    lines = [f"The shoot recipes of the `--plants {plants}` strawberry (`scene/shoot_recipes.py`; the default "
             "Canopy Generator plants take Table 1's parameters instead). "
             f"Scenes {', '.join(str(i) for i in data['scenes'])} of dataset seed 0, grown under each recipe and "
             f"drawn at {data['size'][0]}x{data['size'][1]} on the grid every {data['step']:g} m, at both "
             f"strawberry altitude sets (`tools/strawberry_recipes.py`; {data['machine']}). \"hidden by fruit\": "
             "of the box pixels that are not the target in boxes with OER < 0.4, the share covered by other fruit.",
             "", "| recipe | altitudes | visible per view: min / median / max | views < 5 | views >= 16 | "
             "scenes meeting Fig. 2 (< 5 and >= 16 somewhere) | OER < 0.4 | in 2-8 % | hidden by fruit | visible fraction of those fruit (median) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for row in data["recipes"]:
        visible = np.concatenate([s["visible"] for s in row["scenes"]])
        oer = np.concatenate([s["box_oer"] for s in row["scenes"]])
        share = float((oer < 0.4).mean())
        fig2 = sum(min(s["visible"]) < 5 and max(s["visible"]) >= 16 for s in row["scenes"])
        by_fruit = [s["low_hidden_by_fruit"] for s in row["scenes"] if s["low_hidden_by_fruit"] is not None]
        low_vf = [s["low_visible_fraction"] for s in row["scenes"] if s["low_visible_fraction"] is not None]
        lines.append(f"| {row['recipe']}: {row['idea']} | {row['altitudes']} | {visible.min()} / "
                     f"{np.median(visible):g} / {visible.max()} | {(visible < 5).sum()} | {(visible >= 16).sum()} | "
                     f"{fig2} of {len(row['scenes'])} | {share:.1%} | {'yes' if 0.02 <= share <= 0.08 else 'no'} | "
                     f"{np.mean(by_fruit):.0%} | {np.median(low_vf):.2f} |")
    return lines + [""]


def skewness(values: np.ndarray) -> float:
    """Sample skewness (third standardised moment): negative when the tail points to low values."""
    centred = np.asarray(values, dtype=float) - np.mean(values)
    return float(np.mean(centred**3) / np.mean(centred**2) ** 1.5)


def render_markdown() -> str:
    """docs/scenes.md from the saved measurements."""
    lines = ["# Our scenes beside the paper's", "",
             "Written by `tools/scene_stats.py` from its measurements (docs/scenes-*.json); "
             "do not edit by hand.", ""]
    if views := views_table():
        lines += ["## Images per scene (Table 3)", "", *views, ""]
    if plants := plants_table():
        lines += ["## Fruit per plant", "", *plants, ""]
    if refused := refused_table():
        lines += ["## Moves the benchmark refuses from its episode starts", "", *refused, ""]
    if findings := findings_table():
        lines += ["## The paper's findings on single-plant strawberry scenes", "", *findings]
    if recipes := recipes_table():
        lines += ["## PlantArchitecture strawberry recipes tried for Fig. 2 and the OER share together", "",
                  *recipes]
    return "\n".join(lines)


def main(argv: list[str]) -> None:
    """Run one measurement (or none) and rewrite docs/scenes.md."""
    machine = (f"{platform.machine()} with {os.cpu_count()} cores, measured {time.strftime('%Y-%m-%d')} "
               f"(load average {os.getloadavg()[0]:.1f} at the end: times are those of a shared machine)")
    if argv and argv[0] == "views":
        write_json_atomic(DOCS / "scenes-views.json", measure_views(), indent=1)
    elif argv and argv[0] == "plants":
        # Crops measured earlier are kept: the vine takes long, so crops can be measured apart.
        path = DOCS / "scenes-plants.json"
        crops = argv[2].split(",") if len(argv) > 2 else list(CROPS)
        fresh = measure_plants(int(argv[1]), crops)
        saved = json.loads(path.read_text()) if path.exists() else {"crops": {}}
        merged = {**saved, **fresh, "crops": {**saved["crops"], **fresh["crops"]}, "machine": machine}
        merged["crops"] = {name: merged["crops"][name] for name in CROPS if name in merged["crops"]}
        write_json_atomic(path, merged, indent=1)
    elif argv and argv[0] == "refused":
        size = tuple(int(v) for v in argv[2].split("x"))
        generators = argv[3].split(",") if len(argv) > 3 else ["canopy", "architecture"]
        write_json_atomic(DOCS / "scenes-refused.json",
                          {**measure_refused(int(argv[1]), size, generators), "machine": machine}, indent=1)
    elif argv and argv[0] == "findings":
        size = tuple(int(v) for v in argv[2].split("x"))
        step = float(argv[3]) if len(argv) > 3 else 0.25
        write_json_atomic(findings_file(size),
                          {**measure_findings(int(argv[1]), size, step), "machine": machine}, indent=1)
    write_text_atomic(DOCS / "scenes.md", render_markdown())
    update_docs_pages({"views": views_table(), "plants": plants_table(), "findings": findings_table()})


def update_docs_pages(blocks: dict[str, list[str]]) -> None:
    """Replace the ``<!-- scene-stats:NAME -->`` blocks of the docs pages that hold them
    (docs/dataset-format.md: views; docs/plants.md: plants, findings) with the measured tables."""
    for page in sorted(DOCS.glob("*.md")):
        text = original = page.read_text()
        for name, lines in blocks.items():
            begin, end = f"<!-- scene-stats:{name} -->", f"<!-- /scene-stats:{name} -->"
            if lines and begin in text and end in text:
                head, _, tail = text.partition(begin)
                _, _, tail = tail.partition(end)
                text = head + begin + "\n" + "\n".join(lines) + "\n" + end + tail
        if text != original:
            write_text_atomic(page, text)


if __name__ == "__main__":
    main(sys.argv[1:])

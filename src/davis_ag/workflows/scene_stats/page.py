"""docs/scenes.md and the marked tables of docs/dataset-format.md, docs/plants.md and docs/crops.md, written from the
measurements ``davis-ag scene-stats`` keeps in ``docs/data/`` (:mod:`davis_ag.workflows.scene_stats.stats`)."""

from __future__ import annotations

import json
import os
import platform
import time
from pathlib import Path

import numpy as np

from davis_ag.atomic_files import read_page, write_json_atomic, write_text_atomic
from davis_ag.errors import UserError
from davis_ag.scene.specs import CROPS, PHENOTYPE_SPREAD, SEEABLE_FRUIT_PIXELS
from davis_ag.workflows.scene_stats.library_crops import CROPS_FILE, library_crops_table, library_recipes_table

#: The measurements' folder below the docs folder.
DATA = "data"


def saved(docs: Path, name: str) -> dict | None:
    """A measurement saved under docs/data/, or None before it was made."""
    path = docs / DATA / name
    return json.loads(path.read_text()) if path.exists() else None


def refused_table(docs: Path) -> list[str]:
    """Markdown: the share of moves TVM-v0 refuses from its episode starts, per crop and generator."""
    data = saved(docs, "scenes-refused.json")
    if data is None:
        return []
    lines = [
        f"{data['scenes_per_crop']} single-plant scenes per crop (dataset seed 0) at "
        f"{data['size'][0]}x{data['size'][1]}, every eligible start (a view and a target with OER "
        f"below 0.4 and the crop's visible pixels) and every move of TVM-v0 (`davis-ag stats`); "
        f"{data['machine']}.",
        "",
        "| crop | plants | starts | moves refused | no view there | target not boxed there |",
        "|---|---|---|---|---|---|",
    ]
    for generator, crops in data["generators"].items():
        for crop, c in crops.items():
            share = f"{(c['no_view'] + c['target_lost']) / c['moves']:.1%}" if c["moves"] else "-"
            lines.append(
                f"| {crop} | {generator} | {c['starts']:,} | {share} | {c['no_view']:,} | {c['target_lost']:,} |"
            )
    return lines


def views_table(docs: Path) -> list[str]:
    """Markdown rows: images per scene, ours beside Table 3's."""
    views_file = docs / DATA / "scenes-views.json"
    if not views_file.exists():
        return []
    views = json.loads(views_file.read_text())
    lines = ["| images per scene | strawberry | tomato | vine |", "|---|---|---|---|"]
    for scenario, title in (("sp", "SP"), ("mp", "MP")):
        for who in ("ours", "paper (Table 3)"):
            cells = [f"{views[f'{scenario}-{c}'][who.split()[0]]:,}" for c in ("strawberry", "tomato", "vine")]
            lines.append(f"| {title}, {who} | {' | '.join(cells)} |")
    return lines


#: Plant measurements per generator: the default's (``plants N``) and the PlantArchitecture
#: plants' (``plants N --generators architecture``).
PLANT_FILES = {"canopy": "scenes-plants.json", "architecture": "scenes-plants-architecture.json"}


def plants_table(docs: Path) -> list[str]:
    """Markdown: fruit per plant, measured phenotypes and growing time, per crop and generator."""
    intro: list[str] = []
    lines: list[str] = []
    for generator, name in PLANT_FILES.items():
        plants_file = docs / DATA / name
        if not plants_file.exists():
            continue
        data = json.loads(plants_file.read_text())
        if not lines:
            lines = [
                "| crop | plants | fruit per plant: min / median / max | plant (vine: trunk) height, m | "
                "fruit (vine: berry) radius, mm | leaf length, m | all in Table 1 +- spread | "
                "seconds per plant, median (shared machine) |",
                "|---|---|---|---|---|---|---|---|",
            ]
        for crop_name, plants in data["crops"].items():
            crop = CROPS[crop_name]
            fruit = [p["fruit_count"] for p in plants]
            measured = {
                k: [p["phenotype_measured"][k] for p in plants] for k in ("plant_height", "fruit_radius", "leaf_length")
            }
            # 0.1 % of slack: a canopy plant is built at its drawn phenotype, which may lie on the edge.
            inside = all(
                abs(p["phenotype_measured"][k] / getattr(crop, k) - 1) <= PHENOTYPE_SPREAD[k] + 1e-3
                for p in plants
                for k in measured
            )
            span = {
                k: f"{min(v) * (1000 if k == 'fruit_radius' else 1):.{1 if k == 'fruit_radius' else 2}f}-"
                f"{max(v) * (1000 if k == 'fruit_radius' else 1):.{1 if k == 'fruit_radius' else 2}f}"
                for k, v in measured.items()
            }
            seconds = [p["build_s"] if p.get("build_s") is not None else p["grow_s"] for p in plants]
            lines.append(
                f"| {crop_name} | {generator} | {min(fruit)} / {np.median(fruit):g} / {max(fruit)} | "
                f"{span['plant_height']} | {span['fruit_radius']} | {span['leaf_length']} | "
                f"{'yes' if inside else 'no'} | {np.median(seconds):.1f} |"
            )
        intro.append(
            f"- `{generator}`: {data['plants_per_crop']} single plants per crop, grown as `davis-ag "
            f"generate --plants {generator}` grows them (scene seeds of dataset seed 0, scenes "
            f"0-{data['plants_per_crop'] - 1}); {data['machine']}."
        )
    return [*intro, "", *lines] if lines else []


def findings_file(docs: Path, size: tuple[int, int]) -> Path:
    """Where the findings measured at one image size are kept (the OER share depends on it)."""
    return docs / DATA / f"scenes-findings-{size[0]}x{size[1]}.json"


def findings_table(docs: Path) -> list[str]:
    """Markdown: the findings measured at every image size measured, smallest first."""
    files = sorted(
        (docs / DATA).glob("scenes-findings-*x*.json"), key=lambda f: int(f.stem.split("-")[-1].split("x")[0])
    )
    lines: list[str] = []
    for path in files:
        lines += findings_lines(json.loads(path.read_text()))
    return lines


def findings_lines(data: dict) -> list[str]:
    """Markdown: the section IV and V-D findings measured on generated strawberry scenes of one size."""
    scenes = data["scenes"]
    oer = np.concatenate([s["box_oer"] for s in scenes])
    lines = [
        f"{len(scenes)} scenes (dataset seed 0, scenes 0-{len(scenes) - 1}) generated at "
        f"{data['size'][0]}x{data['size'][1]} on the grid every {data.get('step', 0.25):g} m "
        "(the paper's: 0.25 m); a fruit is visible when the Synthetic Annotation plug-in would box "
        f"it ({SEEABLE_FRUIT_PIXELS} pixels at 1280x720), the boxes are those of at least 210 "
        "pixels (both scaled with the image area); "
        f"{data['machine']}. Section IV: one plant with 24 fruit; visible fruit from fewer than 5 "
        "to 16 or more across positions; no view sees all 24; Fig. 3: changing altitude at a "
        "position both loses and gains fruit. Section V-D: 4 % of boxes have OER < 0.4.",
        "",
        "| scene | fruit | visible per view: min / median / max | views < 5 | views >= 16 | "
        "views seeing all | going up loses / gains fruit (of pairs) | boxes | OER < 0.4 |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for index, s in enumerate(scenes):
        visible = np.asarray(s["visible"])
        box_oer = np.asarray(s["box_oer"])
        lines.append(
            f"| {index:03d} | {s['fruit']} | {visible.min()} / {np.median(visible):g} / {visible.max()} | "
            f"{(visible < 5).sum()} | {(visible >= 16).sum()} | {s['views_seeing_all']} | "
            f"{s['up_loses']} / {s['up_gains']} (of {s['up_pairs']}) | {len(box_oer)} | "
            f"{(box_oer < 0.4).mean():.1%} |"
        )
    skew = skewness(oer)
    per_scene = ", ".join(f"{skewness(np.asarray(scene['box_oer'])):.2f}" for scene in scenes)
    lines += [
        "",
        f"All scenes: {len(oer):,} boxes, {(oer < 0.4).mean():.1%} with OER < 0.4 (paper: 4 %); "
        f"OER median {np.median(oer):.2f}, mean {oer.mean():.2f}, skewness {skew:.2f} (the "
        'paper\'s "right-skewed": the mass to the right, a tail towards 0, i.e. skewness < 0, '
        f"is {'true' if skew < 0 else 'false'}; per scene "
        f"{per_scene}).",
        "",
    ]
    return lines


def recipes_table(docs: Path) -> list[str]:
    """Markdown: the strawberry recipes tried for Fig. 2 and the OER share (a finished measurement)."""
    data = saved(docs, "scenes-strawberry-recipes.json")
    if data is None:
        return []
    # Recipes are PlantArchitecture shoot parameters; a file from before the key existed measured those plants.
    plants = data.get("plants", "architecture")
    lines = [
        f"The shoot recipes of the `--plants {plants}` strawberry (`scene/shoot_recipes.py`; the default "
        "Canopy Generator plants take Table 1's parameters instead). "
        f"Scenes {', '.join(str(i) for i in data['scenes'])} of dataset seed 0, grown under each recipe and "
        f"drawn at {data['size'][0]}x{data['size'][1]} on the grid every {data['step']:g} m, at both "
        "strawberry altitude sets (a one-off measurement: `git show f39bb12:tools/strawberry_recipes.py` is "
        f'the script at the commit that wrote its numbers; {data["machine"]}). "hidden by fruit": '
        "of the box pixels that are not the target in boxes with OER < 0.4, the share covered by other fruit.",
        "",
        "| recipe | altitudes | visible per view: min / median / max | views < 5 | views >= 16 | "
        "scenes meeting Fig. 2 (< 5 and >= 16 somewhere) | OER < 0.4 | in 2-8 % | hidden by fruit | visible fraction of those fruit (median) |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    for row in data["recipes"]:
        visible = np.concatenate([s["visible"] for s in row["scenes"]])
        oer = np.concatenate([s["box_oer"] for s in row["scenes"]])
        share = float((oer < 0.4).mean())
        fig2 = sum(min(s["visible"]) < 5 and max(s["visible"]) >= 16 for s in row["scenes"])
        by_fruit = [s["low_hidden_by_fruit"] for s in row["scenes"] if s["low_hidden_by_fruit"] is not None]
        low_vf = [s["low_visible_fraction"] for s in row["scenes"] if s["low_visible_fraction"] is not None]
        lines.append(
            f"| {row['recipe']}: {row['idea']} | {row['altitudes']} | {visible.min()} / "
            f"{np.median(visible):g} / {visible.max()} | {(visible < 5).sum()} | {(visible >= 16).sum()} | "
            f"{fig2} of {len(row['scenes'])} | {share:.1%} | {'yes' if 0.02 <= share <= 0.08 else 'no'} | "
            f"{np.mean(by_fruit):.0%} | {np.median(low_vf):.2f} |"
        )
    return [*lines, ""]


def skewness(values: np.ndarray) -> float:
    """Sample skewness (third standardised moment): negative when the tail points to low values."""
    centred = np.asarray(values, dtype=float) - np.mean(values)
    return float(np.mean(centred**3) / np.mean(centred**2) ** 1.5)


def render_markdown(docs: Path) -> str:
    """docs/scenes.md from the saved measurements: each table once, so a table another page holds
    between its ``<!-- scene-stats:NAME -->`` markers is a link here (:func:`update_docs_pages`)."""
    lines = [
        "# Our scenes beside the paper's",
        "",
        "Written by `davis-ag scene-stats` from its measurements (docs/data/scenes-*.json); do not edit by hand.",
        "",
    ]
    sections = [
        ("views", "Images per scene (Table 3)", views_table(docs)),
        ("plants", "Fruit per plant", plants_table(docs)),
        ("crops", "The plant-library crops beside the literature", library_crops_table(docs / DATA / CROPS_FILE)),
        ("refused", "Moves the benchmark refuses from its episode starts", refused_table(docs)),
        ("findings", "The paper's findings on single-plant strawberry scenes", findings_table(docs)),
        (
            "recipes",
            "PlantArchitecture strawberry recipes tried for Fig. 2 and the OER share together",
            recipes_table(docs),
        ),
    ]
    for name, title, table in sections:
        if not table:
            continue
        holder = page_holding(docs, name)
        body = [f"In [{holder.name}]({holder.name}).", ""] if holder else [*table, ""]
        lines += [f"## {title}", "", *body]
    return "\n".join(lines).rstrip() + "\n"


def page_holding(docs: Path, name: str) -> Path | None:
    """The docs page (other than scenes.md) that holds the table ``name`` between its markers."""
    for page in sorted(docs.glob("*.md")):
        if page.name != "scenes.md" and f"<!-- scene-stats:{name} -->" in read_page(page, "--docs"):
            return page
    return None


def update_docs_pages(docs: Path, blocks: dict[str, list[str]]) -> None:
    """Replace the ``<!-- scene-stats:NAME -->`` blocks of the docs pages that hold them
    (docs/dataset-format.md: views; docs/plants.md: plants, findings) with the measured tables."""
    for page in sorted(docs.glob("*.md")):
        text = original = read_page(page, "--docs")
        for name, lines in blocks.items():
            begin, end = f"<!-- scene-stats:{name} -->", f"<!-- /scene-stats:{name} -->"
            if lines and begin in text and end in text:
                head, _, tail = text.partition(begin)
                _, _, tail = tail.partition(end)
                text = head + begin + "\n" + "\n".join(lines) + "\n" + end + tail
        if text != original:
            write_text_atomic(page, text)


def write_measurement(
    docs: Path,
    what: str | None,
    count: int = 10,
    size: tuple[int, int] = (1280, 720),
    crops: list[str] | None = None,
    generators: list[str] | None = None,
    step: float = 0.25,
) -> None:
    """Run one measurement (or none), save it under docs/data/, and rewrite docs/scenes.md and the
    marked tables of the other pages.

    Args:
        docs: The docs folder.
        what: ``views``, ``plants``, ``refused``, ``findings`` or None (only rewrite the pages).
        count: Plants per crop, or scenes.
        size: Image size of the generated scenes (``refused``, ``findings``).
        crops: Crops whose plants are grown (``plants``; the others keep their saved rows).
        generators: Plant generators compared (``refused``) or grown (``plants``; default canopy).
        step: Grid step, m (``findings``; 0.25 is the paper's).
    """
    from davis_ag.workflows.scene_stats import stats as scene_stats

    machine = (
        f"{platform.machine()} with {os.cpu_count()} cores, measured {time.strftime('%Y-%m-%d')} "
        f"(load average {os.getloadavg()[0]:.1f} at the end: times are those of a shared machine)"
    )
    data = docs / DATA
    if what == "views":
        write_json_atomic(data / "scenes-views.json", scene_stats.measure_views(), indent=1)
    elif what == "plants":
        # Crops measured earlier are kept: the vine takes long, so crops can be measured apart.
        paper = [name for name in CROPS if CROPS[name].source == "canopy"]
        if others := [name for name in crops or [] if name not in paper]:
            raise UserError(f"--crops {','.join(others)}: 'plants' measures the paper's crops; use 'crops'")
        for generator in generators or ["canopy"]:
            path = data / PLANT_FILES[generator]
            fresh = scene_stats.measure_plants(count, crops or paper, generator)
            before = json.loads(path.read_text()) if path.exists() else {"crops": {}}
            merged = {**before, **fresh, "crops": {**before["crops"], **fresh["crops"]}, "machine": machine}
            merged["crops"] = {name: merged["crops"][name] for name in CROPS if name in merged["crops"]}
            write_json_atomic(path, merged, indent=1)
    elif what == "crops":
        library = [name for name in CROPS if CROPS[name].source == "library"]
        others = [name for name in crops or [] if name not in library]
        if others:
            raise UserError(f"--crops {','.join(others)}: 'crops' measures the plant-library crops; use 'plants'")
        path = data / CROPS_FILE
        fresh = scene_stats.measure_plants(count, crops or library)
        before = json.loads(path.read_text()) if path.exists() else {"crops": {}}
        merged = {**before, **fresh, "crops": {**before["crops"], **fresh["crops"]}, "machine": machine}
        merged["crops"] = {name: merged["crops"][name] for name in library if name in merged["crops"]}
        write_json_atomic(path, merged, indent=1)
    elif what == "refused":
        write_json_atomic(
            data / "scenes-refused.json",
            {**scene_stats.measure_refused(count, size, generators or ["canopy", "architecture"]), "machine": machine},
            indent=1,
        )
    elif what == "findings":
        write_json_atomic(
            findings_file(docs, size), {**scene_stats.measure_findings(count, size, step), "machine": machine}, indent=1
        )
    write_text_atomic(docs / "scenes.md", render_markdown(docs))
    update_docs_pages(
        docs,
        {
            "views": views_table(docs),
            "plants": plants_table(docs),
            "crops": library_crops_table(docs / DATA / CROPS_FILE),
            "crop-recipes": library_recipes_table(),
            "findings": findings_table(docs),
        },
    )

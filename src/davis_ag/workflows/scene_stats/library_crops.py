"""docs/crops.md's table of the plant-library crops as grown, beside the literature.

Written by ``davis-ag scene-stats crops`` from its measurement (``docs/data/scenes-crops.json``:
single plants grown as ``davis-ag generate`` grows them) and the published figures each crop's
recipe was checked against (:data:`davis_ag.scene.crop_literature.LITERATURE`).
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np

from davis_ag.scene.crop_literature import LITERATURE
from davis_ag.scene.library_crops import LIBRARY_RECIPES

#: The measurement's file below docs/data/.
CROPS_FILE = "scenes-crops.json"


def _span(values: list[float], scale: float = 1.0, digits: int = 2) -> str:
    values = [v * scale for v in values if v == v]  # NaN (no fruit measured) left out
    if not values:
        return "–"
    return f"{min(values):.{digits}f}-{max(values):.{digits}f}"


def library_crops_table(path: Path) -> list[str]:
    """Markdown: per crop, the model and age, fruit per plant, fruit diameter, height and crown width
    as grown (min-max over the plants), each beside the literature's, primitives and seconds.

    Args:
        path: The measurement (``docs/data/scenes-crops.json``).

    Returns:
        The lines, or none where the measurement was not made.
    """
    if not path.is_file():
        return []
    data = json.loads(path.read_text())
    lines = [
        f"{data['plants_per_crop']} single plants per crop, grown as `davis-ag generate` grows them "
        f"(scene seeds of dataset seed 0); {data.get('machine', 'machine not recorded')}. Each measured "
        "figure is min-max over the plants (a fruit's size: the median over its fruit of the largest and "
        "middle extents along its principal axes); the literature's follows in brackets, `-` where the "
        "sources give none.",
        "",
        "| crop | library model, age (days) | fruit per plant | fruit length x width, mm | height, m | "
        "crown along the row (x) / across it (y), m | primitives | seconds per plant |",
        "|---|---|---|---|---|---|---|---|",
    ]
    for name, plants in data["crops"].items():
        recipe, seen = LIBRARY_RECIPES[name], LITERATURE[name]
        fruit = [p["fruit_count"] for p in plants]
        library = [p.get("library", {}) for p in plants]
        lengths = [lib.get("fruit_length_m", float("nan")) for lib in library]
        widths = [lib.get("fruit_diameter_m", float("nan")) for lib in library]
        heights = [p["phenotype_measured"]["plant_height"] for p in plants]
        along = [lib["width_m"][0] for lib in library if len(lib.get("width_m", [])) == 2]
        across = [lib["width_m"][1] for lib in library if len(lib.get("width_m", [])) == 2]
        primitives = [p["primitives"] for p in plants if "primitives" in p]
        seconds = [p["build_s"] if p.get("build_s") is not None else p["grow_s"] for p in plants]
        lines.append(
            f"| {name} | {recipe.model}, {recipe.age_days:g} | {min(fruit)}-{max(fruit)} "
            f"(median {np.median(fruit):g}) [{seen.fruit_per_plant}] | "
            f"{_span(lengths, 1000, 0)} x {_span(widths, 1000, 0)} [{seen.fruit_size}] | "
            f"{_span(heights)} [{seen.plant_height}] | {_span(along)} / {_span(across)} | "
            f"{_span(primitives, 1e-3, 0)}K | {np.median(seconds):.1f} |"
        )
    lines += ["", "Sources of the bracketed figures:", ""]
    lines += [f"- {name}: {LITERATURE[name].source}" for name in data["crops"]]
    return lines


def library_recipes_table() -> list[str]:
    """Markdown: every plant-library crop's recipe, grids and row, from the code that grows them
    (:mod:`davis_ag.scene.library_crops`), so the page never disagrees with it.

    Returns:
        Two tables: how each crop grows, and where its cameras go.
    """
    from davis_ag.scene.specs import CROPS, camera_altitudes, scenario_spec
    from davis_ag.scene.view_grid import views_per_scene

    lines = [
        "| crop | library model | day built | changed from the library | fruit per plant kept | "
        "primitives (typical plant) |",
        "|---|---|---|---|---|---|",
    ]
    for name, recipe in LIBRARY_RECIPES.items():
        changes = [
            f"{shoot}: `{path.rsplit('.', 1)[-1]}` {value['parameters'][0]:g}"
            for shoot, path, value in recipe.shoot_changes
        ]
        if recipe.fruit_scale != 1.0:
            changes.append(f"fruit x{recipe.fruit_scale:g}")
        if recipe.build_parameters:
            changes += [f"`{key}` {value:g}" for key, value in recipe.build_parameters.items()]
        if recipe.yaw_deg:
            changes.append(f"turned {recipe.yaw_deg:g} deg to a row along x")
        low, high = recipe.fruit_range
        lines.append(
            f"| {name} | {recipe.model} | {recipe.age_days:g} | {'; '.join(changes) or 'none'} | {low}-{high} | "
            f"{recipe.primitives / 1000:.0f}K |"
        )
    lines += [
        "",
        "| crop | SP grid (views) | SP altitudes, m | row system | in the row x between rows, m | "
        "camera lines from the row, m | row heights, m | row views | source of the spacing |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for name in CROPS:
        crop = CROPS[name]
        row = crop.row
        if row is None:
            continue
        sp, row_scenario = scenario_spec("sp", crop), scenario_spec("row", crop)
        lines.append(
            f"| {name} | {sp.extent[0]:g} x {sp.extent[1]:g} m, step {sp.step:g} ({views_per_scene(sp, crop)}) | "
            f"{' / '.join(f'{a:g}' for a in crop.altitudes)} | {row.system} | {row.in_row_spacing:g} x "
            f"{row.row_spacing:g} | {row.standoff:g}, {row.standoff + row.step:g} | "
            f"{' / '.join(f'{a:g}' for a in camera_altitudes(row_scenario, crop))} | "
            f"{views_per_scene(row_scenario, crop)} | {row.source} |"
        )
    return lines

"""Which PlantArchitecture strawberry recipes meet section IV's Fig. 2 and section V-C's OER share at once (a tool).

    .venv/bin/python tools/strawberry_recipes.py [--scenes 0,3] [--size 1280x720]

Issue 10 asks for a single-strawberry scene where some views see fewer than 5 fruit and some 16
or more (Fig. 2), and for about 4 % of boxes with OER < 0.4 (section V-C, 2-8 % accepted). This
tool grows the same scenes with ``--plants architecture`` (the generator the recipes in
``scene/shoot_recipes.py`` shape; the default Canopy Generator plants take Table 1's parameters)
under candidate recipes (the default's keys overridden), at both
strawberry altitude sets, on the grid every 0.5 m, and measures for each: the Fig. 2 counts
(fruit the Synthetic Annotation plug-in would box, as ``tools/scene_stats.py`` counts them), the
OER < 0.4 share of the published boxes (210 pixels), and why boxes fall below 0.4: how much of a
low box's hidden area is covered by *other fruit* (slivers of fruit behind fruit) rather than by
leaves or stems, and the median visible fraction of those fruit. The results go to
docs/scenes-strawberry-recipes.json; ``tools/scene_stats.py`` puts them in docs/scenes.md.
"""

from __future__ import annotations

import argparse
import dataclasses
import json
import os
import platform
import sys
import tempfile
import time
from pathlib import Path

import numpy as np
from PIL import Image

import davis_ag.scene.shoot_recipes as shoot_recipes
from davis_ag.atomic_files import write_json_atomic

DOCS = Path(__file__).resolve().parent.parent / "docs"
OUT = DOCS / "scenes-strawberry-recipes.json"
P = "phytomer_parameters"
#: The plant generator whose shoots the recipes shape.
PLANTS = "architecture"
#: Our recipe, as the package ships it; every candidate overrides some of its keys.
DEFAULT_RECIPE = shoot_recipes.SHOOT_RECIPES["strawberry"]
#: Candidate recipes: a name, what they try, and the keys they override (uniform ranges).
CANDIDATES: tuple[tuple[str, str, dict[str, tuple[float, float]]], ...] = (
    ("default", "our recipe: fruit on 4-8 cm peduncles around a 5 cm crown, petioles arching over them", {}),
    ("longer peduncles", "fruit 10-18 cm out", {f"{P}.peduncle.length": (0.10, 0.18)}),
    ("long, low peduncles", "fruit 10-18 cm out, peduncles leaning 55-80 degrees",
     {f"{P}.peduncle.length": (0.10, 0.18), f"{P}.peduncle.pitch": (55.0, 80.0)}),
    ("spread fruit, upright leaves", "fruit 12-22 cm out; the library's petiole pitch and curvature",
     {f"{P}.peduncle.length": (0.12, 0.22), f"{P}.peduncle.pitch": (60.0, 85.0),
      f"{P}.petiole.pitch": (10.0, 45.0), f"{P}.petiole.curvature": (-150.0, -50.0)}),
    ("spread fruit, long petioles", "fruit 12-22 cm out under 25-40 cm petioles",
     {f"{P}.peduncle.length": (0.12, 0.22), f"{P}.peduncle.pitch": (60.0, 85.0),
      f"{P}.petiole.length": (0.25, 0.40)}),
    ("Canopy Generator reach", "fruit 15-28 cm out (its 10-30 cm) under 25-40 cm upright petioles",
     {f"{P}.peduncle.length": (0.15, 0.28), f"{P}.peduncle.pitch": (60.0, 85.0),
      f"{P}.petiole.pitch": (10.0, 45.0), f"{P}.petiole.curvature": (-150.0, -50.0),
      f"{P}.petiole.length": (0.25, 0.40)}),
)


def apply_recipe(overrides: dict[str, tuple[float, float]]) -> None:
    """Replace the strawberry's recipe in ``shoot_recipes`` with the default plus ``overrides``."""
    recipe = {path: spec for path, spec in DEFAULT_RECIPE}
    for key, (low, high) in overrides.items():
        recipe[tuple(key.split("."))] = shoot_recipes._uniform(low, high)
    shoot_recipes.SHOOT_RECIPES["strawberry"] = tuple(recipe.items())



def measure_scene(index: int, size: tuple[int, int], altitudes: str) -> dict:
    """Generate one SP strawberry scene and measure Fig. 2, the OER share and its causes.

    Args:
        index: Scene index of dataset seed 0.
        size: Image size.
        altitudes: ``table1`` or ``readme`` (``scene.specs.STRAWBERRY_ALTITUDES``).

    Returns:
        JSON-ready measurements of the scene.
    """
    sys.path.insert(0, str(Path(__file__).resolve().parent))
    from scene_stats import published_oer, published_pixels, seeable, visibility_findings

    from davis_ag.data.reader import open_dataset
    from davis_ag.generate.one_scene import SceneRequest, generate_scene
    from davis_ag.scene.camera import Camera
    from davis_ag.scene.specs import CROPS, scenario_spec, with_strawberry_altitudes

    crop = with_strawberry_altitudes(CROPS["strawberry"], altitudes)
    grid = dataclasses.replace(scenario_spec("sp", crop), step=0.5)
    with tempfile.TemporaryDirectory() as folder:
        root = Path(folder)
        request = SceneRequest(grid, seeable(crop), index, 0, Camera(*size), plants=PLANTS)
        threshold = published_pixels(request)
        scene_dir, _ = generate_scene(request, root)
        meta = json.loads((scene_dir / "scene.json").read_text())
        scene = open_dataset(root).scene(f"Single-Strawberry/{index:03d}")
        findings = visibility_findings(scene, meta)
        oer = np.asarray(published_oer(scene, root, request), dtype=float)
        hidden_by_fruit, low_visible = [], []
        for name, view in json.loads((scene_dir / "annotations.json").read_text()).items():
            seg = np.asarray(Image.open(scene_dir / "images" / name.replace(".jpeg", "_seg.png")))
            for x, y, w, h, fruit, _ in view["bounding_boxes"]:
                box = seg[y:y + h, x:x + w]
                target = box == fruit
                if (seg == fruit).sum() >= threshold and target.mean() < 0.4 and not target.all():
                    # Box pixels that are not the target: another boxed fruit, or anything else.
                    hidden_by_fruit.append(float(((box != fruit) & (box != 255)).sum() / (~target).sum()))
                    low_visible.append(meta["visible_fraction"][name][str(fruit)])
    return {"scene": index, "fruit": findings["fruit"], "visible": findings["visible"],
            "views_seeing_all": findings["views_seeing_all"], "up_loses": findings["up_loses"],
            "up_gains": findings["up_gains"], "up_pairs": findings["up_pairs"],
            "box_oer": [round(float(v), 4) for v in oer],
            "low_hidden_by_fruit": round(float(np.mean(hidden_by_fruit)), 3) if hidden_by_fruit else None,
            "low_visible_fraction": round(float(np.median(low_visible)), 3) if low_visible else None}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--scenes", default="0,3", help="scene indices of dataset seed 0 (default 0,3)")
    parser.add_argument("--size", default="1280x720", help="image size WxH (default the paper's 1280x720)")
    args = parser.parse_args()
    size = tuple(int(v) for v in args.size.split("x"))
    scenes = [int(v) for v in args.scenes.split(",")]
    rows = []
    for name, idea, overrides in CANDIDATES:
        apply_recipe(overrides)
        for altitudes in ("table1", "readme"):
            measured = [measure_scene(index, size, altitudes) for index in scenes]
            rows.append({"recipe": name, "idea": idea, "overrides": overrides, "altitudes": altitudes,
                         "scenes": measured})
            oer = np.concatenate([m["box_oer"] for m in measured])
            print(f"{name} [{altitudes}]: OER < 0.4 {100 * (oer < 0.4).mean():.1f} % of {len(oer)}; visible "
                  f"{min(min(m['visible']) for m in measured)}-{max(max(m['visible']) for m in measured)}",
                  flush=True)
    apply_recipe({})
    machine = (f"{platform.machine()} with {os.cpu_count()} cores, measured {time.strftime('%Y-%m-%d')}, "
               f"load average {os.getloadavg()[0]:.1f} at the end")
    write_json_atomic(OUT, {"plants": PLANTS, "size": list(size), "step": 0.5, "scenes": scenes, "machine": machine,
                            "recipes": rows}, indent=1)
    print(f"wrote {OUT}")


if __name__ == "__main__":
    main()

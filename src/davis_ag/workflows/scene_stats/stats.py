"""``davis-ag scene-stats``: measure our scenes against the paper (Table 3's images per scene, fruit
per plant, the Fig. 2-3 and section V-D findings, the moves TVM-v0 refuses), each measurement saved
to its own JSON file under ``docs/data/`` so that a slow one is not redone when another is refreshed.

- ``views``: images per scene for every crop and scenario, beside Table 3's (instant).
- ``plants --count N [--crops tomato,vine]``: fruit per plant and the measured phenotype of N
  single plants per crop, grown as ``davis-ag generate`` grows them (scene seeds of dataset seed 0,
  indices 0..N-1).
- ``findings --count N --size WxH [--step 0.5]``: N single-plant strawberry scenes generated at
  WxH (dataset seed 0), and the paper's section IV and V-D findings measured on them: visible
  fruit per position (fruit that Helios's Synthetic Annotation plug-in would box:
  ``specs.SEEABLE_FRUIT_PIXELS``), whether any view sees every fruit, how often changing altitude
  at a fixed position loses or gains fruit (Fig. 3), and the share of the published boxes (the
  crop's 210 pixels) with OER below 0.4; one file per image size, since that share depends on it.
- ``refused --count N --size WxH``: N single-plant scenes per crop with each plant generator, and
  the share of moves TVM-v0 refuses from its episode starts (:mod:`davis_ag.benchmark.moves`).

docs/scenes.md and the marked tables of the other pages are then rewritten from whichever files
exist (:mod:`davis_ag.workflows.scene_stats.page`).
"""

from __future__ import annotations

import dataclasses
import sys
import tempfile
import time
from pathlib import Path

import numpy as np

from davis_ag.data.reader import Scene
from davis_ag.scene.specs import CROPS, PAPER_TABLE3, SEEABLE_FRUIT_PIXELS, group_name, scenario_spec
from davis_ag.scene.view_grid import views_per_scene


def measure_views() -> dict:
    """Our images per scene and the paper's, per scenario and crop."""
    rows = {}
    for (scenario, crop_name), (scenes, images) in PAPER_TABLE3.items():
        crop = CROPS[crop_name]
        rows[f"{scenario}-{crop_name}"] = {
            "ours": views_per_scene(scenario_spec(scenario, crop), crop),
            "paper": images // scenes,
        }
    return rows


def measure_plants(count: int, crops: list[str], generator: str = "canopy") -> dict:
    """Grow ``count`` single plants of each of ``crops`` with the plant ``generator`` (``canopy``,
    ``architecture``; the plant-library crops grow from the library whatever it says) as
    ``generate`` grows them; their fruit counts, phenotypes and primitives."""
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.scene.build import build_scene

    out: dict = {"plants_per_crop": count, "crops": {}}
    for crop in (CROPS[name] for name in crops):
        scenario = scenario_spec("sp", crop)
        plants = []
        for index in range(count):
            started = time.perf_counter()
            seed = SceneRequest(scenario, crop, index, 0).seed
            model = build_scene(scenario, crop, np.random.default_rng(seed), plants=generator)
            plant = model.plants[0]
            plants.append(
                {
                    **plant.summary(),
                    "build_s": None if plant.build_s is None else round(plant.build_s, 3),
                    "scene_seed": seed,
                    "grow_s": round(time.perf_counter() - started, 1),
                    "primitives": len(plant.uuids),
                }
            )
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
            _scene_dir, stats = generate_scene(request, root)
            scene = open_dataset(root).scene(f"Single-Strawberry/{index:03d}")
            scenes.append(
                {
                    **visibility_findings(scene),
                    "box_oer": published_oer(scene, root, request),
                    "seconds": round(stats["total_s"], 1),
                }
            )
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
                    generate_scene(
                        SceneRequest(scenario_spec("sp", crop), crop, index, 0, Camera(*size), plants=generator), root
                    )
                seconds[crop.name] = round(time.perf_counter() - started, 1)
                print(f"{generator} {crop.name}: {count} scenes", file=sys.stderr, flush=True)
            groups = refused_move_statistics(open_dataset(root))
            out["generators"][generator] = {
                crop.name: {**groups[group_name(scenario_spec("sp"), crop)], "seconds": seconds[crop.name]}
                for crop in CROPS.values()
            }
    return out


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


def visibility_findings(scene: Scene) -> dict:
    """Visible fruit per position and altitude changes of one generated scene.

    Args:
        scene: The scene, from :func:`davis_ag.data.reader.open_dataset`, with its scene.json.

    Returns:
        Fruit count, boxed fruit per view (``visible``; generated with :func:`seeable`, the fruit
        the Synthetic Annotation plug-in would box), views that box every fruit, and the
        (position, altitude) pairs where moving up loses and gains fruit.
    """
    meta = scene.metadata
    if meta is None or meta.views is None:
        raise ValueError(f"{scene.path}: no scene.json with the views' grid places")
    seen: dict[tuple[int, int, int], set[int]] = {}
    for view in scene:
        ix, iy, level, _ = meta.views[view.name].grid or (0, 0, 0, 0)
        seen[ix, iy, level] = {box.fruit_id for box in view.boxes}
    fruit = len(meta.fruits)
    pairs = [(below, seen[ix, iy, level + 1]) for (ix, iy, level), below in seen.items() if (ix, iy, level + 1) in seen]
    return {
        "fruit": fruit,
        "fruit_per_plant": [p.fruit_count for p in meta.plants],
        "visible": [len(s) for s in seen.values()],
        "views_seeing_all": sum(len(s) == fruit for s in seen.values()),
        "up_pairs": len(pairs),
        "up_loses": sum(bool(low - high) for low, high in pairs),
        "up_gains": sum(bool(high - low) for low, high in pairs),
    }

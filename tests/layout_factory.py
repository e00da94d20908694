"""Write tiny but fully consistent DAVIS-Ag datasets for tests (no renderer, no Helios).

The grid and pointers come from the real :func:`davis_ag.scene.view_grid.build_view_grid` on a shrunk
scenario, so an environment built on them sees the true action graph. The "renderer" is a
pinhole camera with a z-buffer over flat discs (fruits) and axis-aligned rectangles (leaves)
placed in 3-D around each plant: parallax moves leaves across fruits between views, so the
exposure rate varies and some fruits vanish from some views, exactly as occlusion does in the
real data.

Our writer's conventions, which :func:`write_tiny_dataset` follows to the pixel:

- keys and pointer values carry ".jpeg"; "" marks an invalid move;
- boxes are ``[xmin, ymin, width, height, fruit_id, 0]`` ints with the inclusive pixel extent
  of the fruit's mask (``width = xmax - xmin + 1``);
- the seg mask holds exactly the fruits that have a box in that view (255 elsewhere).

Import it from a test as ``from layout_factory import write_tiny_dataset`` (pytest puts the
``tests`` folder, which has no ``__init__.py``, on ``sys.path``).
"""

from __future__ import annotations

import json
import math
from dataclasses import dataclass, replace
from pathlib import Path

import numpy as np
from PIL import Image

from davis_ag.formats.layout import published_pointers, view_file_name, view_name
from davis_ag.scene import specs as config
from davis_ag.scene.specs import CropSpec, ScenarioSpec
from davis_ag.scene.view_grid import Viewpoint, build_view_grid

#: Visible pixels a fruit needs for a box at these tiny sizes (the real threshold is per crop).
TINY_MIN_FRUIT_PIXELS = 4
#: Horizontal field of view of the tiny camera, degrees.
TINY_HFOV_DEG = 70.0
_FRUITS_PER_PLANT = {"sp": 6, "mp": 3}
_LEAVES_PER_PLANT = 10
_FRUIT_RADIUS = 0.035  # exaggerated so a fruit spans several pixels at 128x72
_FRUIT_RGB = {"strawberry": (200, 30, 40), "tomato": (230, 70, 30), "vine": (90, 30, 110)}


def tiny_specs(scenario: str = "sp", crop: str = "strawberry") -> tuple[ScenarioSpec, CropSpec]:
    """The shrunk scenario and crop specs the factory lays its grid out with.

    SP: a 1 x 1 m staggered lattice of 0.25 m steps and three altitudes (54 views);
    MP: a 1 x 1 m lattice of 0.5 m steps, two altitudes and the real 12 headings (144-168 views).

    Args:
        scenario: ``sp`` or ``mp``.
        crop: ``strawberry``, ``tomato`` or ``vine``.

    Returns:
        ``(scenario_spec, crop_spec)``.
    """
    sc, cr = config.scenario_spec(scenario), config.crop_spec(crop)
    if sc.name == "sp":
        sc = replace(sc, extent=(1.0, 1.0), step=0.25)
    else:
        sc = replace(sc, extent=(1.0, 1.0), step=0.5)
    # Small exclusion radii, so the tiny grids keep positions around the plants (SP) and
    # beside the dense strawberry row (MP), with a hole where moves point to "".
    return sc, replace(cr, exclusion_radius=0.3 if sc.name == "sp" else 0.25)


@dataclass(frozen=True)
class _Camera:
    width: int
    height: int
    fx: float

    @property
    def as_json(self) -> dict[str, float]:
        return {
            "width": self.width,
            "height": self.height,
            "fx": self.fx,
            "fy": self.fx,
            "cx": self.width / 2,
            "cy": self.height / 2,
            "hfov_deg": TINY_HFOV_DEG,
            "vfov_deg": math.degrees(2 * math.atan(self.height / 2 / self.fx)),
        }

    def project(self, view: Viewpoint, point: np.ndarray) -> tuple[float, float, float]:
        """Pixel (u, v) and depth of a world point; depth <= 0 means behind the camera."""
        yaw, pitch = math.radians(view.yaw), math.radians(view.pitch)
        fwd = np.array([math.cos(pitch) * math.cos(yaw), math.cos(pitch) * math.sin(yaw), math.sin(pitch)])
        right = np.array([math.sin(yaw), -math.cos(yaw), 0.0])
        up = np.cross(right, fwd)
        d = point - np.asarray(view.position)
        depth = float(d @ fwd)
        if depth <= 1e-6:
            return 0.0, 0.0, depth
        return (
            self.width / 2 + self.fx * float(d @ right) / depth,
            self.height / 2 - self.fx * float(d @ up) / depth,
            depth,
        )


def _grow(sc: ScenarioSpec, cr: CropSpec, rng: np.random.Generator) -> tuple[list, list, list]:
    """Plants, fruits and leaves of one scene as JSON-ready dicts."""
    plants, fruits, leaves = [], [], []
    for p, (px, py) in enumerate(config.plant_positions(sc, cr)):
        height = cr.plant_height * rng.uniform(0.9, 1.1)
        plants.append({"id": p, "index": p, "position": [px, py, 0.0], "height": round(height, 4)})
        for _ in range(_FRUITS_PER_PLANT[sc.name]):
            angle, reach = rng.uniform(0, 2 * math.pi), rng.uniform(0.03, 0.12)
            centre = [px + reach * math.cos(angle), py + reach * math.sin(angle), height * rng.uniform(0.25, 0.75)]
            radius = _FRUIT_RADIUS * rng.uniform(0.8, 1.2)
            fruits.append(
                {
                    "id": len(fruits),
                    "plant": p,
                    "center": [round(c, 5) for c in centre],
                    "size": [round(2 * radius, 5)] * 3,
                }
            )
        for _ in range(_LEAVES_PER_PLANT):
            angle, reach = rng.uniform(0, 2 * math.pi), rng.uniform(0.08, 0.22)
            centre = [px + reach * math.cos(angle), py + reach * math.sin(angle), height * rng.uniform(0.2, 0.9)]
            leaves.append(
                {
                    "plant": p,
                    "center": [round(c, 5) for c in centre],
                    "half_size": round(rng.uniform(0.03, 0.06), 5),
                    "aspect": round(rng.uniform(0.5, 2.0), 3),
                    "shade": round(rng.uniform(0.7, 1.0), 3),
                }
            )
    return plants, fruits, leaves


def _render(
    camera: _Camera,
    view: Viewpoint,
    crop: str,
    fruits: list,
    leaves: list,
) -> tuple[np.ndarray, np.ndarray, dict[int, float]]:
    """RGB image, raw owner map (fruit id or -1) and each fruit's visible fraction."""
    h, w = camera.height, camera.width
    vv, uu = np.mgrid[0:h, 0:w] + 0.5
    sky = np.linspace(1.0, 0.75, h)[:, None, None] * np.array([150, 120, 90], dtype=float)
    rgb = np.broadcast_to(sky, (h, w, 3)).copy()
    depth = np.full((h, w), np.inf)
    owner = np.full((h, w), -1, dtype=np.int32)
    full_area: dict[int, float] = {}
    fruit_rgb = np.array(_FRUIT_RGB[crop], dtype=float)
    for fruit in fruits:
        u, v, d = camera.project(view, np.asarray(fruit["center"]))
        if d <= 0.05:
            continue
        r = camera.fx * fruit["size"][0] / 2 / d
        dist = np.hypot(uu - u, vv - v)
        cover = (dist <= r) & (d < depth)
        full_area[fruit["id"]] = math.pi * r * r
        depth[cover], owner[cover] = d, fruit["id"]
        shade = 1.0 - 0.35 * (dist[cover] / max(r, 1e-6))
        rgb[cover] = fruit_rgb * shade[:, None]
    for leaf in leaves:
        u, v, d = camera.project(view, np.asarray(leaf["center"]))
        if d <= 0.05:
            continue
        half = camera.fx * leaf["half_size"] / d
        cover = (np.abs(uu - u) <= half * leaf["aspect"]) & (np.abs(vv - v) <= half) & (d < depth)
        depth[cover], owner[cover] = d, -1
        rgb[cover] = np.array([40, 150, 50], dtype=float) * leaf["shade"]
    visible = {}
    for fid, area in full_area.items():
        seen = int(np.count_nonzero(owner == fid))
        if seen:
            visible[fid] = round(min(1.0, seen / area), 4)
    return np.clip(rgb, 0, 255).astype(np.uint8), owner, visible


def _boxes_and_mask(owner: np.ndarray) -> tuple[list[list[int]], np.ndarray]:
    """Boxes of the fruits with enough visible pixels, and the mask holding exactly those."""
    mask = np.full(owner.shape, 255, dtype=np.uint8)
    boxes = []
    for fid in sorted(int(i) for i in np.unique(owner) if i >= 0):
        ys, xs = np.nonzero(owner == fid)
        if len(xs) < TINY_MIN_FRUIT_PIXELS:
            continue
        mask[ys, xs] = fid
        x0, y0 = int(xs.min()), int(ys.min())
        boxes.append([x0, y0, int(xs.max()) - x0 + 1, int(ys.max()) - y0 + 1, fid, 0])
    return boxes, mask


def write_tiny_scene(
    scene_dir: Path, scenario: str = "sp", crop: str = "strawberry", seed: int = 0, size: tuple[int, int] = (128, 72)
) -> Path:
    """Write one scene folder (annotations.json, scene.json, images/) in our writer's layout.

    Args:
        scene_dir: The scene folder to create, e.g. ``root/Single-Strawberry/000``.
        scenario: ``sp`` or ``mp``.
        crop: ``strawberry``, ``tomato`` or ``vine``.
        seed: Seeds the plants, the slip and everything else; same seed, same bytes.
        size: Image width and height in pixels.

    Returns:
        ``scene_dir``.
    """
    sc, cr = tiny_specs(scenario, crop)
    rng = np.random.default_rng(seed)
    plants, fruits, leaves = _grow(sc, cr, rng)
    grid = build_view_grid(sc, cr, config.plant_centres(sc, cr), cr.plant_height / 2, rng)
    width, height = size
    camera = _Camera(width, height, width / 2 / math.tan(math.radians(TINY_HFOV_DEG) / 2))
    images = scene_dir / "images"
    images.mkdir(parents=True, exist_ok=True)
    annotations, visible_fraction, places = {}, {}, {}
    for view in grid.viewpoints:
        rgb, owner, visible = _render(camera, view, cr.name, fruits, leaves)
        boxes, mask = _boxes_and_mask(owner)
        name = view_name(view.number)
        Image.fromarray(rgb).save(images / name, "JPEG", quality=95)
        Image.fromarray(mask).save(images / view_file_name(name, "mask"))
        annotations[name] = {
            "bounding_boxes": boxes,
            "pose": [round(p, 5) for p in view.pose],
            **published_pointers(grid, view.index),
        }
        visible_fraction[name] = {str(k): v for k, v in sorted(visible.items())}
        places[name] = {"grid": [view.ix, view.iy, view.level, view.heading], "nominal": list(view.nominal)}
    (scene_dir / "annotations.json").write_text(json.dumps(annotations, indent=1))
    metadata = {
        "seed": seed,
        "generator": {"name": "tests/layout_factory.py"},
        "scenario": sc.name,
        "crop": cr.name,
        "camera": camera.as_json,
        "grid": {
            "extent": list(sc.extent),
            "step": sc.step,
            "headings": sc.headings,
            "altitudes": [cr.altitudes[i] for i in sc.altitude_levels],
            "exclusion_radius": cr.exclusion_radius,
            # Our writer's names for the same (scene.json's GridRecord).
            "extent_m": list(sc.extent),
            "step_m": sc.step,
            "altitudes_m": [cr.altitudes[i] for i in sc.altitude_levels],
        },
        "min_fruit_pixels": TINY_MIN_FRUIT_PIXELS,
        "plants": plants,
        "fruits": fruits,
        "leaves": leaves,
        "views": places,
        "visible_fraction": visible_fraction,
    }
    (scene_dir / "scene.json").write_text(json.dumps(metadata, indent=1))
    return scene_dir


def write_tiny_dataset(
    root: Path,
    scenario: str = "sp",
    crop: str = "strawberry",
    scenes: int = 2,
    seed: int = 0,
    size: tuple[int, int] = (128, 72),
    splits: bool = True,
) -> Path:
    """Write a small, fully consistent dataset in the published layout (plus our extras).

    Args:
        root: Dataset root; the group folder (e.g. ``Single-Strawberry``) is created in it, next
            to any group already there.
        scenario: ``sp`` or ``mp``.
        crop: ``strawberry``, ``tomato`` or ``vine``.
        scenes: Number of scene folders, ``000`` upwards.
        seed: Scene ``i`` is drawn from seed ``seed * 1000 + i``.
        size: Image width and height in pixels.
        splits: Write ``splits.json`` (last scene in "test", the rest in "train"; merged with an
            existing one so several groups can share a root).

    Returns:
        ``root``.
    """
    root = Path(root)
    group = config.group_name(config.scenario_spec(scenario), config.crop_spec(crop))
    ids = []
    for i in range(scenes):
        write_tiny_scene(root / group / f"{i:03d}", scenario, crop, seed * 1000 + i, size)
        ids.append(f"{group}/{i:03d}")
    if splits:
        path = root / "splits.json"
        data = json.loads(path.read_text()) if path.exists() else {"seed": seed, "train": [], "test": []}
        test = ids[-1:] if len(ids) > 1 else []
        data["train"] += [i for i in ids if i not in test]
        data["test"] += test
        path.write_text(json.dumps(data, indent=1))
    return root


def write_original_style_dataset(
    root: Path,
    scenario: str = "sp",
    crop: str = "strawberry",
    scenes: int = 1,
    seed: int = 0,
    size: tuple[int, int] = (128, 72),
    missing_mask: bool = False,
) -> Path:
    """Like :func:`write_tiny_dataset`, then rewritten into every shape the original README allows.

    Keys lose ".jpeg"; pointer values lose it on every other view; "" pointers are dropped
    (a missing key is an invalid move); boxes become floats; the first view loses its pose;
    every view gains an unknown key; scene.json and splits.json are not written.

    Args:
        root, scenario, crop, scenes, seed, size: As for :func:`write_tiny_dataset`.
        missing_mask: Also delete the first view's ``_seg.png``.

    Returns:
        ``root``.
    """
    write_tiny_dataset(root, scenario, crop, scenes, seed, size, splits=False)
    group = config.group_name(config.scenario_spec(scenario), config.crop_spec(crop))
    for i in range(scenes):
        scene_dir = Path(root) / group / f"{i:03d}"
        raw = json.loads((scene_dir / "annotations.json").read_text())
        out = {}
        for n, (key, entry) in enumerate(raw.items()):
            new: dict = {
                "bounding_boxes": [[float(v) for v in box] for box in entry["bounding_boxes"]],
                "capture_time": n * 0.5,
            }
            if n:
                new["pose"] = entry["pose"]
            for action in config.ALL_ACTIONS:
                target = entry.get(action, "")
                if target:
                    new[action] = target.removesuffix(".jpeg") if n % 2 else target
            out[key.removesuffix(".jpeg")] = new
        (scene_dir / "annotations.json").write_text(json.dumps(out))
        (scene_dir / "scene.json").unlink()
        if missing_mask:
            (scene_dir / "images" / "0001_seg.png").unlink()
    return Path(root)

"""Reopen a generated scene: regrow it from its scene.json, or load its cached geometry.

A scene made by ``davis-ag generate`` records its seed and settings in scene.json. Growing it
again from them (:func:`davis_ag.generate.one_scene.grow_scene`) gives the same plants, bit for
bit, and the same slipped grid; both are checked against what scene.json stored (the fruit
registry, the plants and every view's pose) before anything is used.

Growing takes 20-60 s per plant, so the extracted geometry (every triangle, the fruit's
primitives, the exact grid poses) is cached in ``live_geometry.npz`` inside the scene folder,
written atomically and keyed by everything that shapes it (scene.json's seed and settings,
generator and pyhelios versions). A cache with another key is ignored and rewritten; a scene
folder that cannot be written is reopened uncached, with one line on stderr.

The cache also holds each primitive's organ class and plant (the 3-D exports' labels,
:mod:`davis_ag.worlds`); a cache written before they were kept still serves drawing, and is
regrown once by a caller that asks for them (``reopen_assets(..., labelled=True)``).
"""

from __future__ import annotations

import hashlib
import importlib.util
import json
import sys
from dataclasses import asdict, dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from davis_ag.atomic_files import atomic_output
from davis_ag.errors import UserError
from davis_ag.formats.layout import ANNOTATIONS, LIVE_GEOMETRY, view_name
from davis_ag.formats.scene_file import GeneratorRecord
from davis_ag.generate.recorded_settings import RecordedSettings
from davis_ag.scene.lighting import Lighting
from davis_ag.scene.view_grid import Viewpoint

if TYPE_CHECKING:
    from davis_ag.render.scene_geometry import SceneGeometry

#: Bump when the cache's content changes (2: the whole lighting, appearance included).
CACHE_VERSION = 2
_GEOMETRY_FIELDS = ("positions", "uvs", "normals", "uuids", "colours", "texture", "mode", "caster", "patch")


def cache_key(settings: RecordedSettings) -> str:
    """Digest of everything that shapes a scene's grown geometry and grid: the cache's key."""
    meta = settings.metadata
    keyed = {
        "version": CACHE_VERSION,
        "seed": settings.seed,
        "dataset_seed": settings.dataset_seed,
        "scenario": meta.scenario,
        "crop": meta.crop,
        "scene": meta.scene,
        "grid": meta.grid.as_written() if meta.grid else None,
        "generator": meta.generator.as_written() if meta.generator else None,
        "plants": settings.plants,
        "appearance": settings.appearance,
        # Keyed only where built, so the caches of scenes without structures keep their keys.
        **({"structures": settings.structures} if settings.structures != "none" else {}),
    }
    return hashlib.sha256(json.dumps(keyed, sort_keys=True).encode()).hexdigest()[:20]


@dataclass
class SceneAssets:
    """A reopened scene's drawable content.

    Attributes:
        geometry: Every triangle (:class:`davis_ag.render.scene_geometry.SceneGeometry`).
        fruit_uuids: Each fruit id's primitive UUIDs.
        uuid_count: One more than the largest primitive UUID.
        lighting: Sun and sky.
        aim_height: Height single-plant cameras aim at, m.
        grid_views: The grid's exact viewpoints (unrounded slip), in image order.
        from_cache: Whether this came from the cache (False: regrown just now).
        organ_of_uuid: Organ class (:mod:`davis_ag.scene.organs`) of every primitive, indexed by
            UUID (uint8; None from a cache written before it was kept).
        plant_of_uuid: Plant index of every primitive, indexed by UUID, -1 for none (int32; None
            as ``organ_of_uuid``).
    """

    geometry: SceneGeometry
    fruit_uuids: dict[int, np.ndarray]
    uuid_count: int
    lighting: Lighting
    aim_height: float
    grid_views: list[Viewpoint]
    from_cache: bool
    organ_of_uuid: np.ndarray | None = None
    plant_of_uuid: np.ndarray | None = None


def _pyhelios_root() -> Path | None:
    spec = importlib.util.find_spec("pyhelios")
    return Path(spec.origin).parent if spec and spec.origin else None


def _portable(path: str, root: Path | None) -> str:
    """Texture paths under pyhelios's install relative to it, so a cache survives another venv."""
    if root is not None and Path(path).is_relative_to(root):
        return "pyhelios:" + Path(path).relative_to(root).as_posix()
    return path


def _resolve(path: str, root: Path | None) -> str:
    if path.startswith("pyhelios:") and root is not None:
        return str(root / path[len("pyhelios:") :])
    return path


def _lighting_record(lighting: Lighting, root: Path | None) -> dict:
    """The lighting as JSON, its sky's path portable."""
    record = asdict(lighting)
    record["sky_texture"] = _portable(lighting.sky_texture, root) if lighting.sky_texture else None
    return record


def _lighting_from(record: dict, root: Path | None) -> Lighting:
    """The lighting a cache records (OSError when its sky image is gone: the cache is then redone)."""
    sky = record.pop("sky_texture")
    if sky is not None and not Path(sky := _resolve(sky, root)).is_file():
        raise OSError(f"{sky} is gone")
    balance = tuple(record.pop("white_balance"))
    return Lighting(**record, sky_texture=sky, white_balance=balance)


def regrow(settings: RecordedSettings) -> SceneAssets:
    """Grow a scene again from its seed and settings and check it against scene.json.

    Raises:
        UserError: when the regrown plants, fruit or grid poses differ from the stored ones
            (another pyhelios or davis-ag version grows differently).
    """
    from davis_ag.generate.one_scene import grow_scene

    request = settings.request()
    if request.seed != settings.seed:
        raise UserError(
            f"{settings.folder}/scene.json: seed {settings.seed} does not follow from dataset seed "
            f"{settings.dataset_seed} and scene {settings.metadata.scene}; the file was edited"
        )
    model, grid = grow_scene(request)
    stored = settings.metadata
    generator = stored.generator or GeneratorRecord()
    version = f"pyhelios3d {generator.pyhelios3d}, davis-ag {generator.version}"
    regrown_fruit = json.loads(json.dumps([f.summary() for f in model.fruits]))
    regrown_plants = json.loads(json.dumps([p.summary() for p in model.plants]))
    if regrown_fruit != [f.as_written() for f in stored.fruits] or regrown_plants != [
        p.as_written() for p in stored.plants
    ]:
        raise UserError(
            f"{settings.folder}: regrowing from the seed gave other plants than scene.json records "
            f"(made with {version}); reopen it with those versions"
        )
    check_grid(settings, list(grid.viewpoints))
    return assets_from_model(model, grid)


def assets_from_model(model, grid) -> SceneAssets:
    """A grown scene's drawable content (:func:`davis_ag.generate.one_scene.grow_scene`'s output)."""
    from davis_ag.render.scene_geometry import read_scene_geometry

    plant_of_uuid = np.full(model.uuid_count, -1, dtype=np.int32)
    for plant in model.plants:
        plant_of_uuid[np.asarray(plant.uuids, dtype=np.int64)] = plant.index
    return SceneAssets(
        read_scene_geometry(model.context),
        {f.id: np.asarray(f.uuids, dtype=np.int64) for f in model.fruits},
        model.uuid_count,
        model.lighting,
        float(model.aim_height),
        list(grid.viewpoints),
        False,
        model.organ_of_uuid(),
        plant_of_uuid,
    )


def check_grid(settings: RecordedSettings, views: list[Viewpoint]) -> None:
    """The grid's views must be the stored ones: same names, same poses as annotations.json."""
    path = settings.folder / ANNOTATIONS
    try:
        annotations = json.loads(path.read_text())
    except (OSError, ValueError) as error:
        raise UserError(f"{path}: cannot be read ({error})") from None
    poses = {view_name(v.number): [round(x, 5) for x in v.pose] for v in views}
    for name, entry in annotations.items():
        if poses.get(name) != entry.get("pose"):
            raise UserError(
                f"{path}: view {name} has pose {entry.get('pose')}, the regrown grid "
                f"{poses.get(name)}; the scene cannot be reopened as it was drawn"
            )


def save_cache(path: Path, key: str, assets: SceneAssets) -> None:
    """Write the assets atomically (an uncompressed npz loads in a fraction of a second)."""
    root = _pyhelios_root()
    geometry = assets.geometry
    fruit_ids = sorted(assets.fruit_uuids)
    uuids = [assets.fruit_uuids[f] for f in fruit_ids]
    views = assets.grid_views
    arrays = {name: getattr(geometry, name) for name in _GEOMETRY_FIELDS}
    arrays.update(
        key=np.array(key),
        texture_files=np.array([_portable(f, root) for f in geometry.texture_files], dtype=np.str_),
        fruit_ids=np.array(fruit_ids, dtype=np.int64),
        fruit_offsets=np.cumsum([0] + [len(u) for u in uuids]),
        fruit_uuids=np.concatenate([*uuids, np.zeros(0, np.int64)]).astype(np.int64),
        uuid_count=np.array(assets.uuid_count),
        aim_height=np.array(assets.aim_height),
        lighting=np.array(json.dumps(_lighting_record(assets.lighting, root))),
        view_grid=np.array([[v.ix, v.iy, v.level, v.heading] for v in views], dtype=np.int64).reshape(-1, 4),
        view_nominal=np.array([v.nominal for v in views], dtype=np.float64).reshape(-1, 3),
        view_position=np.array([v.position for v in views], dtype=np.float64).reshape(-1, 3),
        view_angles=np.array([(v.yaw, v.pitch) for v in views], dtype=np.float64).reshape(-1, 2),
    )
    if assets.organ_of_uuid is not None and assets.plant_of_uuid is not None:
        arrays.update(organ_of_uuid=assets.organ_of_uuid, plant_of_uuid=assets.plant_of_uuid)
    with atomic_output(path) as handle:
        np.savez(handle, **arrays)


def load_cache(path: Path, key: str) -> SceneAssets | None:
    """The cached assets, or None when missing, unreadable or made for other settings."""
    from davis_ag.render.scene_geometry import SceneGeometry

    try:
        with np.load(path, allow_pickle=False) as data:
            if str(data["key"]) != key:
                return None
            root = _pyhelios_root()
            files = [_resolve(str(f), root) for f in data["texture_files"]]
            if not all(Path(f).is_file() for f in files):
                return None
            geometry = SceneGeometry(**{name: data[name] for name in _GEOMETRY_FIELDS}, texture_files=files)
            offsets = data["fruit_offsets"]
            fruit_uuids = {
                int(f): data["fruit_uuids"][offsets[k] : offsets[k + 1]] for k, f in enumerate(data["fruit_ids"])
            }
            lighting = _lighting_from(json.loads(str(data["lighting"])), root)
            views = [
                Viewpoint(
                    k,
                    int(g[0]),
                    int(g[1]),
                    int(g[2]),
                    int(g[3]),
                    (float(n[0]), float(n[1]), float(n[2])),
                    (float(p[0]), float(p[1]), float(p[2])),
                    float(a[0]),
                    float(a[1]),
                )
                for k, (g, n, p, a) in enumerate(
                    zip(data["view_grid"], data["view_nominal"], data["view_position"], data["view_angles"])
                )
            ]
            return SceneAssets(
                geometry,
                fruit_uuids,
                int(data["uuid_count"]),
                lighting,
                float(data["aim_height"]),
                views,
                True,
                data["organ_of_uuid"] if "organ_of_uuid" in data.files else None,
                data["plant_of_uuid"] if "plant_of_uuid" in data.files else None,
            )
    except (OSError, ValueError, KeyError, IndexError, TypeError):
        return None


def reopen_assets(settings: RecordedSettings, use_cache: bool = True, labelled: bool = False) -> SceneAssets:
    """The scene's assets from its cache if current, else regrown (and cached where possible).

    Args:
        settings: From :func:`~davis_ag.generate.recorded_settings.read_settings`.
        use_cache: False regrows even when a current cache exists (and rewrites it).
        labelled: The organ class and plant of every primitive are needed: a cache written
            before they were kept is regrown (and rewritten with them).
    """
    path = settings.folder / LIVE_GEOMETRY
    key = cache_key(settings)
    if use_cache:
        cached = load_cache(path, key)
        if cached is not None and (not labelled or cached.organ_of_uuid is not None):
            return cached
    assets = regrow(settings)
    try:
        save_cache(path, key, assets)
    except OSError as error:
        print(
            f"davis-ag: cannot cache the scene's geometry in {path} ({error.strerror or error}); "
            "the next reopening will grow it again",
            file=sys.stderr,
        )
    return assets

"""Per-scene observation cache: every view resized once, then memory-mapped by the environment.

A step of :class:`davis_ag.benchmark.tvm.TVMEnv` must never decode a JPEG (a 1280x720 decode costs
milliseconds, a step has tens of microseconds), so each scene is converted once into:

- ``images.npy``: ``(n_views, 224, 224, 4)`` uint8, views in image order: RGB plus a fourth
  channel of zeros, so that an observation is one contiguous 200 KB copy and a box fill
  (filling a 4-channel array from a 3-channel one is a strided copy, ~50 times slower, and
  alone would cap the environment below 5,000 steps/s). Written with
  :func:`numpy.lib.format.open_memmap` and read back with ``mmap_mode="r"`` so that a
  multi-plant scene (1,800 views, 360 MB) costs page cache, not process memory.
- ``tables.npz``: small dense tables (see :class:`SceneCache`): pointers, and one row per
  annotated box with its fruit id, its box in original and in 224 pixels, its OER and the
  fruit's visible pixel count.
- ``meta.json``: format version, the fingerprint, view names and original image size.

The folder is ``<dataset root>/.davis_ag_cache/<scene id>/`` unless a ``cache_dir`` is given.
It is written to a temporary sibling and moved into place with :func:`os.replace`, so a reader
(or a second process building the same scene) never sees half a cache. It is keyed by the
SHA-256 of the scene's ``annotations.json``: an edited or re-generated scene is rebuilt.
"""

from __future__ import annotations

import hashlib
import json
import os
import shutil
import tempfile
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np
from PIL import Image

from davis_ag.data.safe_read import check_inside
from davis_ag.errors import UserError
from davis_ag.formats.layout import ANNOTATIONS, CACHE_FOLDER, IMAGES
from davis_ag.formats.masks import no_fruit_value
from davis_ag.scene.specs import ALL_ACTIONS

if TYPE_CHECKING:  # the reader's types only: at run time the cache module stays light
    from davis_ag.data.reader import Scene, View

#: Side of the square observation image (section V-C: 224x224).
OBS_SIZE = 224
#: Bumped whenever the files' meaning changes, so that old caches are rebuilt.
CACHE_VERSION = 2


@dataclass(frozen=True)
class SceneCache:
    """One scene's views and tables, as the environment uses them.

    Attributes:
        scene_id: The reader's scene id, e.g. ``Single-Strawberry/000``.
        view_names: Image names in view order (``0001.jpeg`` ...).
        image_size: Original ``(width, height)`` of the views, pixels.
        images: ``(n_views, 224, 224, 4)`` uint8, memory-mapped: RGB, then zeros.
        pointers: ``(n_views, len(ALL_ACTIONS))`` int32: the view an action leads to, -1 for "".
            Columns follow :data:`davis_ag.scene.specs.ALL_ACTIONS`.
        fruit_ids: ``(n_fruits,)`` int32: every fruit id annotated anywhere in the scene, sorted.
        box_index: ``(n_views, n_fruits)`` int32: row of ``box_*`` for a fruit's box in a view,
            -1 where that fruit has no box in that view.
        box_view: ``(n_boxes,)`` int32: the view a box belongs to.
        box_fruit: ``(n_boxes,)`` int32: column of ``fruit_ids`` the box belongs to.
        box_xywh: ``(n_boxes, 4)`` int32: the annotated box (xmin, ymin, width, height), original
            pixels.
        box_scaled: ``(n_boxes, 4)`` int32: the box in 224 pixels as inclusive (x0, y0, x1, y1),
            rounded outwards so that the mask channel always covers the fruit.
        box_oer: ``(n_boxes,)`` float32: object exposure rate (eq. 1) of the box.
        box_pixels: ``(n_boxes,)`` int32: visible pixels of the box's fruit in the whole view.
    """

    scene_id: str
    view_names: tuple[str, ...]
    image_size: tuple[int, int]
    images: np.ndarray
    pointers: np.ndarray
    fruit_ids: np.ndarray
    box_index: np.ndarray
    box_view: np.ndarray
    box_fruit: np.ndarray
    box_xywh: np.ndarray
    box_scaled: np.ndarray
    box_oer: np.ndarray
    box_pixels: np.ndarray

    @property
    def n_views(self) -> int:
        """Number of views of the scene."""
        return len(self.view_names)


# Caches already opened by this process, by (folder, fingerprint): environments of one
# vectorised learner share tables and memory maps instead of re-reading them.
_OPEN: dict[tuple[str, str], SceneCache] = {}

_TABLES = (
    "pointers",
    "fruit_ids",
    "box_index",
    "box_view",
    "box_fruit",
    "box_xywh",
    "box_scaled",
    "box_oer",
    "box_pixels",
)


def scene_fingerprint(scene: Scene, root: Path) -> str:
    """Hash what the cache is derived from: the scene's annotations.json, the name, size and
    modification time of every file in its ``images/`` folder (a view replaced or cut short after
    the cache was built makes it stale, so the rebuild reads, and reports, the damaged file), and
    the cache format.

    Args:
        scene: A reader scene (``davis_ag.data.reader.Scene``).
        root: The dataset root the scene id is relative to.

    Returns:
        A hex digest; a different one means the cache is stale.
    """
    digest = hashlib.sha256(f"davis-ag-cache:{CACHE_VERSION}:{OBS_SIZE}\n".encode())
    path = check_inside(annotations_path(scene, root), getattr(scene, "root", None))
    try:
        digest.update(path.read_bytes())
    except OSError as error:
        raise UserError(f"cannot read {path}: {error.strerror}; check the dataset copy") from error
    try:
        with os.scandir(path.parent / IMAGES) as entries:
            files = sorted((e.name, e.stat(follow_symlinks=False)) for e in entries)
    except OSError:  # no images folder: the build reports the missing views
        files = []
    for name, stat in files:
        digest.update(f"{name}\0{stat.st_size}\0{stat.st_mtime_ns}\n".encode())
    return digest.hexdigest()


def annotations_path(scene: Scene, root: Path) -> Path:
    """The scene's annotations.json: the reader's ``path`` if it has one, else root/id."""
    path = getattr(scene, "annotations_path", None)
    return Path(path) if path is not None else Path(root) / scene.id / ANNOTATIONS


def scaled_box(xmin: int, ymin: int, width: int, height: int, image_size: tuple[int, int]) -> tuple[int, int, int, int]:
    """Map a box in original pixels to inclusive (x0, y0, x1, y1) in the 224x224 image.

    Rounded outwards (floor of the start, ceiling of the end) so that a fruit never falls out
    of its own box channel, and clipped to the image.

    Args:
        xmin, ymin, width, height: The annotated box, original pixels (xmax = xmin + width - 1).
        image_size: Original ``(width, height)``.

    Returns:
        ``(x0, y0, x1, y1)``, each within ``[0, 223]``.
    """
    sx, sy = OBS_SIZE / image_size[0], OBS_SIZE / image_size[1]
    x0 = int(np.floor(xmin * sx))
    y0 = int(np.floor(ymin * sy))
    x1 = int(np.ceil((xmin + width) * sx)) - 1
    y1 = int(np.ceil((ymin + height) * sy)) - 1
    clip = lambda v: min(max(v, 0), OBS_SIZE - 1)  # noqa: E731 - local one-liner
    return clip(x0), clip(y0), max(clip(x1), clip(x0)), max(clip(y1), clip(y0))


def _resized_image(view: View) -> tuple[np.ndarray, tuple[int, int]]:
    """Decode a view and downsize it to 224x224 (aspect not kept, as in the paper's input).

    The JPEG is decoded in draft mode (DCT scaling to the smallest size still >= 224 on both
    sides), which is several times faster on 1280x720 views; anything unusual falls back to
    the reader, whose errors name the file.

    Returns:
        The 224x224x3 uint8 image and the original ``(width, height)``.
    """
    path = view.image_path
    check_inside(path, view.scene.root)  # never decode a link out of the dataset, even on the fast path
    try:
        with Image.open(path) as pil:
            size = pil.size
            pil.draft("RGB", (OBS_SIZE, OBS_SIZE))
            small = pil.convert("RGB").resize((OBS_SIZE, OBS_SIZE), Image.Resampling.BILINEAR)
    except Exception:
        image = view.image()
        size = (image.shape[1], image.shape[0])
        small = Image.fromarray(np.ascontiguousarray(image[..., :3])).resize(
            (OBS_SIZE, OBS_SIZE), Image.Resampling.BILINEAR
        )
    return np.asarray(small, dtype=np.uint8), size


def _build(scene: Scene, folder: Path, fingerprint: str) -> None:
    """Decode every view of ``scene`` once and write the cache files into ``folder``."""
    # Local import: the reader may import heavy modules; the cache module stays light.
    from davis_ag.data.reader import exposure_rate

    views = list(scene.views.values())
    if not views:
        raise UserError(f"{scene.annotations_path}: scene {scene.id} has no views; check its annotations.json")
    names = [view.name for view in views]
    position = {name: i for i, name in enumerate(names)}
    images = np.lib.format.open_memmap(
        folder / "images.npy", mode="w+", dtype=np.uint8, shape=(len(views), OBS_SIZE, OBS_SIZE, 4)
    )
    pointers = np.full((len(views), len(ALL_ACTIONS)), -1, dtype=np.int32)
    rows: list[tuple[int, int, tuple[int, int, int, int], float, int]] = []
    image_size: tuple[int, int] | None = None
    for i, view in enumerate(views):
        mask = view.mask()
        if mask is None:
            raise UserError(
                f"{view.mask_path}: missing; scene {scene.id} view {view.name} has no segmentation "
                "mask and the exposure rate needs masks: use a download or generation that includes them"
            )
        resized, (width, height) = _resized_image(view)
        if mask.shape != (height, width):
            raise UserError(
                f"{view.mask_path}: mask is {mask.shape[1]}x"
                f"{mask.shape[0]}, image {width}x{height}; regenerate the mask"
            )
        if image_size is None:
            image_size = (width, height)
        elif image_size != (width, height):
            raise UserError(
                f"{view.image_path}: {width}x{height}, the first "
                f"view {image_size[0]}x{image_size[1]}; all views must share a size"
            )
        images[i, :, :, :3] = resized
        images[i, :, :, 3] = 0
        for j, action in enumerate(ALL_ACTIONS):
            target = view.pointers.get(action, "")
            if target:
                if target not in position:
                    raise UserError(
                        f"{scene.annotations_path}: view {view.name}'s {action} points to "
                        f"missing view {target!r}; fix annotations.json or regenerate the scene"
                    )
                pointers[i, j] = position[target]
        # One bincount gives every fruit's visible pixel count in the view (uint8 or uint16 mask:
        # davis_ag.formats.masks; no fruit is its last bin).
        counts = np.bincount(mask.ravel(), minlength=no_fruit_value(mask) + 1)
        for box in view.boxes:
            rows.append(
                (
                    i,
                    int(box.fruit_id),
                    (int(box.xmin), int(box.ymin), int(box.width), int(box.height)),
                    float(exposure_rate(mask, box)),
                    int(counts[int(box.fruit_id)]) if 0 <= box.fruit_id < len(counts) else 0,
                )
            )
    images.flush()
    del images
    assert image_size is not None
    fruit_ids = np.array(sorted({row[1] for row in rows}), dtype=np.int32)
    column = {int(f): k for k, f in enumerate(fruit_ids)}
    box_index = np.full((len(views), len(fruit_ids)), -1, dtype=np.int32)
    for b, (view_i, fruit, _, _, _) in enumerate(rows):
        # A fruit boxed twice in one view (should not happen) keeps its first box.
        if box_index[view_i, column[fruit]] < 0:
            box_index[view_i, column[fruit]] = b
    tables = {
        "pointers": pointers,
        "fruit_ids": fruit_ids,
        "box_index": box_index,
        "box_view": np.array([r[0] for r in rows], dtype=np.int32),
        "box_fruit": np.array([column[r[1]] for r in rows], dtype=np.int32),
        "box_xywh": np.array([r[2] for r in rows], dtype=np.int32).reshape(-1, 4),
        "box_scaled": np.array([scaled_box(*r[2], image_size) for r in rows], dtype=np.int32).reshape(-1, 4),
        "box_oer": np.array([r[3] for r in rows], dtype=np.float32),
        "box_pixels": np.array([r[4] for r in rows], dtype=np.int32),
    }
    # Numbers only, as _load reads them (allow_pickle named: type checkers then match **tables
    # against the arrays alone, not against this bool too).
    np.savez(folder / "tables.npz", allow_pickle=False, **tables)
    meta = {
        "version": CACHE_VERSION,
        "fingerprint": fingerprint,
        "scene": scene.id,
        "views": names,
        "image_size": list(image_size),
        "actions": list(ALL_ACTIONS),
    }
    (folder / "meta.json").write_text(json.dumps(meta))


def _load(folder: Path, fingerprint: str) -> SceneCache | None:
    """Open a cache folder; ``None`` when it is missing, incomplete, stale or damaged in any way
    (the caller rebuilds it from the dataset), so a damaged cache never reaches an episode."""
    files = [folder / name for name in ("meta.json", "tables.npz", "images.npy")]
    if folder.is_symlink() or any(path.is_symlink() for path in files):
        return None  # a link could point anywhere; a cache we wrote never holds one
    try:
        meta = json.loads(files[0].read_text())
        if meta.get("version") != CACHE_VERSION or meta.get("fingerprint") != fingerprint:
            return None
        with np.load(files[1], allow_pickle=False) as npz:
            tables = {name: np.asarray(npz[name]) for name in _TABLES}
        images = np.load(files[2], mmap_mode="r", allow_pickle=False)
        cache = SceneCache(
            scene_id=str(meta["scene"]),
            view_names=tuple(str(v) for v in meta["views"]),
            image_size=(int(meta["image_size"][0]), int(meta["image_size"][1])),
            images=images,
            **tables,
        )
    except Exception:
        return None
    return cache if _consistent(cache) else None


def _consistent(cache: SceneCache) -> bool:
    """Whether every table has the shape, type and index range the environment relies on."""
    n, n_boxes, n_fruits = cache.n_views, len(cache.box_view), len(cache.fruit_ids)

    def ints(array: np.ndarray, shape: tuple[int, ...], low: int, high: int) -> bool:
        return (
            array.shape == shape
            and array.dtype.kind in "iu"
            and (array.size == 0 or (int(array.min()) >= low and int(array.max()) < high))
        )

    return (
        n > 0
        and min(cache.image_size) > 0
        and cache.images.shape == (n, OBS_SIZE, OBS_SIZE, 4)
        and cache.images.dtype == np.uint8
        and ints(cache.pointers, (n, len(ALL_ACTIONS)), -1, n)
        and ints(cache.fruit_ids, (n_fruits,), -(2**31), 2**31)
        and ints(cache.box_index, (n, n_fruits), -1, n_boxes)
        and ints(cache.box_view, (n_boxes,), 0, n)
        and ints(cache.box_fruit, (n_boxes,), 0, max(n_fruits, 1))
        and ints(cache.box_xywh, (n_boxes, 4), -(2**31), 2**31)
        and ints(cache.box_scaled, (n_boxes, 4), 0, OBS_SIZE)
        and cache.box_oer.shape == (n_boxes,)
        and cache.box_oer.dtype.kind == "f"
        and bool(np.all(np.isfinite(cache.box_oer)))
        and ints(cache.box_pixels, (n_boxes,), 0, 2**31)
    )


def cache_folder(scene: Scene, root: Path, cache_dir: str | os.PathLike[str] | None) -> Path:
    """Where a scene's cache lives: ``<cache_dir or root/.davis_ag_cache>/<scene id>``."""
    base = Path(cache_dir) if cache_dir is not None else Path(root) / CACHE_FOLDER
    return base / scene.id


#: The files of a scene's cache: all a folder may hold to be replaced as a stale cache.
_CACHE_FILES = frozenset({"meta.json", "tables.npz", "images.npy"})


def _replaceable(folder: Path) -> bool:
    """Whether an existing folder may be deleted as a cache of ours (stale or damaged): a real
    folder holding nothing but a cache's own file names, none a link. Decided on the names alone
    (nothing is read): a scene folder, which a ``--cache-dir`` pointed at a dataset would
    otherwise replace, always holds ``annotations.json`` and ``images/``."""
    if folder.is_symlink() or not folder.is_dir():
        return False
    try:
        entries = list(folder.iterdir())
    except OSError:
        return False
    return all(entry.name in _CACHE_FILES and not entry.is_symlink() for entry in entries)


def load_scene_cache(scene: Scene, root: Path, cache_dir: str | os.PathLike[str] | None = None) -> SceneCache:
    """Open a scene's cache, building (or rebuilding a stale one) first.

    Args:
        scene: A reader scene (``davis_ag.data.reader.Scene``).
        root: The dataset root (``Dataset.root``).
        cache_dir: Base folder for caches; default ``<root>/.davis_ag_cache``.

    Returns:
        The memory-mapped :class:`SceneCache`.

    Raises:
        UserError: when a view has no mask, the annotations are inconsistent, or the cache
            folder cannot be written.
    """
    folder = cache_folder(scene, root, cache_dir)
    fingerprint = scene_fingerprint(scene, root)
    key = (str(folder.absolute()), fingerprint)
    cache = _OPEN.get(key) or _load(folder, fingerprint)
    if cache is not None:
        _OPEN[key] = cache
        return cache
    if folder.exists() and not _replaceable(folder):
        raise UserError(
            f"{folder} holds something that is not an observation cache (a scene folder of a dataset?), "
            "so it is left alone: pass a --cache-dir (cache_dir) outside every dataset, or leave it out "
            "for the dataset's own cache folder"
        )
    try:
        folder.parent.mkdir(parents=True, exist_ok=True)
        tmp = Path(tempfile.mkdtemp(prefix=f".{folder.name}.tmp-", dir=folder.parent))
    except OSError as error:
        raise UserError(
            f"cannot write the observation cache under {folder.parent}: "
            f"{error.strerror}; pass a writable cache_dir (--cache-dir)"
        ) from error
    try:
        _build(scene, tmp, fingerprint)
        if folder.exists():
            # Move the stale cache aside first: os.replace cannot overwrite a non-empty folder.
            stale = Path(tempfile.mkdtemp(prefix=f".{folder.name}.old-", dir=folder.parent))
            try:
                os.replace(folder, stale / "x")
            except OSError:
                pass  # another process moved it already
            shutil.rmtree(stale, ignore_errors=True)
        try:
            os.replace(tmp, folder)
        except OSError:
            # Another process finished the same scene first; its cache is as good as ours.
            pass
    finally:
        shutil.rmtree(tmp, ignore_errors=True)
    cache = _load(folder, fingerprint)
    if cache is None:
        raise UserError(
            f"the observation cache at {folder} could not be read back after building; delete that folder and retry"
        )
    _OPEN[key] = cache
    return cache

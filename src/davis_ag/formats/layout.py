"""The dataset's file layout: every file name, and how each per-view image is encoded and decoded.

One module owns the names the writer, reader, validator, viewer, exports and the PyTorch dataset
use, so a name or an encoding changes in one place::

    <root>/dataset.json, splits.json, .davis_ag_cache/ (benchmark caches), .davis_ag.lock
    <root>/<Group>/<NNN>/annotations.json, scene.json
    <root>/<Group>/<NNN>/images/NNNN.jpeg          colour, JPEG quality 95, NNNN from 0001
    <root>/<Group>/<NNN>/images/NNNN_seg.png       fruit id per pixel: uint8, 255 = no fruit (at most
                                                   255 fruit); uint16, 65535 = no fruit (more)
    <root>/<Group>/<NNN>/images/NNNN_depth.png     uint16 mm along the optical axis, 0 = nothing hit
    <root>/<Group>/<NNN>/images/NNNN_class.png     uint8 organ class per pixel

A new per-view image is one more entry in :data:`VIEW_FILES` (its suffix and what it holds);
:func:`view_file`, :func:`view_of_file` and the validator's stray-file check then know it.
Which integer type a scene's masks use is the rule of :mod:`davis_ag.formats.masks`.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from davis_ag.errors import UserError
from davis_ag.formats.masks import mask_image

if TYPE_CHECKING:
    from davis_ag.scene.view_grid import ViewGrid

ANNOTATIONS = "annotations.json"
SCENE_METADATA = "scene.json"
DATASET_FILE = "dataset.json"
SPLITS_FILE = "splits.json"
#: The live environments' cache of a scene's grown geometry, in its scene folder (not the generator's).
LIVE_GEOMETRY = "live_geometry.npz"
#: Folder under the dataset root that holds the benchmark's default observation caches.
CACHE_FOLDER = ".davis_ag_cache"
#: The generator's lock, held for a whole run.
LOCK_FILE = ".davis_ag.lock"
#: Every name a dataset root may hold besides its group folders.
ROOT_FILES = (DATASET_FILE, SPLITS_FILE, CACHE_FOLDER, LOCK_FILE)
IMAGES = "images"
IMAGE_SUFFIX = ".jpeg"
JPEG_QUALITY = 95
#: Depth images: uint16 millimetres along the optical axis, 0 where nothing is hit; farther
#: surfaces than this many millimetres are stored as this value.
DEPTH_MAX_MM = 65535

#: Every per-view file: kind -> (suffix after the view's number, what it holds).
VIEW_FILES: dict[str, tuple[str, str]] = {
    "image": (IMAGE_SUFFIX, "RGB, JPEG"),
    "mask": ("_seg.png", "fruit id per pixel, uint8 (255 = no fruit) or uint16 (65535): formats.masks"),
    "depth": ("_depth.png", "uint16 millimetres along the optical axis, 0 = nothing hit"),
    "classes": ("_class.png", "uint8 organ class per pixel (davis_ag.scene.organs)"),
}


def view_name(number: int) -> str:
    """A view's image name from its 1-based number: ``view_name(1)`` is ``"0001.jpeg"``."""
    return f"{number:04d}{IMAGE_SUFFIX}"


def view_stem(name: str) -> str:
    """``"0001.jpeg"`` -> ``"0001"``."""
    return name.removesuffix(IMAGE_SUFFIX)


def view_number(name: str) -> int | None:
    """``"0001.jpeg"`` -> 1; None for a name that is no number (the original download may have some)."""
    stem = view_stem(name)
    return int(stem) if stem.isascii() and stem.isdigit() else None  # not '²', which isdigit() takes


def published_pointers(grid: ViewGrid, index: int) -> dict[str, str]:
    """The published pointer dictionary of a grid's view: action to image name, "" where invalid."""
    return {
        action: "" if (target := grid.pointer(index, action)) is None else view_name(target + 1)
        for action in grid.actions
    }


def view_file_name(name: str, kind: str) -> str:
    """A view's file of one kind: ``view_file_name("0001.jpeg", "mask")`` is ``"0001_seg.png"``.

    Args:
        name: The view's image name (``NNNN.jpeg``).
        kind: A key of :data:`VIEW_FILES`.
    """
    return view_stem(name) + VIEW_FILES[kind][0]


def view_file(scene_dir: str | Path, name: str, kind: str) -> Path:
    """Where a view's file of one kind lies in a scene folder, whether or not it exists."""
    return Path(scene_dir) / IMAGES / view_file_name(name, kind)


def view_of_file(file_name: str) -> tuple[str, str] | None:
    """The view and kind a file of ``images/`` belongs to: ``"0001_seg.png"`` -> ``("0001.jpeg", "mask")``.

    Returns:
        None for a file that is no per-view image of the layout (``.jpg`` and other ``.png``
        files, as the original download may hold, count as the image of their stem).
    """
    # Longest suffix first: "_seg.png" must win over a plain ".png".
    for kind, (suffix, _) in sorted(VIEW_FILES.items(), key=lambda item: -len(item[1][0])):
        if file_name.endswith(suffix) and file_name != suffix:
            return file_name.removesuffix(suffix) + IMAGE_SUFFIX, kind
    stem, dot, extension = file_name.rpartition(".")
    if dot and stem and extension.lower() in ("jpeg", "jpg", "png"):
        return stem + IMAGE_SUFFIX, "image"
    return None


def encode_depth(depth: np.ndarray) -> np.ndarray:
    """Metres (0 = nothing hit) to the uint16 millimetres of ``NNNN_depth.png``."""
    millimetres = np.rint(np.asarray(depth, dtype=np.float64) * 1000.0)
    return np.clip(millimetres, 0, DEPTH_MAX_MM).astype(np.uint16)


def decode_depth(millimetres: np.ndarray) -> np.ndarray:
    """The uint16 millimetres of ``NNNN_depth.png`` to float32 metres (0 = nothing hit)."""
    return np.asarray(millimetres).astype(np.float32) / 1000.0


def write_view_files(
    images_dir: Path,
    name: str,
    colour: np.ndarray | None = None,
    segmentation: np.ndarray | None = None,
    depth: np.ndarray | None = None,
    classes: np.ndarray | None = None,
) -> list[str]:
    """Encode and write a view's files (those given) into ``images/``; not atomic by itself.

    Args:
        images_dir: The scene's ``images`` folder (the writer's hidden one while it writes).
        name: The view's image name.
        colour: ``H x W x 3`` uint8.
        segmentation: ``H x W`` fruit ids, no fruit elsewhere: uint8 (255) or uint16 (65535), as
            :func:`davis_ag.formats.masks.mask_dtype` of the scene's fruit count gives.
        depth: ``H x W`` metres along the optical axis, 0 where nothing is hit.
        classes: ``H x W`` uint8 organ classes.

    Returns:
        The names of the files written.
    """
    from PIL import Image

    written = []
    if colour is not None:
        Image.fromarray(colour).save(images_dir / name, quality=JPEG_QUALITY)
        written.append(name)
    if segmentation is not None:
        mask_image(segmentation).save(images_dir / view_file_name(name, "mask"), compress_level=1)
        written.append(view_file_name(name, "mask"))
    if depth is not None:
        Image.fromarray(encode_depth(depth)).save(images_dir / view_file_name(name, "depth"), compress_level=1)
        written.append(view_file_name(name, "depth"))
    if classes is not None:
        Image.fromarray(classes, mode="L").save(images_dir / view_file_name(name, "classes"), compress_level=1)
        written.append(view_file_name(name, "classes"))
    return written


def read_depth_millimetres(path: Path) -> np.ndarray:
    """Read ``NNNN_depth.png`` as its stored uint16 millimetres.

    Raises:
        UserError: naming the file when it cannot be decoded or is not a 16-bit single-channel PNG.
    """
    from PIL import Image

    try:
        with Image.open(path) as im:
            millimetres = np.asarray(im)
    except Exception as error:  # Pillow, and plug-ins patched into it (ultralytics' HEIF), raise many types
        if isinstance(error, MemoryError):
            raise
        raise UserError(f"{path}: cannot decode ({error}); regenerate the scene") from None
    if millimetres.dtype != np.uint16 or millimetres.ndim != 2:
        raise UserError(
            f"{path}: a depth image must be a uint16 single-channel PNG (millimetres), "
            f"got {millimetres.dtype} {millimetres.shape}; regenerate the scene"
        )
    return millimetres


def read_depth(path: Path) -> np.ndarray:
    """Read ``NNNN_depth.png`` as float32 metres along the optical axis (0 = nothing hit).

    Raises:
        UserError: as :func:`read_depth_millimetres`.
    """
    return decode_depth(read_depth_millimetres(path))

"""``davis-ag export nerfstudio``: each scene as nerfstudio's ``transforms.json``, posed multi-view images.

One file a scene, ``OUT/<Group>/<NNN>/transforms.json``, in nerfstudio's data format
(docs.nerf.studio, "Data conventions"), which gsplat, Instant-NGP and other reconstruction tools
also read:

- the scene's pinhole once at the top: ``camera_model`` ``OPENCV``, ``fl_x``, ``fl_y``, ``cx``,
  ``cy``, ``w``, ``h`` and ``k1 k2 p1 p2`` (0: no distortion), from scene.json. Pixel centres are
  at +0.5 in both (nerfstudio shoots pixel (0, 0)'s ray through its centre);
- one frame per view with a pose: ``file_path`` (the colour image), ``transform_matrix`` (4x4
  camera-to-world in world metres, Z up, OpenGL's camera frame: +x right, +y up, +z back,
  :func:`davis_ag.worlds.cameras.camera_to_world`), ``depth_file_path`` where the view has depth
  (uint16 millimetres along the optical axis, 0 where nothing is hit: nerfstudio's default
  ``depth_unit_scale_factor`` 1e-3 reads it as metres, and it is z-depth, not distance along the
  ray), ``fruit_mask_path`` (the instance mask ``NNNN_seg.png``: fruit id per pixel, 255 or 65535
  for none) and ``class_path`` (organ class per pixel) where the dataset has them.

The instance mask is *not* nerfstudio's ``mask_path``, which means "train only where the mask is
not 0": as that, fruit 0 would be left out and everything else kept. ``davis_ag`` at the top
records the scene id and the class table.

The files are referenced by relative path from the transforms.json into the dataset (nothing is
copied: the export is a few kilobytes and stays valid while the two folders keep their places),
or with ``copy`` copied beside it under ``images/`` (a folder that can be moved on its own).
"""

from __future__ import annotations

import os
import shutil
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import write_json_atomic
from davis_ag.data.point_cloud import Pinhole
from davis_ag.data.reader import Scene
from davis_ag.formats.layout import IMAGES
from davis_ag.scene.organs import ORGAN_NAMES
from davis_ag.worlds.cameras import camera_to_world

TRANSFORMS = "transforms.json"


def _linked(path: Path, folder: Path, copy: bool) -> str:
    """How transforms.json in ``folder`` names a dataset file: a relative path to it, or to its copy."""
    if copy:
        target = folder / IMAGES / path.name
        target.parent.mkdir(parents=True, exist_ok=True)
        shutil.copyfile(path, target)
        return f"{IMAGES}/{path.name}"
    return Path(os.path.relpath(path.resolve(), folder.resolve())).as_posix()


def transforms(scene: Scene, folder: Path, copy: bool = False) -> dict[str, Any]:
    """A scene's transforms.json content (copying its files into ``folder`` with ``copy``).

    Args:
        scene: A scene with scene.json (:func:`davis_ag.worlds.triangles.geometry_scenes`).
        folder: Where the transforms.json will be.
        copy: Copy the images beside it instead of referring to the dataset's.

    Returns:
        The JSON-ready dictionary.
    """
    pinhole = Pinhole.of_scene(scene)
    frames = []
    for view in scene:
        if view.pose is None:
            continue
        frame: dict[str, Any] = {
            "file_path": _linked(view.image_path, folder, copy),
            "transform_matrix": camera_to_world(view.pose).tolist(),
        }
        if view.depth_path.is_file():
            frame["depth_file_path"] = _linked(view.depth_path, folder, copy)
        if view.mask_path.is_file():
            frame["fruit_mask_path"] = _linked(view.mask_path, folder, copy)
        if view.class_path.is_file():
            frame["class_path"] = _linked(view.class_path, folder, copy)
        frames.append(frame)
    return {
        "camera_model": "OPENCV",
        "fl_x": pinhole.fx,
        "fl_y": pinhole.fy,
        "cx": pinhole.cx,
        "cy": pinhole.cy,
        "w": pinhole.width,
        "h": pinhole.height,
        "k1": 0.0,
        "k2": 0.0,
        "p1": 0.0,
        "p2": 0.0,
        "frames": frames,
        "davis_ag": {
            "scene": scene.id,
            "units": "m, Z up; depth images uint16 mm along the optical axis",
            "classes": list(ORGAN_NAMES),
        },
    }


def export_nerfstudio(scenes: list[Scene], out: Path, copy: bool = False) -> dict[str, int]:
    """Write every scene's transforms.json under ``out``.

    Args:
        scenes: From :func:`davis_ag.worlds.triangles.geometry_scenes`.
        out: The claimed export folder.
        copy: Copy the images instead of referring to them.

    Returns:
        Totals: ``scenes``, ``frames``.
    """
    totals = {"scenes": 0, "frames": 0}
    for scene in scenes:
        folder = out / scene.id
        folder.mkdir(parents=True, exist_ok=True)
        content = transforms(scene, folder, copy)
        write_json_atomic(folder / TRANSFORMS, content)  # last: a scene without it is unfinished
        totals["scenes"] += 1
        totals["frames"] += len(content["frames"])
    return totals

"""Write one scene in the published DAVIS-Ag layout, atomically.

A scene is written into a hidden sibling folder and renamed into place only once every file is
complete, so a crash never leaves a half-written scene where a reader would look: a scene folder
either is whole or does not exist.
"""

from __future__ import annotations

import os
import shutil
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path

import numpy as np
from PIL import Image

from davis_ag.atomic_files import write_json_atomic

JPEG_QUALITY = 95
#: Depth images: uint16 millimetres along the optical axis, 0 where nothing is hit; farther
#: surfaces than this many millimetres are stored as this value.
DEPTH_MAX_MM = 65535


def depth_png(depth: np.ndarray) -> np.ndarray:
    """Metres (0 = nothing hit) to the uint16 millimetres of ``NNNN_depth.png``."""
    millimetres = np.rint(np.asarray(depth, dtype=np.float64) * 1000.0)
    return np.clip(millimetres, 0, DEPTH_MAX_MM).astype(np.uint16)


def partial_dir(scene_dir: Path) -> Path:
    """The hidden folder a scene is written into before it is moved into place."""
    return scene_dir.parent / f".{scene_dir.name}.partial"


class SceneWriter:
    """Collects a scene's images and annotations and publishes the folder when closed.

    Image encoding runs on a small thread pool (Pillow releases the GIL while encoding), so it
    overlaps with drawing the next view.

    Args:
        scene_dir: Where the finished scene will be.
    """

    def __init__(self, scene_dir: Path) -> None:
        # Absolute from the start: pyhelios changes the process's working directory while a
        # Visualizer or PlantArchitecture is built or destroyed, and our encoder threads may
        # still be writing then.
        self.scene_dir = Path(scene_dir).absolute()
        self.tmp_dir = partial_dir(self.scene_dir)
        if self.tmp_dir.exists():  # left by a run that crashed mid-scene
            shutil.rmtree(self.tmp_dir)
        (self.tmp_dir / "images").mkdir(parents=True)
        self.annotations: dict[str, dict] = {}
        self._pool = ThreadPoolExecutor(max_workers=2)
        self._pending: list[Future] = []

    def add_view(self, name: str, colour: np.ndarray, segmentation: np.ndarray, entry: dict,
                 depth: np.ndarray | None = None) -> None:
        """Queue one view's image, segmentation, depth and annotations entry.

        Args:
            name: Image name, ``NNNN.jpeg``.
            colour: (height, width, 3) uint8.
            segmentation: (height, width) uint8.
            entry: Its annotations.json entry.
            depth: (height, width) metres along the optical axis, 0 where nothing is hit; written
                as ``NNNN_depth.png`` (uint16 millimetres) unless None.
        """
        stem = name.rsplit(".", 1)[0]
        images = self.tmp_dir / "images"
        self._pending.append(self._pool.submit(
            lambda: Image.fromarray(colour).save(images / name, quality=JPEG_QUALITY)))
        self._pending.append(self._pool.submit(
            lambda: Image.fromarray(segmentation, mode="L").save(images / f"{stem}_seg.png", compress_level=1)))
        if depth is not None:
            self._pending.append(self._pool.submit(
                lambda: Image.fromarray(depth_png(depth)).save(images / f"{stem}_depth.png", compress_level=1)))
        self.annotations[name] = entry
        if len(self._pending) > 24:
            self._drain(keep=12)

    def _drain(self, keep: int = 0) -> None:
        while len(self._pending) > keep:
            self._pending.pop(0).result()

    def wait(self) -> None:
        """Block until every queued image is on disk (call before a renderer is closed)."""
        self._drain()

    def finish(self, scene_metadata: dict) -> Path:
        """Write annotations.json and scene.json, then move the scene into place.

        Returns:
            The scene folder.
        """
        self._drain()
        self._pool.shutdown()
        write_json_atomic(self.tmp_dir / "annotations.json", self.annotations)
        write_json_atomic(self.tmp_dir / "scene.json", scene_metadata)
        _fsync_dir(self.tmp_dir / "images")
        os.replace(self.tmp_dir, self.scene_dir)
        _fsync_dir(self.scene_dir.parent)
        return self.scene_dir

    def abort(self) -> None:
        """Drop the partial scene."""
        self._pool.shutdown(cancel_futures=True)
        shutil.rmtree(self.tmp_dir, ignore_errors=True)


def _fsync_dir(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)

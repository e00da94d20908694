"""Write one scene in the published DAVIS-Ag layout, atomically, resuming a crashed scene.

A scene is written into a hidden sibling folder and renamed into place only once every file is
complete, so a crash never leaves a half-written scene where a reader would look: a scene folder
either is whole or does not exist.

A multi-plant scene takes most of an hour, so the hidden folder also keeps a journal: one line
per view whose files are all on disk, with its annotations entry and extras. A run that finds
the folder of the same request (``resume_key``: the request and the code version) draws only the
views the journal lacks; generation is deterministic (same seed, same plants, same draws), so
the finished scene is the one an uninterrupted run writes. Any other folder is cleared. The
journal and key are removed just before the scene is published, after its last file.
"""

from __future__ import annotations

import json
import os
import shutil
from concurrent.futures import Future, ThreadPoolExecutor
from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.atomic_files import write_bytes_atomic, write_json_atomic
from davis_ag.formats.layout import ANNOTATIONS, IMAGES, SCENE_METADATA, view_file_name, write_view_files
from davis_ag.formats.scene_file import SceneFile

#: In the hidden folder only: the views written so far (JSON lines) and what they were made for.
JOURNAL = "views.jsonl"
RESUME_KEY = "resume.json"


def partial_dir(scene_dir: Path) -> Path:
    """The hidden folder a scene is written into before it is moved into place."""
    return scene_dir.parent / f".{scene_dir.name}.partial"


class SceneWriter:
    """Collects a scene's images and annotations and publishes the folder when closed.

    Image encoding runs on a small thread pool (Pillow releases the GIL while encoding), so it
    overlaps with drawing the next view.
    """

    def __init__(
        self, scene_dir: Path, resume_key: dict[str, Any] | None = None, order: list[str] | None = None
    ) -> None:
        """Args:
        scene_dir: Where the finished scene will be.
        resume_key: What the scene is made from (JSON-ready); a hidden folder left with the
            same key is resumed (:attr:`done`), any other is cleared. None: never resume.
        order: The view names in the order they are drawn: a resumed journal is kept only as
            far as it follows it (None: as far as its lines are whole).
        """
        # Absolute from the start: pyhelios changes the process's working directory while a
        # Visualizer or PlantArchitecture is built or destroyed, and our encoder threads may
        # still be writing then.
        self.scene_dir = Path(scene_dir).absolute()
        self.tmp_dir = partial_dir(self.scene_dir)
        self.resume_key = resume_key
        #: Views already on disk from a crashed run: image name -> its journal record.
        self.done: dict[str, dict[str, Any]] = {}
        if self.tmp_dir.exists():  # left by a run that crashed mid-scene
            if resume_key is not None and _read_key(self.tmp_dir) == resume_key:
                self.done = _read_journal(self.tmp_dir, order)
            else:
                shutil.rmtree(self.tmp_dir)
        (self.tmp_dir / IMAGES).mkdir(parents=True, exist_ok=True)
        if resume_key is not None:
            write_json_atomic(self.tmp_dir / RESUME_KEY, resume_key)
            # Rewritten with only the views kept, so a torn last line does not stay in the middle.
            lines = "".join(json.dumps(record) + "\n" for record in self.done.values())
            write_bytes_atomic(self.tmp_dir / JOURNAL, lines.encode())
        self.annotations: dict[str, dict] = {name: record["entry"] for name, record in self.done.items()}
        self._journal = open(self.tmp_dir / JOURNAL, "a") if resume_key is not None else None
        self._pool = ThreadPoolExecutor(max_workers=2)
        # Per queued view: its name, its files' futures and its journal record.
        self._pending: list[tuple[str, list[Future], dict[str, Any]]] = []

    def add_view(
        self,
        name: str,
        colour: np.ndarray,
        segmentation: np.ndarray,
        entry: dict,
        depth: np.ndarray | None = None,
        extras: dict[str, Any] | None = None,
        classes: np.ndarray | None = None,
    ) -> None:
        """Queue one view's image, segmentation, depth, organ classes and annotations entry.

        Args:
            name: Image name, ``NNNN.jpeg``.
            colour: (height, width, 3) uint8.
            segmentation: (height, width) uint8, or uint16 in a scene of more than 255 fruit
                (:mod:`davis_ag.formats.masks`).
            entry: Its annotations.json entry.
            depth: (height, width) metres along the optical axis, 0 where nothing is hit; written
                as ``NNNN_depth.png`` (uint16 millimetres) unless None.
            extras: JSON-ready data of the view the caller wants back when the scene is resumed
                (``done[name]["extras"]``).
            classes: (height, width) uint8 organ classes, written as ``NNNN_class.png`` unless None.
        """
        images = self.tmp_dir / IMAGES
        files = [
            self._pool.submit(write_view_files, images, name, colour=colour),
            self._pool.submit(write_view_files, images, name, segmentation=segmentation),
        ]
        if depth is not None:
            files.append(self._pool.submit(write_view_files, images, name, depth=depth))
        if classes is not None:
            files.append(self._pool.submit(write_view_files, images, name, classes=classes))
        self._pending.append(
            (
                name,
                files,
                {
                    "name": name,
                    "entry": entry,
                    "extras": extras or {},
                    "files": [name, view_file_name(name, "mask")]
                    + ([view_file_name(name, "depth")] if depth is not None else [])
                    + ([view_file_name(name, "classes")] if classes is not None else []),
                },
            )
        )
        self.annotations[name] = entry
        if len(self._pending) > 8:
            self._drain(keep=4)

    def _drain(self, keep: int = 0) -> None:
        """Wait for the oldest views' files, then journal those views, in order.

        A view leaves the queue only once journalled: a stop (Ctrl-C) while its files are awaited
        leaves it queued, so the journal never skips a view that a later line then follows.
        """
        while len(self._pending) > keep:
            _, files, record = self._pending[0]
            for future in files:
                future.result()
            if self._journal is not None:
                self._journal.write(json.dumps(record) + "\n")
                self._journal.flush()
            self._pending.pop(0)

    def wait(self) -> None:
        """Block until every queued image is on disk (call before a renderer is closed)."""
        self._drain()

    def finish(self, scene_metadata: SceneFile) -> Path:
        """Write annotations.json and scene.json, then move the scene into place.

        Returns:
            The scene folder.
        """
        self._drain()
        self._pool.shutdown()
        if self._journal is not None:
            self._journal.close()
        write_json_atomic(self.tmp_dir / ANNOTATIONS, self.annotations)
        write_json_atomic(self.tmp_dir / SCENE_METADATA, scene_metadata.as_written())
        _fsync_dir(self.tmp_dir / IMAGES)
        # Last before the rename: a run killed before it resumes from the journal, every view kept.
        (self.tmp_dir / JOURNAL).unlink(missing_ok=True)  # not part of the published layout
        (self.tmp_dir / RESUME_KEY).unlink(missing_ok=True)
        os.replace(self.tmp_dir, self.scene_dir)
        _fsync_dir(self.scene_dir.parent)
        return self.scene_dir

    def abort(self, keep: bool = False) -> None:
        """Stop writing the scene.

        Args:
            keep: Keep the hidden folder, its finished views journalled, for the next run to
                resume (a stop: Ctrl-C); otherwise drop it (an error such as a full disk, whose
                space the user wants back). Only a writer with a ``resume_key`` keeps anything.
        """
        if not keep or self._journal is None:
            self._pool.shutdown(cancel_futures=True)
            if self._journal is not None:
                self._journal.close()
            shutil.rmtree(self.tmp_dir, ignore_errors=True)
            return
        try:
            self._drain()  # views already queued are a few encodings from being kept
        except Exception:
            pass
        finally:
            self._pool.shutdown(cancel_futures=True)
            self._journal.close()


def _read_key(folder: Path) -> Any:
    try:
        return json.loads((folder / RESUME_KEY).read_text())
    except (OSError, ValueError):
        return None


def _read_journal(folder: Path, order: list[str] | None = None) -> dict[str, dict[str, Any]]:
    """The journalled views, in order, up to the first one torn, with a file not whole, or out of
    ``order``.

    Stopping there keeps the views a prefix of the scene's, so annotations.json comes out in the
    same order as an uninterrupted run's. A torn last line is what a crash mid-write leaves; a
    file cut short, what a power loss can (the journal is written after its views' files, but
    neither is synced to disk).
    """
    done: dict[str, dict[str, Any]] = {}
    try:
        lines = (folder / JOURNAL).read_text().splitlines()
    except OSError:
        return done
    for index, line in enumerate(lines):
        try:
            record = json.loads(line)
        except ValueError:
            break
        if order is not None and (index >= len(order) or record.get("name") != order[index]):
            break
        if not all(_whole(folder / IMAGES / name) for name in record["files"]):
            break
        done[record["name"]] = record
    return done


#: How our image files end: JPEG's end-of-image marker and PNG's IEND chunk (with its CRC).
_FILE_ENDS = {".jpeg": b"\xff\xd9", ".png": b"IEND\xaeB`\x82"}


def _whole(path: Path) -> bool:
    """Whether an image file is there and ends as a complete JPEG or PNG does."""
    end = _FILE_ENDS.get(path.suffix, b"")
    try:
        with open(path, "rb") as file:
            file.seek(0, os.SEEK_END)
            size = file.tell()
            file.seek(max(0, size - len(end)))
            return size > len(end) and file.read() == end
    except OSError:
        return False


def _fsync_dir(path: Path) -> None:
    fd = os.open(path, os.O_RDONLY)
    try:
        os.fsync(fd)
    finally:
        os.close(fd)

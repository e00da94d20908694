"""Make a scene again from its own records and compare it, file by file, with the one on disk.

A dataset is reproducible when the code grows and draws the same bytes from the same records.
``davis-ag verify`` proves it scene by scene: the request that made a scene is rebuilt from its
``scene.json`` (seed, scenario, crop, grid, camera, renderer, plants, appearance), the scene is
made again in a folder of its own, and every file is compared byte for byte; ``scene.json`` is
compared as JSON without what records the making (the generator's versions and the timings).
Nothing is written inside the dataset.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from davis_ag.errors import UserError
from davis_ag.formats.layout import ANNOTATIONS, LIVE_GEOMETRY, SCENE_METADATA
from davis_ag.formats.scene_file import read_scene_file
from davis_ag.generate.one_scene import SceneRequest

#: What ``scene.json`` records of the making rather than of the scene: left out of the comparison.
MAKING = ("generator", "timing_s")
#: What a verdict says of a version or a renderer the scene does not record (scenes made before it was).
UNRECORDED = "unrecorded"


@dataclass(frozen=True)
class Verdict:
    """One scene made again and compared.

    Attributes:
        scene: The scene's id (``Single-Strawberry/000``).
        files: How many files the scene on disk holds.
        differing: The files (relative to the scene) whose bytes differ, or that only one side has.
        made_by: The code that made the scene on disk (its ``scene.json``).
        remade_by: The code that made it again.
        drawn_by: The OpenGL implementation that drew the scene on disk (``GL_RENDERER``, as its
            ``scene.json`` records it; ``unrecorded`` for scenes made before it was).
        redrawn_by: The one that drew it again.
    """

    scene: str
    files: int
    differing: tuple[str, ...]
    made_by: str
    remade_by: str
    drawn_by: str = UNRECORDED
    redrawn_by: str = UNRECORDED

    @property
    def identical(self) -> bool:
        """Whether every file came out the same."""
        return not self.differing

    def text(self) -> str:
        """One line for the terminal."""
        versions = f"made by {self.made_by}, made again by {self.remade_by}"
        if self.identical:
            return (
                f"{self.scene}: identical, {self.files:,} files byte for byte (scene.json but for its "
                f"generator and timings; {versions})"
            )
        shown = ", ".join(self.differing[:5]) + (
            f" and {len(self.differing) - 5} more" if len(self.differing) > 5 else ""
        )
        line = f"{self.scene}: {len(self.differing):,} of {self.files:,} files differ ({shown}; {versions})"
        labels = f"{ANNOTATIONS} {'differs too' if ANNOTATIONS in self.differing else 'came out the same'}"
        if self.drawn_by == UNRECORDED and self.redrawn_by != UNRECORDED:
            line += (
                f"; drawn again by {self.redrawn_by}, where the scene does not record what drew it: if another "
                f"OpenGL implementation drew it, its pixels differ ({labels})"
            )
        elif self.drawn_by != self.redrawn_by:
            line += (
                f"; drawn by {self.drawn_by}, drawn again by {self.redrawn_by}: another OpenGL implementation "
                f"draws other pixels, so only the same one gives the same images ({labels})"
            )
        return line


def scene_folder_of(path: str | os.PathLike[str]) -> Path:
    """A scene folder as an absolute path through no ``..`` (its group and dataset are its parents)."""
    return Path(os.path.normpath(Path(path).absolute()))


def request_for(scene_dir: str | os.PathLike[str]) -> SceneRequest:
    """The request that made a scene of ours, rebuilt from its ``scene.json``.

    The scene's settings are read as a live scene reads them
    (:func:`davis_ag.generate.recorded_settings.read_settings`: grid, altitudes, camera, renderer, plants,
    appearance); what ``generate`` writes besides (depth, organ classes) is read here. A scene drawn by
    Helios's Visualizer comes back with ``msaa`` where ``generate`` had its default ``fxaa``: that
    renderer ignores the setting and records the same words for either.

    Args:
        scene_dir: A scene folder (``DATA/Single-Strawberry/000``).

    Returns:
        The :class:`SceneRequest`, whose seed, folder and view count are the scene's.

    Raises:
        UserError: when the folder is not a scene of ours, or its records do not rebuild it.
    """
    from davis_ag.generate.recorded_settings import read_settings
    from davis_ag.scene.view_grid import views_per_scene

    folder = scene_folder_of(scene_dir)
    where = folder / SCENE_METADATA
    if folder.is_dir() and not where.exists():  # a dataset or group folder given for its scenes
        inside = sorted(p.parent for p in [*folder.glob(f"*/{SCENE_METADATA}"), *folder.glob(f"*/*/{SCENE_METADATA}")])
        if inside:
            raise UserError(f"{folder} is not a scene folder: give scene folders, such as {inside[0]}")
    settings = read_settings(folder)
    meta = settings.metadata
    request = settings.request(
        depth=meta.depth is not None,
        antialiasing=settings.antialiasing,
        classes=meta.classes is not None,
    )
    if f"{folder.parent.name}/{folder.name}" != meta.scene:
        raise UserError(f"{where}: it records scene {meta.scene}, not this folder: was the folder renamed or moved?")
    if request.seed != settings.seed:
        raise UserError(f"{where}: its settings give seed {request.seed}, not its recorded {settings.seed}")
    views = views_per_scene(request.scenario, request.crop)
    if meta.grid is not None and meta.grid.views not in (None, views):
        raise UserError(f"{where}: its grid gives {views} views, not its recorded {meta.grid.views}")
    return request


def verify_scene(scene_dir: Path, work: Path | None = None, progress: bool = True) -> Verdict:
    """Make a scene again from its records and compare it with the one on disk.

    Args:
        scene_dir: The scene folder.
        work: Where to make it again (a fresh temporary folder, removed after, when None); the
            scene lands in ``work/GROUP/NNN``, so a kept ``work`` holds it as a dataset.
        progress: Show the generator's progress.

    Returns:
        The :class:`Verdict`.
    """
    from davis_ag.generate.run_progress import RunOptions
    from davis_ag.generate.runner import run_dataset
    from davis_ag.provenance import code_version

    scene_dir = scene_folder_of(scene_dir)
    request = request_for(scene_dir)
    if work is not None and (Path(work) / request.folder).exists():  # it would be kept, not made again
        raise UserError(f"{Path(work) / request.folder} already exists: make the scene again in another folder")
    with tempfile.TemporaryDirectory(prefix="davis-ag-verify-") as temporary:
        root = Path(work) if work is not None else Path(temporary)
        run_dataset([request], root, RunOptions(workers=1, progress=progress))
        differing, files = compare_scenes(scene_dir, root / request.folder)
        again = read_scene_file(root / request.folder / SCENE_METADATA).generator
    generator = read_scene_file(scene_dir / SCENE_METADATA).generator
    made_by = (generator.version if generator else None) or UNRECORDED
    return Verdict(
        request.folder,
        files,
        tuple(differing),
        made_by,
        code_version(),
        (generator.gl_renderer if generator else None) or UNRECORDED,
        (again.gl_renderer if again else None) or UNRECORDED,
    )


def compare_scenes(ours: Path, again: Path) -> tuple[list[str], int]:
    """The files of two scene folders that differ, and how many the first holds.

    Args:
        ours: The scene on disk.
        again: The scene made again.

    Returns:
        ``(differing, files)``: paths relative to the scene, sorted; ``scene.json`` compared as JSON
        without :data:`MAKING`.
    """
    mine, theirs = _files(ours), _files(again)
    differing = sorted(set(mine) ^ set(theirs))
    for name in sorted(set(mine) & set(theirs)):
        same: Callable[[Path, Path], bool] = _same_scene_file if name == SCENE_METADATA else _same_bytes
        if not same(ours / name, again / name):
            differing.append(name)
    return sorted(differing), len(mine)


def _files(folder: Path) -> list[str]:
    """A scene's files, relative to it: hidden ones and the live geometry cache (written beside a
    scene by the live environments, not by ``generate``) left out."""
    return sorted(
        str(path.relative_to(folder))
        for path in folder.rglob("*")
        if path.is_file()
        and path.relative_to(folder).as_posix() != LIVE_GEOMETRY
        and not any(part.startswith(".") for part in path.relative_to(folder).parts)
    )


def _same_bytes(a: Path, b: Path) -> bool:
    if a.stat().st_size != b.stat().st_size:
        return False
    with a.open("rb") as first, b.open("rb") as second:
        while chunk := first.read(1 << 20):
            if chunk != second.read(len(chunk)):
                return False
    return True


def _same_scene_file(a: Path, b: Path) -> bool:
    def scene(path: Path) -> dict[str, Any]:
        return {k: v for k, v in json.loads(path.read_text()).items() if k not in MAKING}

    return scene(a) == scene(b)

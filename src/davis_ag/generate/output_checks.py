"""The output folder's rules: refuse a folder we could damage, skip a finished scene, and never
replace one made with another seed, nor add scenes drawn otherwise beside it.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from davis_ag.atomic_files import PROBE_PREFIX, prove_writable_folder
from davis_ag.errors import UserError
from davis_ag.formats.layout import ANNOTATIONS, ROOT_FILES, SCENE_METADATA
from davis_ag.formats.scene_file import SceneFile, read_scene_file
from davis_ag.render.backends import antialiasing_of

if TYPE_CHECKING:
    from davis_ag.generate.one_scene import SceneRequest


def read_scene_record(scene_dir: Path) -> SceneFile | None:
    """A finished scene's scene.json, or None when it carries none of ours that can be read."""
    try:
        return read_scene_file(scene_dir / SCENE_METADATA)
    except UserError:
        return None


def check_output_root(root: Path) -> None:
    """Refuse an output folder we could damage or cannot write.

    Raises:
        UserError: when ``root`` is a file, holds something that is not a DAVIS-Ag dataset, or
            cannot be written.
    """
    from davis_ag.scene.specs import parse_group_name

    if root.exists() and not root.is_dir():
        raise UserError(f"{root} is a file, not a folder: choose another --out")
    if root.is_dir():
        strangers = [
            p.name
            for p in root.iterdir()
            if p.name not in ROOT_FILES
            and not p.name.startswith(PROBE_PREFIX)
            and not (p.is_dir() and parse_group_name(p.name))
        ]
        if strangers:
            raise UserError(
                f"{root} holds other things ({', '.join(sorted(strangers)[:3])}): "
                "choose an empty or DAVIS-Ag folder for --out"
            )
    prove_writable_folder(root)


def check_scene_slot(root: Path, request: SceneRequest) -> bool:
    """Whether a scene is already complete (True: skip it).

    A scene's folder appears only once the scene is whole (it is written under a hidden partial
    name first), so a folder without its labels lost them afterwards: it is neither skipped as
    complete nor drawn over.

    Raises:
        UserError: when a finished scene was made with a different seed, image size, depth
            choice or antialiasing, or has lost its labels: it is never replaced.
    """
    scene_dir = root / request.folder
    if not scene_dir.exists():
        return False
    record = read_scene_record(scene_dir)
    seed = record.seed if record is not None else None
    if seed != request.seed:
        raise UserError(
            f"{scene_dir} already holds a scene made with other settings (seed {seed}, "
            f"not {request.seed}): use another --out or --seed, or move it away"
        )
    if record is not None:
        _check_drawn_alike(scene_dir, record, request)
    if not (scene_dir / ANNOTATIONS).is_file():
        raise UserError(
            f"{scene_dir} has lost its {ANNOTATIONS} (missing or unreadable), so it is not complete: "
            "move the folder out of the dataset and run again to make the scene anew (validate lists every such scene)"
        )
    return True


def check_drawn_like_the_rest(root: Path, request: SceneRequest, finished: list[str]) -> None:
    """Refuse a run that would add a scene drawn otherwise than the folder's finished ones.

    One finished scene stands for all: every run checks its scenes against them, so a folder's
    scenes agree (reading every scene.json of a large dataset would take minutes).

    Args:
        root: The dataset folder.
        request: A scene this run will make.
        finished: Ids of the folder's finished scenes.

    Raises:
        UserError: as :func:`check_scene_slot`.
    """
    for scene_id in finished:
        record = read_scene_record(root / scene_id)
        if record is not None:
            _check_drawn_alike(root / scene_id, record, request)
            return


def _check_drawn_alike(scene_dir: Path, record: SceneFile, request: SceneRequest) -> None:
    """What dataset.json does not hold but each scene.json does: a resumed run must not add scenes
    drawn otherwise beside the finished ones (a depth-less scene among scenes with depth stops
    ``export pointcloud`` halfway)."""
    size = record.image_size()
    if size is not None and size != (request.camera.width, request.camera.height):
        raise UserError(
            f"{scene_dir} was drawn at {size[0]}x{size[1]}, not {request.camera.width}x"
            f"{request.camera.height}: use the same --size or another --out"
        )
    if (record.depth is not None) != request.depth:
        made, asked = ("with", "without") if record.depth is not None else ("without", "with")
        raise UserError(
            f"{scene_dir} was made {made} depth images, this run asks {asked}: "
            f"{'drop' if request.depth is False else 'add'} --no-depth (config: depth) or use another --out"
        )
    if record.renderer is not None and record.renderer.name == "opengl" == request.renderer:
        drawn = antialiasing_of(record.renderer)
        if drawn != request.antialiasing:
            raise UserError(
                f"{scene_dir} was drawn with antialiasing {drawn}, not {request.antialiasing}: "
                f"use --antialiasing {drawn} (config: antialiasing) or another --out"
            )

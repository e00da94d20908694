"""The output folder's rules: refuse a folder we could damage, skip a finished scene, and never
replace one made with another seed or image size.
"""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from davis_ag.atomic_files import PROBE_PREFIX, prove_writable_folder
from davis_ag.errors import UserError
from davis_ag.formats.layout import ANNOTATIONS, ROOT_FILES, SCENE_METADATA
from davis_ag.formats.scene_file import read_scene_file

if TYPE_CHECKING:
    from davis_ag.generate.one_scene import SceneRequest


def read_scene_seed(scene_dir: Path) -> int | None:
    """The seed a finished scene was made with, or None when it carries no scene.json of ours."""
    try:
        return read_scene_file(scene_dir / SCENE_METADATA).seed
    except UserError:
        return None


def read_scene_size(scene_dir: Path) -> tuple[int, int] | None:
    """The image size a finished scene was drawn at, or None when its scene.json does not say."""
    try:
        return read_scene_file(scene_dir / SCENE_METADATA).image_size()
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
        UserError: when a finished scene was made with a different seed or image size, or has
            lost its labels: it is never replaced.
    """
    scene_dir = root / request.folder
    if scene_dir.exists():
        seed = read_scene_seed(scene_dir)
        if seed != request.seed:
            raise UserError(
                f"{scene_dir} already holds a scene made with other settings (seed {seed}, "
                f"not {request.seed}): use another --out or --seed, or move it away"
            )
        size = read_scene_size(scene_dir)
        if size is not None and size != (request.camera.width, request.camera.height):
            raise UserError(
                f"{scene_dir} was drawn at {size[0]}x{size[1]}, not {request.camera.width}x"
                f"{request.camera.height}: use the same --size or another --out"
            )
        if not (scene_dir / ANNOTATIONS).is_file():
            raise UserError(
                f"{scene_dir} has lost its {ANNOTATIONS} (missing or unreadable), so it is not complete: "
                "move the folder out of the dataset and run again to make the scene anew (validate lists every such scene)"
            )
        return True
    return False

"""Make a scene again from its own records and compare it, file by file, with the one on disk.

A dataset is reproducible when the code grows and draws the same bytes from the same records.
``davis-ag verify`` proves it scene by scene: the request that made a scene is rebuilt from its
``scene.json`` (seed, scenario, crop, camera, renderer, plants, appearance) and the dataset's
``dataset.json`` (its group's grid), the scene is made again in a folder of its own, and every file
is compared byte for byte; ``scene.json`` is compared as JSON without what records the making
(the generator's versions and the timings). Nothing is written inside the dataset.
"""

from __future__ import annotations

import json
import os
import tempfile
from collections.abc import Callable
from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any

from davis_ag.errors import UserError
from davis_ag.formats.layout import DATASET_FILE, SCENE_METADATA
from davis_ag.generate.one_scene import SceneRequest
from davis_ag.render.backends import ANTIALIASING_DESCRIPTIONS
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import STRAWBERRY_ALTITUDES, crop_spec, scenario_spec, with_strawberry_altitudes

#: What ``scene.json`` records of the making rather than of the scene: left out of the comparison.
MAKING = ("generator", "timing_s")


@dataclass(frozen=True)
class Verdict:
    """One scene made again and compared.

    Attributes:
        scene: The scene's id (``Single-Strawberry/000``).
        files: How many files the scene on disk holds.
        differing: The files (relative to the scene) whose bytes differ, or that only one side has.
        made_by: The code that made the scene on disk (its ``scene.json``).
        remade_by: The code that made it again.
    """

    scene: str
    files: int
    differing: tuple[str, ...]
    made_by: str
    remade_by: str

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
        return f"{self.scene}: {len(self.differing):,} of {self.files:,} files differ ({shown}; {versions})"


def scene_folder_of(path: str | os.PathLike[str]) -> Path:
    """A scene folder as an absolute path through no ``..`` (its group and dataset are its parents)."""
    return Path(os.path.normpath(Path(path).absolute()))


def request_for(scene_dir: Path) -> SceneRequest:
    """The request that made a scene of ours, rebuilt from its records.

    Args:
        scene_dir: A scene folder (``DATA/Single-Strawberry/000``) holding ``scene.json``, in a
            dataset whose root holds ``dataset.json``.

    Returns:
        The :class:`SceneRequest`, whose seed is the scene's.

    Raises:
        UserError: when the folder is not a scene of ours, or its records do not rebuild its seed.
    """
    scene_dir = scene_folder_of(scene_dir)
    scene = _read_json(scene_dir / SCENE_METADATA)
    dataset = _read_json(scene_dir.parent.parent / DATASET_FILE)
    where = scene_dir / SCENE_METADATA
    try:
        crop = crop_spec(scene["crop"])
        scenario = scenario_spec(scene["scenario"], crop)
        grid = dataset["groups"][scene_dir.parent.name]["grid"]
        altitudes = tuple(grid.get("altitudes_m", ()))
        for choice, heights in STRAWBERRY_ALTITUDES.items():  # strawberry's two altitude choices
            if crop.name == "strawberry" and altitudes == tuple(heights[i] for i in grid["altitude_levels"]):
                crop = with_strawberry_altitudes(crop, choice)
        scenario = replace(
            scenario,
            extent=tuple(grid["extent"]),
            step=grid["step"],
            altitude_levels=tuple(grid["altitude_levels"]),
            headings=grid["headings"],
        )
        camera = scene["camera"]
        renderer = scene["renderer"]
        antialiasing = {text: mode for mode, text in ANTIALIASING_DESCRIPTIONS.items()}.get(
            renderer.get("antialiasing"), "fxaa"
        )
        request = SceneRequest(
            scenario,
            crop,
            int(scene_dir.name),
            int(scene["dataset_seed"]),
            Camera(int(camera["width"]), int(camera["height"]), float(camera["vfov_deg"])),
            renderer=renderer["name"],
            look=renderer.get("look"),
            depth=scene.get("depth") is not None,
            antialiasing=antialiasing,
            plants=scene.get("plant_generator", "canopy"),
            appearance=(scene.get("appearance") or {}).get("mode", "paper"),
            classes=scene.get("classes") is not None,
        )
    except (KeyError, TypeError, ValueError) as error:
        raise UserError(
            f"{where}: cannot rebuild how this scene was made ({error}): only scenes of ours can be verified"
        ) from None
    if request.seed != scene.get("seed") or request.folder != scene.get("scene"):
        raise UserError(
            f"{where}: its records rebuild scene {request.folder} with seed {request.seed}, not "
            f"{scene.get('scene')} with seed {scene.get('seed')}: was the folder renamed or moved?"
        )
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
    if work is not None and (Path(work) / request.folder).exists():
        raise UserError(f"{Path(work) / request.folder} already exists: choose a folder that does not hold this scene")
    with tempfile.TemporaryDirectory(prefix="davis-ag-verify-") as temporary:
        root = Path(work) if work is not None else Path(temporary)
        run_dataset([request], root, RunOptions(workers=1, progress=progress))
        differing, files = compare_scenes(scene_dir, root / request.folder)
    made_by = _read_json(scene_dir / SCENE_METADATA).get("generator", {}).get("version", "unrecorded")
    return Verdict(request.folder, files, tuple(differing), made_by, code_version())


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
    return sorted(
        str(path.relative_to(folder))
        for path in folder.rglob("*")
        if path.is_file() and not any(part.startswith(".") for part in path.relative_to(folder).parts)
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
        return {k: v for k, v in _read_json(path).items() if k not in MAKING}

    return scene(a) == scene(b)


def _read_json(path: Path) -> dict[str, Any]:
    try:
        data = json.loads(path.read_text())
    except FileNotFoundError:
        raise UserError(f"{path}: not found; give a scene folder of a dataset made by davis-ag generate") from None
    except (OSError, ValueError) as error:
        raise UserError(f"{path}: cannot be read ({error})") from None
    if not isinstance(data, dict):
        raise UserError(f"{path}: not a JSON object")
    return data

"""The two files at a dataset's root besides scene folders: dataset.json and splits.json.

- ``dataset.json`` records what every scene of the folder shares (dataset seed, image size,
  field of view, each group's viewpoint grid); a run checks it before touching anything, so one
  folder never mixes scenes made with different settings.
- ``splits.json`` is the 70/30 train/test split by scene of section V-D,
  ``{"seed": int, "train": [scene ids], "test": [scene ids]}``, drawn by
  :mod:`davis_ag.formats.splits` from the dataset seed; it depends only on the seed and the scenes
  on disk, so a resumed run writes the same one.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from davis_ag.atomic_files import write_json_atomic
from davis_ag.errors import UserError
from davis_ag.formats.layout import ANNOTATIONS, DATASET_FILE, SPLITS_FILE
from davis_ag.formats.models import DatasetFile, SplitsFile, one_line
from davis_ag.formats.splits import recorded_seed, split_scenes
from davis_ag.generate.one_scene import SceneRequest
from davis_ag.generate.run_config import grid_settings
from davis_ag.render.backends import resolve_look
from davis_ag.scene.organs import organ_table
from davis_ag.scene.specs import parse_group_name

DATASET_FORMAT = "davis-ag-dataset/1"


def dataset_settings(requests: Sequence[SceneRequest]) -> dict[str, Any]:
    """The dataset-wide settings of a list of requests (all must share seed and camera).

    Raises:
        UserError: when requests mix seeds or image sizes.
    """
    first = requests[0]
    for request in requests:
        if (
            request.dataset_seed != first.dataset_seed
            or request.camera != first.camera
            or (request.renderer, request.look, request.plants, request.appearance)
            != (first.renderer, first.look, first.plants, first.appearance)
        ):
            raise UserError(
                "the scenes of one run must share the dataset seed, the image size, the renderer, "
                "the look, the plant generator and the appearance"
            )
    groups: dict[str, Any] = {}
    for request in requests:
        group: dict[str, Any] = {"grid": grid_settings(request.scenario, request.crop)}
        if request.structures != "none":  # a group without a structure records what it always did
            group["structures"] = request.structures
        groups[request.folder.split("/")[0]] = group
    return DatasetFile.model_validate(
        {
            "format": DATASET_FORMAT,
            "seed": first.dataset_seed,
            "image_size": (first.camera.width, first.camera.height),
            "vfov_deg": first.camera.vfov,
            "renderer": first.renderer,
            "look": resolve_look(first.renderer, first.look),
            "plants": first.plants,
            "appearance": first.appearance,
            "classes": organ_table() if first.classes else None,
            "groups": groups,
        }
    ).to_json()


def complete_scenes(root: Path) -> list[str]:
    """Ids of the whole scenes under a dataset root (hidden partial folders are not scenes)."""
    if not root.is_dir():
        return []
    return sorted(
        f"{group.name}/{scene.name}"
        for group in root.iterdir()
        if group.is_dir() and parse_group_name(group.name)
        for scene in group.iterdir()
        if scene.is_dir() and not scene.name.startswith(".") and (scene / ANNOTATIONS).is_file()
    )


def reconcile_settings(root: Path, wanted: dict[str, Any]) -> dict[str, Any]:
    """Check a run's settings against the folder's dataset.json; the merged settings to write.

    Args:
        root: The dataset folder.
        wanted: :func:`dataset_settings` of this run.

    Returns:
        The settings with the groups of both.

    Raises:
        UserError: when the folder holds scenes made with another seed, image size or grid.
    """
    path = root / DATASET_FILE
    if not path.is_file():
        return wanted
    try:
        old = DatasetFile.model_validate_json(path.read_bytes()).to_json()
    except OSError as error:
        raise UserError(
            f"{path} is unreadable ({error.strerror}): move it away if the folder holds no scenes of ours"
        ) from None
    except ValidationError as error:
        raise UserError(f"{one_line(error, str(path))}: move it away if the folder holds no scenes of ours") from None
    present = complete_scenes(root)
    if not present:  # nothing was finished with the old settings: they may change freely
        return wanted
    for key, flag in (
        ("seed", "--seed"),
        ("image_size", "--size"),
        ("vfov_deg", "the field of view"),
        ("renderer", "--renderer"),
        ("look", "--look"),
        ("plants", "--plants"),
        ("appearance", "--appearance"),
    ):
        if old.get(key) != wanted[key]:
            shown = [_shown(old.get(key)), _shown(wanted[key])]
            raise UserError(
                f"{root} holds scenes made with {key} {shown[0]}, not {shown[1]}: use the same {flag} or another --out"
            )
    groups = dict(old["groups"])
    for name, settings in wanted["groups"].items():
        if name in groups and groups[name] != settings and any(s.startswith(name + "/") for s in present):
            made, asked = groups[name].get("structures", "none"), settings.get("structures", "none")
            if made != asked:
                raise UserError(
                    f"{root}: {name} scenes were made with structures {made}, not {asked}: use "
                    f"--structures {made} (or structures: {made} in the config) or another --out"
                )
            raise UserError(
                f"{root}: {name} scenes were made with grid {groups[name]['grid']}, not "
                f"{settings['grid']}: use the same grid or another --out"
            )
        groups[name] = settings
    return {**wanted, "groups": groups}


def _shown(value: Any) -> str:
    """A setting as a user types it: an image size as WIDTHxHEIGHT."""
    if isinstance(value, list) and len(value) == 2 and all(isinstance(v, int) for v in value):
        return f"{value[0]}x{value[1]}"
    return str(value)


# ---------------------------------------------------------------------------------------------
# splits.json


def write_splits(root: Path, seed: int | None = None) -> Path:
    """Write ``<root>/splits.json`` atomically from the complete scenes on disk.

    Args:
        root: The dataset root.
        seed: The dataset seed; None reads it from dataset.json (0 without one).

    Returns:
        The path written.
    """
    root = Path(root)
    if seed is None:
        seed = recorded_seed(root)
    path = root / SPLITS_FILE
    write_json_atomic(path, SplitsFile(seed=seed, **split_scenes(complete_scenes(root), seed)).to_json())
    return path

"""The two files at a dataset's root besides scene folders: dataset.json and splits.json.

- ``dataset.json`` records what every scene of the folder shares (dataset seed, image size,
  field of view, each group's viewpoint grid); a run checks it before touching anything, so one
  folder never mixes scenes made with different settings.
- ``splits.json`` is the 70/30 train/test split by scene of section V-C,
  ``{"seed": int, "train": [scene ids], "test": [scene ids]}``, drawn per group from the dataset
  seed; it depends only on the seed and the scenes on disk, so a resumed run writes the same one.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Sequence

import numpy as np

from davis_ag.atomic_files import write_json_atomic
from davis_ag.errors import UserError
from davis_ag.generate.one_scene import SceneRequest
from davis_ag.generate.run_config import grid_settings
from davis_ag.render.backends import resolve_look
from davis_ag.scene.organs import organ_table
from davis_ag.scene.specs import CROPS, SCENARIOS, parse_group_name

DATASET_FILE = "dataset.json"
SPLITS_FILE = "splits.json"
DATASET_FORMAT = "davis-ag-dataset/1"
#: Share of each group's scenes in the training split (section V-C).
TRAIN_FRACTION = 0.7


def dataset_settings(requests: Sequence[SceneRequest]) -> dict[str, Any]:
    """The dataset-wide settings of a list of requests (all must share seed and camera).

    Raises:
        UserError: when requests mix seeds or image sizes.
    """
    first = requests[0]
    for request in requests:
        if request.dataset_seed != first.dataset_seed or request.camera != first.camera \
                or (request.renderer, request.look, request.plants, request.appearance) != (
                    first.renderer, first.look, first.plants, first.appearance):
            raise UserError("the scenes of one run must share the dataset seed, the image size, the renderer, "
                            "the look, the plant generator and the appearance")
    groups: dict[str, Any] = {}
    for request in requests:
        groups[request.folder.split("/")[0]] = {"grid": grid_settings(request.scenario, request.crop)}
    return {"format": DATASET_FORMAT, "seed": first.dataset_seed,
            "image_size": [first.camera.width, first.camera.height], "vfov_deg": first.camera.vfov,
            "renderer": first.renderer, "look": resolve_look(first.renderer, first.look),
            "plants": first.plants, "appearance": first.appearance,
            "classes": organ_table() if first.classes else None, "groups": groups}


def complete_scenes(root: Path) -> list[str]:
    """Ids of the whole scenes under a dataset root (hidden partial folders are not scenes)."""
    if not root.is_dir():
        return []
    return sorted(f"{group.name}/{scene.name}" for group in root.iterdir()
                  if group.is_dir() and parse_group_name(group.name)
                  for scene in group.iterdir()
                  if scene.is_dir() and not scene.name.startswith(".") and (scene / "annotations.json").is_file())


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
        old = json.loads(path.read_text())
        assert isinstance(old, dict) and isinstance(old.get("groups"), dict)
    except (OSError, ValueError, AssertionError):
        raise UserError(f"{path} is unreadable: move it away if the folder holds no scenes of ours") from None
    present = complete_scenes(root)
    if not present:  # nothing was finished with the old settings: they may change freely
        return wanted
    # Datasets from before the choice of renderer were drawn by Helios.
    # Datasets from before the choice of plants grew PlantArchitecture plants, and before
    # randomised appearance had the paper's.
    old = {"renderer": "helios", "look": "helios", "plants": "architecture", "appearance": "paper", **old}
    for key, flag in (("seed", "--seed"), ("image_size", "--size"), ("vfov_deg", "the field of view"),
                      ("renderer", "--renderer"), ("look", "--look"), ("plants", "--plants"),
                      ("appearance", "--appearance")):
        if old.get(key) != wanted[key]:
            shown = [_shown(old.get(key)), _shown(wanted[key])]
            raise UserError(f"{root} holds scenes made with {key} {shown[0]}, not {shown[1]}: "
                            f"use the same {flag} or another --out")
    groups = dict(old["groups"])
    for name, settings in wanted["groups"].items():
        if name in groups and groups[name] != settings and any(s.startswith(name + "/") for s in present):
            raise UserError(f"{root}: {name} scenes were made with grid {groups[name]['grid']}, not "
                            f"{settings['grid']}: use the same grid or another --out")
        groups[name] = settings
    return {**wanted, "groups": groups}


def _shown(value: Any) -> str:
    """A setting as a user types it: an image size as WIDTHxHEIGHT."""
    if isinstance(value, list) and len(value) == 2 and all(isinstance(v, int) for v in value):
        return f"{value[0]}x{value[1]}"
    return str(value)


# ---------------------------------------------------------------------------------------------
# splits.json


def split_group(scene_ids: Sequence[str], seed: int) -> dict[str, list[str]]:
    """The seeded 70/30 train/test split of one group's scenes.

    The group's ids are sorted and shuffled with a generator seeded by the dataset seed and the
    group (scenario, crop), and the first ``round(0.7 n)`` train, keeping a scene on each side
    when the group has two or more. The split depends only on the seed and the set of ids.

    Args:
        scene_ids: Ids of one group, e.g. ``Single-Strawberry/003``.
        seed: The dataset seed.

    Returns:
        ``{"train": [...], "test": [...]}``, each sorted.
    """
    ids = sorted(scene_ids)
    parsed = parse_group_name(ids[0].split("/")[0]) if ids else None
    stream = [list(SCENARIOS).index(parsed[0].name), list(CROPS).index(parsed[1].name)] if parsed else [0, 0]
    # A stream of its own (the trailing 1) so the split never correlates with any scene seed.
    order = np.random.default_rng(np.random.SeedSequence([seed, *stream, 1])).permutation(len(ids))
    n_train = int(round(TRAIN_FRACTION * len(ids)))
    if len(ids) >= 2:
        n_train = min(max(n_train, 1), len(ids) - 1)
    return {"train": sorted(ids[i] for i in order[:n_train]), "test": sorted(ids[i] for i in order[n_train:])}


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
        try:
            seed = int(json.loads((root / DATASET_FILE).read_text())["seed"])
        except (OSError, ValueError, KeyError, TypeError):
            seed = 0
    groups: dict[str, list[str]] = {}
    for scene_id in complete_scenes(root):
        groups.setdefault(scene_id.split("/")[0], []).append(scene_id)
    train: list[str] = []
    test: list[str] = []
    for ids in groups.values():
        split = split_group(ids, seed)
        train += split["train"]
        test += split["test"]
    path = root / SPLITS_FILE
    write_json_atomic(path, {"seed": seed, "train": sorted(train), "test": sorted(test)})
    return path

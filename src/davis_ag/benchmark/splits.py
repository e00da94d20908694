"""Which scenes an environment uses: scenario and crop filter, then the train/test split.

Split rule (section V-C: 70 % of the data trains, 30 % tests):

- If the dataset has a ``splits.json`` (``Dataset.splits``), its ``train`` and ``test`` lists
  are used as they are; scenes in neither list are only used by ``split="all"``.
- Otherwise (e.g. the original download, which ships none) the split is drawn per group
  (scenario and crop, i.e. per published folder such as ``Single-Strawberry``): the group's
  scene ids are sorted, shuffled with ``numpy.random.default_rng(0)``, and the first
  ``round(0.7 n)`` are train, the rest test, keeping at least one scene on each side when the
  group has two or more. The same dataset therefore always splits the same way.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from davis_ag.errors import UserError
from davis_ag.scene.specs import crop_spec, parse_group_name, scenario_spec

#: Share of each group's scenes that train when the dataset has no splits.json.
TRAIN_FRACTION = 0.7
#: Seed of the fallback split.
SPLIT_SEED = 0
SPLITS = ("train", "test", "all")


def scene_scenario(scene: Any) -> str | None:
    """A scene's scenario (``sp``/``mp``): the reader's, else from its group folder name."""
    value = getattr(scene, "scenario", None)
    if value:
        return scenario_spec(str(getattr(value, "name", value))).name
    parsed = parse_group_name(str(scene.id).split("/")[0])
    return parsed[0].name if parsed else None


def scene_crop(scene: Any) -> str | None:
    """A scene's crop name (``strawberry``/``tomato``/``vine``), or ``None`` if unknown."""
    value = getattr(scene, "crop", None)
    if value:
        try:
            return crop_spec(str(getattr(value, "name", value))).name
        except UserError:
            return None
    parsed = parse_group_name(str(scene.id).split("/")[0])
    return parsed[1].name if parsed else None


def fallback_split(scene_ids: list[str]) -> dict[str, list[str]]:
    """The seeded 70/30 split of one group's scenes (see the module docstring).

    Args:
        scene_ids: The group's scene ids, any order.

    Returns:
        ``{"train": [...], "test": [...]}``, each sorted.
    """
    ids = sorted(scene_ids)
    order = np.random.default_rng(SPLIT_SEED).permutation(len(ids))
    n_train = int(round(TRAIN_FRACTION * len(ids)))
    if len(ids) >= 2:
        n_train = min(max(n_train, 1), len(ids) - 1)
    train = sorted(ids[i] for i in order[:n_train])
    test = sorted(ids[i] for i in order[n_train:])
    return {"train": train, "test": test}


def select_scenes(dataset: Any, scenario: str, split: str, crop: str | None = None) -> list[Any]:
    """The scenes of one scenario (and crop) in one split, sorted by id.

    Args:
        dataset: An opened dataset (``davis_ag.data.reader.Dataset``).
        scenario: ``sp`` or ``mp``.
        split: ``train``, ``test`` or ``all``.
        crop: Keep only this crop; ``None`` keeps every crop.

    Returns:
        The selected scenes.

    Raises:
        UserError: for an unknown split, or when nothing is left.
    """
    scenario = scenario_spec(scenario).name
    crop = crop_spec(crop).name if crop else None
    if split not in SPLITS:
        raise UserError(f"unknown split {split!r}: choose one of {', '.join(SPLITS)}")
    scenes = [s for s in dataset.scenes
              if scene_scenario(s) == scenario and (crop is None or scene_crop(s) == crop)]
    where = f"{scenario}{'/' + crop if crop else ''} scenes of {dataset.root}"
    if not scenes:
        raise UserError(f"no {where}: pick a scenario/crop the dataset has")
    if split == "all":
        return sorted(scenes, key=lambda s: s.id)
    splits = getattr(dataset, "splits", None)
    if splits:
        keep = {str(i) for i in splits.get(split, [])}
    else:
        groups: dict[tuple[str | None, str | None], list[str]] = {}
        for s in scenes:
            groups.setdefault((scene_scenario(s), scene_crop(s)), []).append(s.id)
        keep = {i for ids in groups.values() for i in fallback_split(ids)[split]}
    chosen = sorted((s for s in scenes if s.id in keep), key=lambda s: s.id)
    if not chosen:
        raise UserError(f"the {split} split has none of the {len(scenes)} {where}: use "
                        "--split all (split='all') or a dataset with more scenes")
    return chosen

"""A trained model's files beside it: the model's own path and its training record
(``NAME.training.json``: settings, train scenes, sittings, learning curve, snapshot scores).

Kept apart from :mod:`davis_ag.benchmark.training` so that what reads a record (evaluation's
check of the scenes and split rule a model learnt from, ``reproduce``) needs neither torch nor SB3.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from davis_ag.errors import UserError


def model_path(out_path: str | os.PathLike[str]) -> Path:
    """The ``.zip`` SB3 writes for ``out_path``."""
    out = Path(out_path)
    return out if out.suffix == ".zip" else out.with_name(out.name + ".zip")


def training_record_path(out_path: str | os.PathLike[str]) -> Path:
    """``NAME.training.json`` beside the model ``NAME.zip``: settings, sittings, steps/s."""
    stem = model_path(out_path).with_suffix("")
    return stem.with_name(stem.name + ".training.json")


def recorded_train_scenes(out_path: str | os.PathLike[str]) -> list[str] | None:
    """The train scenes a saved model's training record lists (None: no record, or one from before
    they were recorded)."""
    try:
        record = json.loads(training_record_path(out_path).read_text())
    except (OSError, ValueError):
        return None
    scenes = record.get("train_scenes") if isinstance(record, dict) else None
    return [str(s) for s in scenes] if isinstance(scenes, list) else None


def recorded_split_rule(out_path: str | os.PathLike[str]) -> str | None:
    """The split rule a saved model's training record names (None: no record, or one of the
    ``scenes`` rule, which records none so that runs from before the rules resume)."""
    try:
        record = json.loads(training_record_path(out_path).read_text())
    except (OSError, ValueError):
        return None
    rule = record.get("split_rule") if isinstance(record, dict) else None
    return str(rule) if isinstance(rule, str) else None


def check_trained_split(
    name: str, trained_on: list[str] | None, trained_rule: str | None, described: dict[str, Any]
) -> None:
    """Refuse to score a model on a test split it has seen: one trained under another split rule
    (whose train side may hold these very starts), or under ``scenes`` on a test scene.

    Args:
        name: The policy's row name, for the message.
        trained_on: The scenes its training record lists (None: no record).
        trained_rule: The split rule its record names (None: a record from before the rules, or none).
        described: The environment's ``describe()``.

    Raises:
        UserError: one line saying what to do.
    """
    if described.get("split") != "test" or trained_on is None:
        return
    rule, ours = trained_rule or "scenes", described.get("split_rule") or "scenes"
    if rule != ours:
        raise UserError(
            f"{name}: trained under --split-rule {rule}, whose train side overlaps this {ours} rule's test "
            f"split: evaluate it with --split-rule {rule}, or train it again with --split-rule {ours}"
        )
    seen = sorted(set(trained_on) & set(described.get("scenes", []))) if rule == "scenes" else []
    if seen:
        raise UserError(
            f"{name}: trained on {len(seen)} of the {len(described['scenes'])} test scenes "
            f"({seen[0]}{', ...' if len(seen) > 1 else ''}): the split changed after it was trained "
            "(scenes added or removed, or splits.json edited); train it again on this dataset"
        )

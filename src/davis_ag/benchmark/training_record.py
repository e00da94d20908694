"""A trained model's files beside it: the model's own path and its training record
(``NAME.training.json``: settings, train scenes, sittings, learning curve, snapshot scores).

Kept apart from :mod:`davis_ag.benchmark.training` so that what reads a record (evaluation's
check of the scenes a model learnt from, ``reproduce``) needs neither torch nor SB3.
"""

from __future__ import annotations

import json
import os
from pathlib import Path


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

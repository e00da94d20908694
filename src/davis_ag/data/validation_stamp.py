"""A stamp of what validating a dataset folder would read: the validator's code, the root files it
checks (their bytes; for a group opened alone, its own entries in them) and every scene file's
name, size and modification time, as one SHA-256.

A long run that resumes (``davis-ag reproduce``) would validate its data at every sitting; at the
paper's scale that reads 9 GB of SP strawberry views, minutes on 2 cores. Two equal stamps mean the
same rules would read files that were not rewritten since, so the run keeps the earlier report.
Sizes and times, not contents, because hashing the views would cost as much as validating them;
what a stamp cannot see is a file rewritten in place with its size and time restored, which no
writer of ours does (``davis-ag validate`` always reads everything).
"""

from __future__ import annotations

import ast
import hashlib
import json
import os
from pathlib import Path

from davis_ag.data.reader import Dataset, open_dataset
from davis_ag.formats.layout import DATASET_FILE, SPLITS_FILE
from davis_ag.formats.models import SplitsFile

#: The packages whose code decides what a validation finds: a change to any of them is a new stamp.
VALIDATOR_PACKAGES = ("data", "formats")


def validator_digest() -> bytes:
    """SHA-256 of the code of :data:`VALIDATOR_PACKAGES` (this module aside), file by file in name
    order: each file's syntax tree without its docstrings (:func:`code_of`), so a comment, a
    docstring or a reflowed line leaves a long run's validation standing, and any change of what
    the code does does not."""
    package = Path(__file__).resolve().parent.parent
    digest = hashlib.sha256()
    for name in VALIDATOR_PACKAGES:
        for source in sorted((package / name).glob("*.py")):
            if source.name == Path(__file__).name:  # the stamp's own rule decides nothing validation finds
                continue
            digest.update(f"{name}/{source.name}\0".encode())
            digest.update(code_of(source.read_text(encoding="utf-8")).encode())
    return digest.digest()


def code_of(source: str) -> str:
    """What a Python source does, as text: its syntax tree (no comments, no layout, no line
    numbers) with every docstring taken out."""
    tree = ast.parse(source)
    for node in ast.walk(tree):
        if isinstance(node, (ast.Module, ast.ClassDef, ast.FunctionDef, ast.AsyncFunctionDef)):
            body = node.body
            first = body[0] if body else None
            if isinstance(first, ast.Expr) and isinstance(first.value, ast.Constant):
                if isinstance(first.value.value, str):
                    node.body = body[1:] or [ast.Pass()]
    return ast.dump(tree)


def validation_stamp(path: str | os.PathLike[str]) -> str:
    """The stamp of validating ``path`` (a dataset root, a group folder or a scene folder).

    Args:
        path: What :func:`davis_ag.data.validate.validate_dataset` would be given.

    Returns:
        A hex SHA-256; equal for equal code, root files and scene files (names, sizes, times).

    Raises:
        UserError: when the path is not a DAVIS-Ag dataset (as :func:`open_dataset`).
    """
    dataset = open_dataset(path)
    digest = hashlib.sha256(validator_digest())
    digest.update(_own_split_entries(dataset))
    digest.update(_own_dataset_entries(dataset))
    for scene in dataset.scenes:
        for folder, subfolders, files in os.walk(scene.path):
            subfolders[:] = sorted(d for d in subfolders if not d.startswith("."))
            for name in sorted(files):
                stat = os.stat(os.path.join(folder, name))
                relative = os.path.relpath(os.path.join(folder, name), dataset.root)
                digest.update(f"{relative}\0{stat.st_size}\0{stat.st_mtime_ns}\n".encode())
    return digest.hexdigest()


def _own_dataset_entries(dataset: Dataset) -> bytes:
    """What of the root's ``dataset.json`` may bear on validating ``dataset``: every byte for a whole
    dataset; for a group or scene opened alone, the file without the other groups' ``groups``
    entries (a group's validation reads none of it; the rest is kept, to be safe).

    Each generate of a new group adds its entry: hashing the whole file gave every finished group
    of the crops run a new stamp, so each sitting validated all of them again.
    """
    file = dataset.root / DATASET_FILE
    if not file.is_file():
        return f"{DATASET_FILE}\0-".encode()
    raw = file.read_bytes()
    whole = f"{DATASET_FILE}\0".encode() + raw
    if dataset.opened == dataset.root:
        return whole
    try:
        data = json.loads(raw.decode("utf-8"))
    except (ValueError, RecursionError):
        return whole
    if not isinstance(data, dict) or not isinstance(data.get("groups"), dict):
        return whole
    own = {scene.group for scene in dataset.scenes}
    data["groups"] = {name: entry for name, entry in data["groups"].items() if name in own}
    return f"{DATASET_FILE} of these groups\0{json.dumps(data, sort_keys=True)}".encode()


def _own_split_entries(dataset: Dataset) -> bytes:
    """What validating ``dataset`` reads of the root's ``splits.json``: the entries of its own scenes.

    A group opened alone sees only its scenes' entries (:func:`davis_ag.data.dataset_checks.check_splits`),
    and the file is rewritten whenever another group gains a scene: its bytes would give SP strawberry
    a new stamp with every MP vine scene a run makes, and the run would read 24,510 views again at
    each sitting. A whole dataset, or a file the validator would refuse, counts by its bytes.
    """
    file = dataset.root / SPLITS_FILE
    if not file.is_file():
        return f"{SPLITS_FILE}\0-".encode()
    raw = file.read_bytes()
    if dataset.opened == dataset.root:  # the whole dataset: validation reads every entry
        return f"{SPLITS_FILE}\0".encode() + raw
    try:  # a file the validator would refuse counts by its bytes, whatever part is damaged
        splits = SplitsFile.model_validate(json.loads(raw.decode("utf-8")))
    except (ValueError, TypeError):
        return f"{SPLITS_FILE}\0".encode() + raw
    own = {scene.id for scene in dataset.scenes}
    entries = {"train": sorted(set(splits.train) & own), "test": sorted(set(splits.test) & own)}
    return f"{SPLITS_FILE} of these scenes\0{json.dumps(entries, sort_keys=True)}".encode()

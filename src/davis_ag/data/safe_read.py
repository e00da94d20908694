"""Reading a dataset's files safely: JSON, pixels, and nothing that resolves outside the dataset.

Every failure is one :class:`~davis_ag.errors.UserError` naming the file, never a traceback.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.errors import UserError
from davis_ag.formats.masks import as_mask


def _unique_keys(pairs: list[tuple[str, Any]]) -> dict[str, Any]:
    """An object's keys, each once: a view named twice would be read as its last copy unseen."""
    made: dict[str, Any] = {}
    for key, value in pairs:
        if key in made:
            raise ValueError(f"key {key!r} appears twice in one object")
        made[key] = value
    return made


def parse_json(text: str) -> tuple[Any, str | None]:
    """Parse a dataset's JSON text strictly: the value, or None and why it is not sound JSON of
    ours (a syntax error with its place, a key given twice, a number of more digits than Python
    reads, nesting too deep)."""
    try:
        return json.loads(text, object_pairs_hook=_unique_keys), None
    except json.JSONDecodeError as error:
        return None, f"not valid JSON (line {error.lineno} column {error.colno}: {error.msg})"
    except ValueError as error:
        return None, f"not sound JSON ({error})"
    except RecursionError:
        return None, "nested too deeply to be ours"


def read_json(path: Path, what: str) -> Any:
    """Load a JSON file, turning every failure into one :class:`UserError` line."""
    try:
        text = path.read_text(encoding="utf-8")
    except OSError as error:
        raise UserError(f"{path}: cannot read {what} ({error.strerror or error}); check the file") from None
    except UnicodeDecodeError:
        raise UserError(f"{path}: {what} is not UTF-8 text; re-download or regenerate it") from None
    data, problem = parse_json(text)
    if problem is not None:
        raise UserError(f"{path}: {what} is {problem}; re-download or regenerate it")
    return data


def check_inside(path: Path, root: Path | None) -> Path:
    """Refuse a file that resolves outside the dataset (a symlink out of it, or ``..``).

    A dataset is read as given; a link out of it could make the reader read, and a later
    rewrite of the "same" file write, anywhere on the machine.

    Args:
        path: The file about to be read.
        root: The dataset root; None skips the check.

    Returns:
        ``path``.

    Raises:
        UserError: naming the file and where it points.
    """
    if root is None:
        return path
    try:
        resolved, inside = path.resolve(), root.resolve()
    except (OSError, RuntimeError, ValueError) as error:  # a symlink loop, a NUL in a name
        raise UserError(f"{path}: cannot resolve ({error}); replace the link by the file") from None
    if resolved != inside and not resolved.is_relative_to(inside):
        raise UserError(
            f"{path}: points outside the dataset, to {resolved}; copy the file into {root} instead of linking it"
        )
    return path


def load_pixels(path: Path, mode: str | None) -> np.ndarray:
    """Decode an image (``mode`` "RGB") or an instance mask (``mode`` None: H x W uint8, or uint16
    for a 16-bit PNG: :func:`davis_ag.formats.masks.as_mask`).

    Raises:
        UserError: naming the file, when it is missing or cannot be decoded.
    """
    from PIL import Image, UnidentifiedImageError

    try:
        with Image.open(path) as im:
            pixels = np.asarray(im.convert(mode) if mode else im)
    except FileNotFoundError:
        raise UserError(f"{path}: image file missing; re-download or regenerate the scene") from None
    except (OSError, UnidentifiedImageError, ValueError, Image.DecompressionBombError) as error:
        raise UserError(f"{path}: cannot decode ({error}); re-download or regenerate the scene") from None
    if mode is None:
        pixels = as_mask(pixels)
    return pixels

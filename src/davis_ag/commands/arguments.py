"""Argument types shared by the sub-commands: sizes, counts and paths, each checked as parsed."""

from __future__ import annotations

import argparse
import re
from pathlib import Path


def image_size(text: str) -> tuple[int, int]:
    """Parse ``WIDTHxHEIGHT``."""
    match = re.fullmatch(r"(\d+)x(\d+)", text.strip())
    if not match or min(int(match[1]), int(match[2])) < 16:
        raise argparse.ArgumentTypeError(f"{text!r} is not an image size like 1280x720 (16 pixels at least)")
    return int(match[1]), int(match[2])


def count(text: str) -> int:
    """Parse a positive count."""
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not a positive whole number")
    return int(text)


def whole(text: str) -> int:
    """Parse a whole number from 0."""
    if not text.isdigit():
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number from 0")
    return int(text)


def path(text: str) -> Path:
    """Parse a path and make it absolute at once.

    pyhelios changes the process's working directory while it builds and closes a Visualizer, so
    a relative path resolved later could point into pyhelios's folders.
    """
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path")
    return Path(text).expanduser().absolute()


def add_renderer_flags(parser: argparse.ArgumentParser) -> None:
    """``--renderer`` and ``--look``, shared by generate and preview."""
    from davis_ag.render.backends import LOOKS, RENDERERS

    parser.add_argument("--renderer", choices=RENDERERS,
                        help="opengl: ours (default); helios: pyhelios's Visualizer, the slower reference")
    parser.add_argument("--look", choices=LOOKS,
                        help="default: full-resolution, filtered textures (default); helios: Helios's frames, "
                             "reduced unfiltered textures included (the helios renderer draws only this)")
    parser.add_argument("--antialiasing", type=int, choices=(4, 1),
                        help="our renderer's colour samples per pixel: 4 (default) or 1 (no antialiasing; "
                             "several times faster on many small triangles without a GPU; ids exact either way)")

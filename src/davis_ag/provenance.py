"""Which code made an output: the package version and, in a git checkout, the commit."""

from __future__ import annotations

import functools
import subprocess
from pathlib import Path

from davis_ag import __version__


@functools.cache
def source_revision() -> str | None:
    """The git commit of the checkout this package runs from, with ``-dirty`` when its tracked
    files differ from that commit; None when it is not run from a git checkout (an installed wheel).
    Looked up once per process."""
    here = Path(__file__).resolve().parent
    try:
        commit = subprocess.run(
            ["git", "-C", str(here), "rev-parse", "--short=12", "HEAD"],
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
        changed = subprocess.run(
            ["git", "-C", str(here), "status", "--porcelain", "--untracked-files=no", "--", str(here)],
            capture_output=True,
            text=True,
            timeout=10,
            check=True,
        ).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return None
    return f"{commit}-dirty" if changed else commit


def code_version() -> str:
    """``0.1.0`` or ``0.1.0+<commit>[-dirty]``: what to record beside an output."""
    revision = source_revision()
    return f"{__version__}+{revision}" if revision else __version__

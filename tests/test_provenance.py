"""The code version recorded with outputs names the commit when run from a git checkout."""

from __future__ import annotations

import subprocess
from pathlib import Path

import pytest

import davis_ag
from davis_ag.provenance import code_version, source_revision


def test_code_version_names_the_checkouts_commit() -> None:
    here = Path(davis_ag.__file__).parent
    head = subprocess.run(["git", "-C", str(here), "rev-parse", "HEAD"], capture_output=True, text=True)
    if head.returncode != 0:
        pytest.skip("not run from a git checkout")
    revision = source_revision()
    assert revision is not None and head.stdout.startswith(revision.removesuffix("-dirty"))
    assert code_version() == f"{davis_ag.__version__}+{revision}"

"""Fixtures shared across test folders: tiny datasets in the published layout, made without Helios."""

from __future__ import annotations

from pathlib import Path

import pytest
from layout_factory import write_tiny_dataset


@pytest.fixture(scope="module")
def sp_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two single-plant strawberry scenes (splits.json: 000 train, 001 test)."""
    return write_tiny_dataset(tmp_path_factory.mktemp("sp"), "sp", "strawberry", scenes=2)


@pytest.fixture(scope="module")
def mp_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two multi-plant strawberry scenes."""
    return write_tiny_dataset(tmp_path_factory.mktemp("mp"), "mp", "strawberry", scenes=2)

"""docs/errors.md names the tests that hold its promises: every one it names exists."""

from __future__ import annotations

import re
from pathlib import Path

REPO = Path(__file__).resolve().parent.parent


def test_every_test_the_errors_page_names_exists() -> None:
    page = (REPO / "docs" / "errors.md").read_text()
    named = re.findall(r"`(tests/[\w/]+\.py)?((?:::\w+)?)`", page)
    assert len(named) > 15
    current = None
    for path, function in named:
        current = path or current
        assert current and (REPO / current).is_file(), current
        if function:
            assert f"def {function[2:]}(" in (REPO / current).read_text(), f"{current}{function}"

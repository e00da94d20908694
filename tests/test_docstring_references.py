"""Every cross-reference to davis_ag in the docstrings and docs names something that exists.

A module that moves leaves ``:func:`davis_ag.old.place``` behind in the docstrings of others;
MkDocs does not read these roles, so this test is what notices.
"""

from __future__ import annotations

import importlib
import re
from pathlib import Path

import davis_ag

PACKAGE = Path(davis_ag.__file__).parent
ROOT = PACKAGE.parents[1]
#: A Sphinx-style role naming a davis_ag object: ``:func:`davis_ag.x.y``` or ``:class:`~davis_ag.x.Y```.
REFERENCE = re.compile(r":(?:mod|func|class|data|meth|attr|exc|obj):`~?(davis_ag\.[^`<]+?)`", re.S)


def resolves(target: str) -> bool:
    """Whether ``target`` is a module, or an attribute (a pydantic or dataclass field too) of one."""
    parts = target.rstrip("()").split(".")
    for split in range(len(parts), 0, -1):
        try:
            found: object = importlib.import_module(".".join(parts[:split]))
        except ImportError:
            continue
        for name in parts[split:]:
            fields = getattr(found, "model_fields", None) or getattr(found, "__dataclass_fields__", None) or {}
            if hasattr(found, name):
                found = getattr(found, name)
            elif isinstance(found, type) and name in fields and name == parts[-1]:
                return True
            else:
                return False
        return True
    return False


def references() -> list[tuple[str, str]]:
    files = [*sorted(PACKAGE.rglob("*.py")), *sorted((ROOT / "docs").glob("*.md")), ROOT / "README.md"]
    found = []
    for path in files:
        text = path.read_text()
        for match in REFERENCE.finditer(text):
            line = text[: match.start()].count("\n") + 1
            found.append((f"{path.relative_to(ROOT)}:{line}", re.sub(r"\s+", "", match.group(1))))
    return found


def test_there_are_references_to_check() -> None:
    assert len(references()) > 200


def test_every_reference_names_something_that_exists() -> None:
    broken = [f"{where}: {target}" for where, target in references() if not resolves(target)]
    assert not broken, "update these references (moved or renamed):\n" + "\n".join(broken)


def test_a_moved_name_is_caught() -> None:
    assert resolves("davis_ag.generate.recorded_settings.read_settings")
    assert not resolves("davis_ag.live.reopen.read_settings")
    assert not resolves("davis_ag.workflows.reproduce_configs.ReproduceConfig")

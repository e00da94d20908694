"""What a validation reports (:class:`Problem`, :class:`Report`) and the two careful reads every
check starts with: a JSON file read to one reason instead of an exception, and a path that must
not be read because it resolves outside the dataset.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path

from davis_ag.data.safe_read import check_inside, parse_json
from davis_ag.errors import UserError


@dataclass(frozen=True)
class Problem:
    """One thing wrong, and the file it is in."""

    path: Path
    reason: str

    def __str__(self) -> str:
        return f"{display_path(self.path)}: {self.reason}"


def display_path(path: Path) -> str:
    # Relative to the working directory when inside it: shorter and what the user typed.
    try:
        return os.path.relpath(path) if Path(path).is_relative_to(Path.cwd()) else str(path)
    except (ValueError, OSError):  # another drive on Windows, or a deleted working directory
        return str(path)


@dataclass
class Report:
    """What a validation run looked at and found."""

    scenes: int = 0
    views: int = 0
    boxes: int = 0
    problems: list[Problem] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True when no problem was found."""
        return not self.problems

    def summary(self) -> str:
        """One line: the counts and the verdict."""
        verdict = "sound" if self.ok else plural(len(self.problems), "problem")
        counts = ", ".join(
            plural(n, what) for n, what in ((self.scenes, "scene"), (self.views, "view"), (self.boxes, "box"))
        )
        return f"checked {counts}: {verdict}"


def plural(n: int, word: str) -> str:
    return f"{n} {word}" + ("" if n == 1 else "es" if word.endswith("x") else "s")


def read_json_file(path: Path) -> tuple[object, str | None]:
    """A JSON file's value, or None and why it cannot be read (:func:`~davis_ag.data.safe_read.parse_json`)."""
    try:
        text = path.read_text(encoding="utf-8")
    except (OSError, UnicodeDecodeError) as error:
        return None, f"cannot read ({error})"
    return parse_json(text)


def outside_reason(path: Path, root: Path | None) -> str | None:
    """Why ``path`` must not be read (it resolves outside the dataset), or None."""
    try:
        check_inside(path, root)
    except UserError as error:
        return str(error).split(": ", 1)[1]
    return None

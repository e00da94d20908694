"""Wall time per named stage of a workflow, for reports that say where the time went."""

from __future__ import annotations

import time
from collections.abc import Iterator
from contextlib import contextmanager
from dataclasses import dataclass, field


@dataclass
class Timer:
    """Wall time per named stage, in the order the stages ran.

    Attributes:
        stages: Stage name to seconds (``None`` while running).
        notes: Stage name to a remark (e.g. "reused").
    """

    stages: dict[str, float] = field(default_factory=dict)
    notes: dict[str, str] = field(default_factory=dict)

    @contextmanager
    def stage(self, name: str) -> Iterator[None]:
        """Time the body under ``name`` (seconds are added to any earlier entry of the name)."""
        start = time.perf_counter()
        try:
            yield
        finally:
            self.stages[name] = self.stages.get(name, 0.0) + time.perf_counter() - start

    @property
    def total(self) -> float:
        """Sum over stages, seconds."""
        return sum(self.stages.values())

    def rows(self) -> list[tuple[str, float, str]]:
        """``(stage, seconds, note)`` per stage."""
        return [(k, v, self.notes.get(k, "")) for k, v in self.stages.items()]

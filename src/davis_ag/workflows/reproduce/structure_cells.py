"""The ``structures`` run's cells: each row bare and with its structures, each variant on a
dataset of its own (:mod:`davis_ag.workflows.reproduce.structures_run` makes them, its page and
``--status`` read them)."""

from __future__ import annotations

from pathlib import Path

from davis_ag.workflows.reproduce.cells import Cell
from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.groups import group_key

#: Each variant: its name in files and stages, its column heading, its structures setting and the
#: dataset folder it is made in under the run's folder.
VARIANTS: tuple[tuple[str, str, str, str], ...] = (
    ("bare", "bare", "none", "dataset-bare"),
    ("structures", "with structures", "default", "dataset"),
)


def structure_cells(out: Path, config: ReproduceConfig, pairs) -> list[tuple[str, Cell]]:
    """The run's cells in its order, each with its column heading: every bare row, then every row
    with its structures."""
    return [
        (heading, Cell(f"{group_key(scenario, crop)}-{name}", out / folder, scenario, crop))
        for name, heading, _, folder in VARIANTS
        for scenario, crop in pairs
    ]

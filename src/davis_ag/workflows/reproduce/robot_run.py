"""``davis-ag reproduce --config robot``: the rows of a trellised wall, a vineyard and a greenhouse
crop played without a robot and with each robot that reaches them, every baseline, the exact
Oracle, the Best fixed action and the learners trained under each, written to docs/robot.md.

Each row and robot is a cell (:mod:`davis_ag.workflows.reproduce.cells`: its stages, cheapest
first, each resumable); the page is rewritten after every cell.
"""

from __future__ import annotations

from pathlib import Path

from davis_ag.workflows.reproduce.cells import open_run, prepare_rows, run_cells
from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.robot_cells import robot_cells


def reproduce_robot(
    config: ReproduceConfig, out: Path, results_md: Path, pairs: list[tuple[str, str]] | tuple[tuple[str, str], ...]
) -> int:
    """Generate and validate each row, evaluate every cell, train each learner in every cell and
    evaluate it; write ``results_md`` after each cell.

    Args:
        config: The run (its ``robots`` beside no robot).
        out: Work folder (``dataset``, ``models``, ``results``, ``state.json``).
        results_md: The page to (re)write (docs/robot.md's ``robot-run`` section).
        pairs: The ``(scenario, crop)`` rows.

    Returns:
        0 on success, 1 when a dataset failed validation.
    """
    from davis_ag.workflows.reproduce.pages.robot import write_robot_page

    out, results_md, state, record, clock = open_run(config, out, results_md, pairs)
    if not prepare_rows(config, out / "dataset", pairs, state, record, clock, config.structures):
        return 1
    run_cells(
        config, out, robot_cells(out, config, pairs), state, record, clock,
        lambda: write_robot_page(results_md, config, state, out, pairs),
    )  # fmt: skip
    return 0

"""``davis-ag reproduce --config structures``: what the trellises, stakes and greenhouse strings of
:mod:`davis_ag.scene.structures` change on the benchmark. The rows of a fruiting wall, a VSP and a
Wye vineyard and a greenhouse crop are made twice from the same seeds, bare (``--structures
none``: the plants, fruit, light and views of today's rows) and with their structures, and every
baseline, the exact Oracle, the Best fixed action and A2C and PPO are scored on each; written to
docs/crops.md's ``structures-run`` section.

Each row and variant is a cell (:mod:`davis_ag.workflows.reproduce.cells`: its stages, cheapest
first, each resumable); each row is made bare and then with its structures, and the page is
rewritten after every cell.
"""

from __future__ import annotations

from pathlib import Path

from davis_ag.workflows.reproduce.cells import open_run, prepare_rows, run_cells
from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.structure_cells import VARIANTS, structure_cells


def reproduce_structures(
    config: ReproduceConfig, out: Path, results_md: Path, pairs: list[tuple[str, str]] | tuple[tuple[str, str], ...]
) -> int:
    """Make and validate each row bare and with its structures, evaluate every cell, train each
    learner in every cell and evaluate it; write ``results_md`` after each cell.

    Args:
        config: The run.
        out: Work folder (``dataset-bare``, ``dataset``, ``models``, ``results``, ``state.json``).
        results_md: The page to (re)write (docs/crops.md's ``structures-run`` section).
        pairs: The ``(scenario, crop)`` rows.

    Returns:
        0 on success, 1 when a dataset failed validation.
    """
    from davis_ag.workflows.reproduce.pages.structures import write_structures_page

    out, results_md, state, record, clock = open_run(config, out, results_md, pairs, datasets=len(VARIANTS))
    for pair in pairs:  # row by row, so the largest row (the last) comes last in both variants
        for name, _, structures, folder in VARIANTS:
            label = "" if name == "structures" else f" ({name})"
            if not prepare_rows(config, out / folder, [pair], state, record, clock, structures, label):
                return 1
    cells = [cell for _, cell in structure_cells(out, config, pairs)]
    run_cells(
        config, out, cells, state, record, clock,
        lambda: write_structures_page(results_md, config, state, out, pairs),
    )  # fmt: skip
    return 0

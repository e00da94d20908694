"""docs/crops.md's ``structures-run`` section, written from the ``structures`` run's results files:
for each row, every method's OER_tau on the bare row and with its structures, and what the
structures took from it.

The page's prose is written by hand; everything between its markers comes from here. A page
without the markers (a run's own ``results.md``) is written whole: a title and the section.
"""

from __future__ import annotations

from pathlib import Path

from davis_ag.benchmark.results import EvaluationResults
from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.groups import group_key
from davis_ag.workflows.reproduce.pages.cells import START_OER, row_table, run_head, write_run_section
from davis_ag.workflows.reproduce.state import RunState

#: The markers of docs/crops.md's section.
MARKER = "structures-run"


def _starts(results: EvaluationResults) -> str:
    return f"{results.protocol.starts:,}" if results.protocol.starts is not None else "-"


def structures_section(config: ReproduceConfig, state: RunState, out: Path, pairs) -> str:
    """The section: one table per row, the bare row beside the row with its structures.

    Args:
        config: The run's configuration.
        state: Its records (training times).
        out: The run folder (its ``results/``).
        pairs: The rows, in the run's order.

    Returns:
        Markdown.
    """
    from davis_ag.workflows.reproduce.structure_cells import structure_cells

    cells = structure_cells(out, config, pairs)
    lines = [
        run_head(config, pairs, "of its own variant")
        + " Under the methods: the start's OER_0 and the eligible (view, fruit) starts of the test "
        "split (a fruit a wire, a post or the cover hides below the visibility limit is no start).",
        "",
    ]
    for scenario, crop in pairs:
        key = group_key(scenario, crop)
        columns = [(heading, cell) for heading, cell in cells if cell.key.startswith(f"{key}-")]
        extra = (START_OER, ("eligible test starts", _starts))
        lines += row_table(key, out, config, state, columns, extra)
    return "\n".join(lines).rstrip() + "\n"


def write_structures_page(path: Path, config: ReproduceConfig, state: RunState, out: Path, pairs) -> None:
    """Write the run's section into ``path`` (between its markers), or the whole page when it has none.

    Args:
        path: The page.
        config: The run's configuration.
        state: Its records.
        out: The run folder.
        pairs: The rows.
    """
    text = structures_section(config, state, out, pairs)
    write_run_section(path, MARKER, "Structures on the benchmark: the run", text)

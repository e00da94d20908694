"""The table a run of cells writes for each row (:mod:`davis_ag.workflows.reproduce.cells`): a
column per cell, a line per method with its change from the row's first cell, the lines each run
adds, and what is not in the table yet."""

from __future__ import annotations

from collections.abc import Callable
from pathlib import Path

from davis_ag.atomic_files import write_marked_section, write_text_atomic
from davis_ag.benchmark.results import EvaluationResults, table_number
from davis_ag.workflows.reproduce.cells import Cell, load_cell, unreached_stage
from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.state import RunState

#: The lines of each table: the bound, the yardstick, the learners, then the trivial policies a
#: learner must beat (a collapsed policy scores like one of them).
METHODS = ("Oracle", "Best fixed action", "A2C", "PPO", "Rand", "LRD", "UDD")

#: A line a run adds under the methods: its name and what it shows of a cell's results.
ExtraLine = tuple[str, Callable[[EvaluationResults], str]]


def _start_oer(results: EvaluationResults) -> str:
    return table_number(results.policies["Oracle"].oer_0.mean) if "Oracle" in results.policies else "-"


#: The line every run of cells shows first under the methods: where its episodes start.
START_OER: ExtraLine = ("start OER_0 (Oracle)", _start_oer)


def change(value: float, base: float | None) -> str:
    """A number with, in brackets, its change from ``base`` (``.612 (-.041)``)."""
    from davis_ag.benchmark.results import signed_number

    return table_number(value) if base is None else f"{table_number(value)} ({signed_number(value - base)})"


def _method(results: EvaluationResults | None, name: str, first: EvaluationResults | None) -> str:
    """One method's OER_tau in a cell, with its change from the row's first cell."""
    row = results.policies.get(name) if results else None
    if row is None:
        return "-"
    base = first.policies.get(name) if first and first is not results else None
    return change(row.oer_tau.mean, base.oer_tau.mean if base else None)


def row_table(
    title: str,
    out: Path,
    config: ReproduceConfig,
    state: RunState,
    columns: list[tuple[str, Cell]],
    extra: tuple[ExtraLine, ...] = (),
) -> list[str]:
    """One row's table and its notes.

    Args:
        title: The row's name.
        out: The run folder.
        config: The run (its learners).
        state: Its records (unreached robots, training times).
        columns: Each column's heading and cell, the first the one the others are compared with.
        extra: Lines under the methods.

    Returns:
        Markdown lines.
    """
    found = {label: load_cell(out, cell) for label, cell in columns}
    first = found[columns[0][0]]
    scenes = next((r.protocol.scenes for r in found.values() if r), [])
    lines = [
        f"**{title}** (test: {', '.join(scenes) or 'not yet evaluated'})",
        "",
        "| method | " + " | ".join(label for label, _ in columns) + " |",
        "|---|" + "---|" * len(columns),
    ]
    for name in METHODS:
        if any(r and name in r.policies for r in found.values()):
            lines.append(f"| {name} | " + " | ".join(_method(found[label], name, first) for label, _ in columns) + " |")
    for heading, show in extra:
        lines.append(
            f"| {heading} | " + " | ".join(show(r) if (r := found[label]) else "-" for label, _ in columns) + " |"
        )
    missing, trained = [], []
    for label, cell in columns:
        unreached = state.stages.get(unreached_stage(cell))
        results = found[label]
        if unreached is not None:
            missing.append(f"{label}: {unreached.note}")
        elif results is None:
            missing.append(f"{label}: not yet evaluated")
        elif untrained := [a.upper() for a in config.learners if a.upper() not in results.policies]:
            missing.append(f"{label}: {', '.join(untrained)} not yet trained")
        for algo in config.learners:
            if record := state.stages.get(f"{cell.key}: train {algo.upper()}"):
                trained.append(f"{label} {algo.upper()} {record.seconds / 60:.0f} min")
    lines.append("")
    if trained:
        lines.append(
            f"Training wall time on this machine (longer while other work shared its 2 cores, or the run was "
            f"paused): {'; '.join(trained)}."
        )
    if missing:
        lines.append(f"Not in the table yet: {'; '.join(missing)}.")
    lines.append("")
    return lines


def run_head(config: ReproduceConfig, pairs, under: str) -> str:
    """The line above a run's tables: its data, its learners and its protocol.

    Args:
        config: The run.
        pairs: Its rows.
        under: What each learner trained under (``the column's robot``).

    Returns:
        One paragraph.
    """
    steps = ", ".join(f"{a.upper()} {config.timesteps('row') // 1000}K steps" for a in config.learners)
    scenes = config.scenes(pairs[0][0]) if pairs else 0
    return (
        f"Written by `davis-ag reproduce --config {config.name}`: {scenes} row scene(s) of each crop at "
        f"{config.size[0]}x{config.size[1]}, dataset seed {config.seed}, split rule `{config.split_rule}`; each "
        f"learner trained on the train split {under} ({steps}, {config.n_envs} environments, seed {config.seed}, "
        f"the snapshot best on train kept); {config.sessions} sessions of {config.episodes} episodes on the test "
        "split. Each cell: mean OER_tau, in brackets its change from the same method in the first column."
    )


def write_run_section(path: Path, marker: str, title: str, text: str) -> None:
    """Write a run's section into ``path`` between its markers, or the whole page (``title`` and
    the section) when the page has none (a run's own ``results.md``).

    Args:
        path: The page.
        marker: The section's marker name (``robot-run``).
        title: The page's title where it is written whole.
        text: The section.
    """
    start = f"<!-- {marker}:start -->"
    if path.is_file() and start in path.read_text():
        write_marked_section(path, marker, text)
    else:
        write_text_atomic(path, f"# {title}\n\n{start}\n{text}\n<!-- {marker}:end -->\n")

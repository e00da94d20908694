"""docs/robot.md's run section, written from the ``robot`` run's results files: for each row, every
method's OER_tau without a robot and with each robot, what the robot took from it, and the seconds
an episode cost the robot.

The page's prose is written by hand; everything between its ``robot-run`` markers comes from here.
A page without the markers (a run's own ``results.md``) is written whole: a title and the section.
"""

from __future__ import annotations

from pathlib import Path

from davis_ag.benchmark.results import EvaluationResults
from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.groups import group_key
from davis_ag.workflows.reproduce.pages.cells import START_OER, row_table, run_head, write_run_section
from davis_ag.workflows.reproduce.robot_cells import robot_cell, robot_label
from davis_ag.workflows.reproduce.state import RunState

#: The markers of docs/robot.md's section.
MARKER = "robot-run"


def _seconds(results: EvaluationResults) -> str:
    """The Oracle's mean robot seconds per episode and the OER it gained per robot second."""
    row = results.policies.get("Oracle")
    if row is None or not row.seconds or row.seconds.mean <= 0:
        return "-"
    return f"{row.seconds.mean:.1f} s ({(row.oer_tau.mean - row.oer_0.mean) / row.seconds.mean:.3f}/s)"


def robot_section(config: ReproduceConfig, state: RunState, out: Path, pairs) -> str:
    """The section: one table per row, a column per robot (and none), a line per method.

    Args:
        config: The run's configuration.
        state: Its records (robots that reach no start, training times).
        out: The run folder (its ``results/``).
        pairs: The rows, in the run's order.

    Returns:
        Markdown.
    """
    lines = [
        run_head(config, pairs, "under the column's robot")
        + " The last line: the Oracle's mean robot seconds per episode and, in brackets, the OER it "
        "gained per robot second.",
        "",
    ]
    for scenario, crop in pairs:
        columns = [
            (robot_label(robot) if robot else "no robot", robot_cell(out, scenario, crop, robot))
            for robot in (None, *config.robots)
        ]
        extra = (START_OER, ("robot s / episode (Oracle)", _seconds))
        lines += row_table(group_key(scenario, crop), out, config, state, columns, extra)
    return "\n".join(lines).rstrip() + "\n"


def write_robot_page(path: Path, config: ReproduceConfig, state: RunState, out: Path, pairs) -> None:
    """Write the run's section into ``path`` (between its markers), or the whole page when it has none.

    Args:
        path: The page.
        config: The run's configuration.
        state: Its records.
        out: The run folder.
        pairs: The rows.
    """
    write_run_section(path, MARKER, "A robot in the row: the run", robot_section(config, state, out, pairs))

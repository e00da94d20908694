"""docs/robot.md's run section, written from the ``robot`` run's results files: for each row, every
method's OER_tau without a robot and with each robot, what the robot took from it, and the seconds
an episode cost the robot.

The page's prose is written by hand; everything between its ``robot-run`` markers comes from here.
A page without the markers (a run's own ``results.md``) is written whole: a title and the section.
"""

from __future__ import annotations

from pathlib import Path

from davis_ag.atomic_files import write_marked_section, write_text_atomic
from davis_ag.benchmark.results import EvaluationResults, PolicyResult, signed_number, table_number
from davis_ag.errors import UserError
from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.groups import group_key
from davis_ag.workflows.reproduce.state import RunState

#: The markers of docs/robot.md's section.
MARKER = "robot-run"
#: The rows of each table: the bound, the yardstick, the learners, then the trivial policies a
#: learner must beat (a collapsed policy scores like one of them).
METHODS = ("Oracle", "Best fixed action", "A2C", "PPO", "Rand", "LRD", "UDD")


def _cell(results: EvaluationResults | None, name: str, bare: EvaluationResults | None) -> str:
    """One method's OER_tau in a cell, with its change from the row without a robot."""
    row = results.policies.get(name) if results else None
    if row is None:
        return "-"
    text = table_number(row.oer_tau.mean)
    base = bare.policies.get(name) if bare and bare is not results else None
    return f"{text} ({signed_number(row.oer_tau.mean - base.oer_tau.mean)})" if base else text


def _seconds(row: PolicyResult | None) -> str:
    """Mean robot seconds per episode and the OER gained per robot second."""
    if row is None or not row.seconds or row.seconds.mean <= 0:
        return "-"
    gain = (row.oer_tau.mean - row.oer_0.mean) / row.seconds.mean
    return f"{row.seconds.mean:.1f} s ({gain:.3f}/s)"


def _load(path: Path) -> EvaluationResults | None:
    from davis_ag.benchmark.results import load_results

    try:
        return load_results(path)
    except UserError:
        return None


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
    from davis_ag.workflows.reproduce.robot_cells import cell_key, cell_results_path, robot_label, skipped_stage

    robots: tuple[str | None, ...] = (None, *config.robots)
    steps = ", ".join(f"{a.upper()} {config.timesteps('row') // 1000}K steps" for a in config.learners)
    lines = [
        f"Written by `davis-ag reproduce --config {config.name}`: {config.scenes(pairs[0][0]) if pairs else 0} "
        f"row scene(s) of each crop at {config.size[0]}x{config.size[1]}, dataset seed {config.seed}; "
        f"each learner trained on the train split under the column's robot ({steps}, "
        f"{config.n_envs} environments, seed {config.seed}, the snapshot best on train kept); "
        f"{config.sessions} sessions of {config.episodes} episodes on the test split. Each cell: mean "
        "OER_tau, in brackets its change from the same method without a robot. Last line: the robot's "
        "mean seconds per episode of the Oracle and, in brackets, the OER it gained per robot second.",
        "",
    ]
    for scenario, crop in pairs:
        cells: dict[str | None, EvaluationResults | None] = {
            robot: _load(cell_results_path(out, scenario, crop, robot)) for robot in robots
        }
        bare = cells[None]
        scenes = next((r.protocol.scenes for r in cells.values() if r), [])
        lines += [
            f"**{group_key(scenario, crop)}** (test: {', '.join(scenes) or 'not yet evaluated'})",
            "",
            "| method | " + " | ".join(robot_label(r) if r else "no robot" for r in robots) + " |",
            "|---|" + "---|" * len(robots),
        ]
        for name in METHODS:
            if any(r and name in r.policies for r in cells.values()):
                lines.append(f"| {name} | " + " | ".join(_cell(cells[r], name, bare) for r in robots) + " |")
        lines.append(
            "| start OER_0 (Oracle) | "
            + " | ".join(table_number(c.policies["Oracle"].oer_0.mean) if c else "-" for c in cells.values())
            + " |"
        )
        lines.append(
            "| robot s / episode (Oracle) | "
            + " | ".join(_seconds(c.policies.get("Oracle") if c else None) for c in cells.values())
            + " |"
        )
        missing = []
        for robot in robots:
            skipped = state.stages.get(skipped_stage(scenario, crop, robot)) if robot else None
            if skipped is not None:
                missing.append(f"{robot_label(robot)}: {skipped.note}")
            elif (evaluated := cells[robot]) is None:
                missing.append(f"{robot_label(robot) if robot else 'no robot'}: not yet evaluated")
            else:
                untrained = [a.upper() for a in config.learners if a.upper() not in evaluated.policies]
                if untrained:
                    missing.append(
                        f"{robot_label(robot) if robot else 'no robot'}: {', '.join(untrained)} not yet trained"
                    )
        trained = [
            f"{robot_label(robot) if robot else 'no robot'} {algo.upper()} {record.seconds / 60:.0f} min"
            for robot in robots
            for algo in config.learners
            if (record := state.stages.get(f"{cell_key(scenario, crop, robot)}: train {algo.upper()}"))
        ]
        lines.append("")
        if trained:
            lines.append(f"Training time on this machine: {'; '.join(trained)}.")
        if missing:
            lines.append(f"Not in the table yet: {'; '.join(missing)}.")
        lines.append("")
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
    text = robot_section(config, state, out, pairs)
    start = f"<!-- {MARKER}:start -->"
    if path.is_file() and start in path.read_text():
        write_marked_section(path, MARKER, text)
    else:
        write_text_atomic(path, f"# A robot in the row: the run\n\n{start}\n{text}\n<!-- {MARKER}:end -->\n")

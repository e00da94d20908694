"""The ``robot`` run's cells: a row played without a robot or with one, and the names each cell's
results file, models and records go by (:mod:`davis_ag.workflows.reproduce.robot_run` makes them,
its page and ``--status`` read them)."""

from __future__ import annotations

from pathlib import Path

from davis_ag.workflows.reproduce.groups import group_key

#: The column of the rows played without a robot (the camera floats, as in the paper).
NO_ROBOT = "none"


def robot_label(robot: str | None) -> str:
    """What a robot goes by in file names and the table: its name, a YAML file's stem, or ``none``."""
    if robot is None:
        return NO_ROBOT
    return Path(robot).stem if robot.endswith((".yaml", ".yml")) else robot


def cell_key(scenario: str, crop: str, robot: str | None) -> str:
    """The name of one row and robot: its results file and models (``row-apple-wall-ur10-lift``)."""
    return f"{group_key(scenario, crop)}-{robot_label(robot)}"


def cell_results_path(out: Path, scenario: str, crop: str, robot: str | None) -> Path:
    """Where a run keeps one cell's evaluation."""
    return out / "results" / f"{cell_key(scenario, crop, robot)}.json"


def skipped_stage(scenario: str, crop: str, robot: str) -> str:
    """The state record of a robot that reaches none of a row's test starts."""
    return f"{cell_key(scenario, crop, robot)}: unreached"

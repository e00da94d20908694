"""The ``robot`` run's cells: a row played without a robot or with each robot, and the names each
cell's results file, models and records go by (:mod:`davis_ag.workflows.reproduce.robot_run`
makes them, its page and ``--status`` read them)."""

from __future__ import annotations

from pathlib import Path

from davis_ag.workflows.reproduce.cells import Cell
from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.groups import group_key

#: The column of the rows played without a robot (the camera floats, as in the paper).
NO_ROBOT = "none"


def robot_label(robot: str | None) -> str:
    """What a robot goes by in file names and the table: its name, a YAML file's stem, or ``none``."""
    if robot is None:
        return NO_ROBOT
    return Path(robot).stem if robot.endswith((".yaml", ".yml")) else robot


def robot_cell(out: Path, scenario: str, crop: str, robot: str | None) -> Cell:
    """One row with one robot (or none), on the run's dataset (``row-apple-wall-ur10-lift``)."""
    return Cell(f"{group_key(scenario, crop)}-{robot_label(robot)}", out / "dataset", scenario, crop, robot)


def robot_cells(out: Path, config: ReproduceConfig, pairs) -> list[Cell]:
    """The run's cells in its order: every row without a robot, then every row with each robot."""
    return [robot_cell(out, scenario, crop, robot) for robot in (None, *config.robots) for scenario, crop in pairs]

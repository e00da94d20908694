"""Runs of *cells*: one row scored several ways (without a robot and with each robot; bare and
with its structures), each way a cell with its own dataset, robot, results file and models.

The ``robot`` run (:mod:`~davis_ag.workflows.reproduce.robot_run`) and the ``structures`` run
(:mod:`~davis_ag.workflows.reproduce.structures_run`) share these stages, each resumable and the
cheapest first, so a run cut short still leaves a whole table of what needs no training:

1. each dataset's rows (finished scenes skipped) and their validation (:func:`prepare_rows`);
2. every cell's baselines (LRD, UDD, Rand, Oracle, Best fixed); a robot that reaches no start of
   the test split is recorded as such, with the heights it reaches;
3. cell by cell, A2C and PPO trained on the train split under the cell's robot with the same
   steps and seed, then the cell evaluated again with them (:func:`run_cells`).

A cell's results file is reused when it holds the same protocol, scenes, robot, split rule and
learners and is newer than its models.
"""

from __future__ import annotations

import json
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING

from davis_ag.benchmark.results import EvaluationResults
from davis_ag.errors import UserError
from davis_ag.workflows.reproduce.configs import ReproduceConfig, check_disk
from davis_ag.workflows.reproduce.groups import group_key
from davis_ag.workflows.reproduce.state import RunState

if TYPE_CHECKING:
    from davis_ag.workflows.reproduce.clock import StageClock
    from davis_ag.workflows.reproduce.run import Record


@dataclass(frozen=True)
class Cell:
    """One way a row is scored.

    Attributes:
        key: Its name: results file, models and stage records (``row-apple-wall-ur10-lift``).
        root: The dataset it plays.
        scenario: ``row`` (or any scenario).
        crop: The row's crop.
        robot: The robot the camera rides on, None for none.
    """

    key: str
    root: Path
    scenario: str
    crop: str
    robot: str | None = None


def results_path(out: Path, cell: Cell) -> Path:
    """Where a run keeps one cell's evaluation."""
    return out / "results" / f"{cell.key}.json"


def unreached_stage(cell: Cell) -> str:
    """The state record of a cell whose robot reaches none of the row's test starts."""
    return f"{cell.key}: unreached"


def load_cell(out: Path, cell: Cell) -> EvaluationResults | None:
    """A cell's evaluation, or None where there is none yet (or it does not read)."""
    from davis_ag.benchmark.results import load_results

    try:
        return load_results(results_path(out, cell))
    except UserError:
        return None


def open_run(
    config: ReproduceConfig, out: Path, results_md: Path, pairs, datasets: int = 1
) -> tuple[Path, Path, RunState, Record, StageClock]:
    """Check the disk and the paths, load the run's state and record its configuration.

    Args:
        config: The run.
        out: Its folder.
        results_md: Its page.
        pairs: Its rows.
        datasets: How many datasets of those rows it makes (the disk it needs).

    Returns:
        The run folder and page (absolute), its state, its stage recorder and its clock.
    """
    from davis_ag.atomic_files import prove_writable_file, prove_writable_folder
    from davis_ag.provenance import code_version, machine_summary
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE, StageClock
    from davis_ag.workflows.reproduce.run import stage_recorder

    check_disk(config, Path(out).expanduser().absolute(), list(pairs) * datasets)
    out = prove_writable_folder(out)  # absolute at once: Helios moves the working directory
    results_md = prove_writable_file(results_md, "--results")
    state_path = out / "state.json"
    state = RunState.load(state_path)
    state.config = json.loads(json.dumps(asdict(config)))
    state.save(state_path)
    clock = StageClock(out / CLOCK_FILE, code_version(), machine=machine_summary())
    return out, results_md, state, stage_recorder(state, state_path), clock


def prepare_rows(
    config: ReproduceConfig,
    root: Path,
    pairs,
    state: RunState,
    record: Record,
    clock: StageClock,
    structures: str,
    label: str = "",
) -> bool:
    """Generate and validate the run's rows in ``root``.

    Args:
        config: The run (size, scenes, seed).
        root: The dataset.
        pairs: The ``(scenario, crop)`` rows.
        state: The run's records.
        record: Its stage recorder.
        clock: Its clock.
        structures: The rows' structures (``none`` or ``default``).
        label: Added to each stage's name (`` with structures``), where a run has two datasets.

    Returns:
        Whether every row's data is sound.
    """
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.scene.camera import Camera
    from davis_ag.workflows.reproduce.run import validate_once
    from davis_ag.workflows.stages import generate_scenes

    camera = Camera(*config.size)
    for scenario_name, crop_name in pairs:
        scenario, crop = config.specs(scenario_name, crop_name)
        key = group_key(scenario_name, crop_name) + label
        requests = [
            SceneRequest(scenario, crop, i, config.seed, camera, structures=structures)
            for i in range(config.scenes(scenario_name))
        ]
        state.scene_folders[key] = [r.folder for r in requests]
        print(f"== {key}: {len(requests)} scene(s) at {config.size[0]}x{config.size[1]}", flush=True)
        began = time.perf_counter()
        if not all(g["skipped"] for g in generate_scenes(requests, root)):
            record(f"{key}: generate", time.perf_counter() - began)
        if not validate_once(root / requests[0].folder.split("/")[0], state, f"{key}: validate", clock, record):
            return False
    return True


def _robot_digest(robot: str | None) -> str | None:
    """The definition digest a results file records for ``robot`` (None without one)."""
    if robot is None:
        return None
    from davis_ag.robot.definitions import load_robot

    return load_robot(robot).digest


def _reusable(
    path: Path, config: ReproduceConfig, split: str, scenes: list[str], robot: str | None, models: list[Path]
) -> EvaluationResults | None:
    """An earlier evaluation of a cell with the same protocol, scenes, robot and learners, newer
    than each model; else None (evaluated anew: the episodes are seeded, so the rows it had come
    out as they were)."""
    from davis_ag.benchmark.exact import BEST_FIXED
    from davis_ag.benchmark.results import load_results

    try:
        results = load_results(path)
    except UserError:
        return None
    p = results.protocol
    recorded = (p.robot or {}).get("digest") if p.robot else None
    learners = {m.name.split("_", 1)[0].upper() for m in models}
    try:
        fresh = all(path.stat().st_mtime >= m.stat().st_mtime for m in models)
    except OSError:
        return None
    same = (
        (p.split, sorted(p.scenes), p.episodes, p.sessions, p.seed) == (split, sorted(scenes), config.episodes, config.sessions, config.seed)
        and recorded == _robot_digest(robot)
        and (p.split_rule or "scenes") == config.split_rule
        and BEST_FIXED in results.policies
        and learners == {name for name in results.policies if name in {"A2C", "PPO"}}
    )  # fmt: skip
    return results if fresh and same else None


def evaluate_cell(
    config: ReproduceConfig, out: Path, cell: Cell, state: RunState, record: Record
) -> EvaluationResults | None:
    """Evaluate one cell (baselines and each finished learner) unless its file is reusable.

    Args:
        config: The run (protocol, learners, split rule).
        out: The run folder (``results/``, ``models/``).
        cell: The cell.
        state: The run's records.
        record: Its stage recorder.

    Returns:
        The cell's results, or None when its robot reaches no start of the split (recorded in
        ``state`` so the page says so).
    """
    from davis_ag.atomic_files import write_or_rescue
    from davis_ag.benchmark.evaluation import write_json
    from davis_ag.benchmark.results_table import format_table
    from davis_ag.workflows.reproduce.learners import model_path
    from davis_ag.workflows.reproduce.run import split_scene_ids
    from davis_ag.workflows.stages import evaluation_split, run_baselines

    split = evaluation_split(cell.root, cell.scenario, cell.crop, config.split_rule)
    scenes = split_scene_ids(cell.root, cell.scenario, split, cell.crop, config.split_rule)
    models = {algo: model_path(out, cell.key, algo) for algo in config.learners}
    finished = {algo: path for algo, path in models.items() if path.is_file()}
    path = results_path(out, cell)
    results = _reusable(path, config, split, scenes, cell.robot, list(finished.values()))
    if results is not None:
        return results
    began = time.perf_counter()
    try:
        results = run_baselines(
            cell.root, cell.scenario, cell.crop, split, config.episodes, config.sessions, config.seed,
            model=finished.get("a2c"), learners=tuple(p for a, p in finished.items() if a != "a2c"),
            robot=cell.robot, split_rule=config.split_rule,
        )  # fmt: skip
    except UserError as error:
        if cell.robot is None or "reaches" not in str(error):
            raise
        print(f"{cell.key}: {error}", flush=True)
        record(unreached_stage(cell), 0.0, str(error))
        return None
    path.parent.mkdir(parents=True, exist_ok=True)
    write_or_rescue(path, partial(write_json, results), "the results")
    learners = ", ".join(a.upper() for a in finished) or "no learner yet"
    record(f"{cell.key}: evaluate", time.perf_counter() - began, f"split {split}, {learners}")
    print(format_table(results), flush=True)
    return results


def run_cells(
    config: ReproduceConfig,
    out: Path,
    cells: list[Cell],
    state: RunState,
    record: Record,
    clock: StageClock,
    write_page: Callable[[], None],
) -> None:
    """Every cell's baselines, then cell by cell its learners and its evaluation with them;
    ``write_page`` after each.

    Args:
        config: The run (learners, steps, seed).
        out: The run folder.
        cells: The cells, in the order to take them.
        state: The run's records.
        record: Its stage recorder.
        clock: Its clock.
        write_page: Rewrites the run's page from its files.
    """
    from davis_ag.workflows.reproduce.learners import model_path, train_learner

    reached = []
    for cell in cells:
        print(f"== {cell.key}: baselines", flush=True)
        if evaluate_cell(config, out, cell, state, record) is not None:
            reached.append(cell)
        write_page()
    for cell in reached:
        timesteps = config.timesteps(cell.scenario)
        for algo in config.learners:
            stage = f"{cell.key}: train {algo.upper()}"
            with clock.timing(stage) as sitting:
                trained = train_learner(
                    algo, cell.root, cell.scenario, cell.crop, model_path(out, cell.key, algo), timesteps, config,
                    robot=cell.robot,
                )  # fmt: skip
                if trained is None:
                    sitting.discard()
            if trained is not None:
                record(stage, clock.seconds(stage), f"{timesteps} steps under {cell.robot or 'no robot'}")
        evaluate_cell(config, out, cell, state, record)
        write_page()
        print(f"wrote the page after {cell.key}", flush=True)

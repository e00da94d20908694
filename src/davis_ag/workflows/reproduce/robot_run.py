"""``davis-ag reproduce --config robot``: the rows of a trellised wall, a vineyard and a greenhouse
crop played without a robot and with each robot that reaches them, every baseline, the exact
Oracle, the Best fixed action and the learners trained under each, written to docs/robot.md.

Each row and robot is a *cell*. The stages, each resumable, run cheapest first so a run cut short
still leaves a whole table of what needs no training:

1. each row's scenes (finished ones skipped) and their validation;
2. every cell's baselines (LRD, UDD, Rand, Oracle, Best fixed), no robot first: a robot that
   reaches no start of the test split is recorded as such, with the heights it reaches;
3. cell by cell (no robot first), A2C and PPO trained on the train split under the cell's robot
   (its reach and seconds) with the same steps and seed, then the cell evaluated again with them.

A cell's results file is reused when it holds the same protocol, scenes, robot and learners and
is newer than its models; the page is rewritten after every cell.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict
from functools import partial
from pathlib import Path

from davis_ag.benchmark.results import EvaluationResults
from davis_ag.errors import UserError
from davis_ag.workflows.reproduce.configs import ReproduceConfig, check_disk
from davis_ag.workflows.reproduce.groups import group_key
from davis_ag.workflows.reproduce.robot_cells import cell_key, cell_results_path, skipped_stage
from davis_ag.workflows.reproduce.state import RunState


def _robot_digest(robot: str | None) -> str | None:
    """The definition digest a results file records for ``robot`` (None without one)."""
    if robot is None:
        return None
    from davis_ag.robot.definitions import load_robot

    return load_robot(robot).digest


def _reusable(
    path: Path, config: ReproduceConfig, split: str, scenes: list[str], robot: str | None, models: list[Path]
) -> EvaluationResults | None:
    """An earlier evaluation of this cell with the same protocol, scenes, robot and learners,
    newer than each model; else None (evaluated anew: the episodes are seeded, so the rows it had
    come out as they were)."""
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
    config: ReproduceConfig,
    out: Path,
    scenario: str,
    crop: str,
    robot: str | None,
    state: RunState,
    record,
) -> EvaluationResults | None:
    """Evaluate one cell (baselines and each finished learner) unless its file is reusable.

    Returns:
        The cell's results, or None when the robot reaches no start of the split (recorded in
        ``state`` so the page says so).
    """
    from davis_ag.atomic_files import write_or_rescue
    from davis_ag.benchmark.evaluation import write_json
    from davis_ag.benchmark.results_table import format_table
    from davis_ag.workflows.reproduce.learners import model_path
    from davis_ag.workflows.reproduce.run import split_scene_ids
    from davis_ag.workflows.stages import evaluation_split, run_baselines

    root = out / "dataset"
    key = cell_key(scenario, crop, robot)
    split = evaluation_split(root, scenario, crop, config.split_rule)
    scenes = split_scene_ids(root, scenario, split, crop, config.split_rule)
    models = {algo: model_path(out, key, algo) for algo in config.learners}
    finished = {algo: path for algo, path in models.items() if path.is_file()}
    path = cell_results_path(out, scenario, crop, robot)
    results = _reusable(path, config, split, scenes, robot, list(finished.values()))
    if results is not None:
        return results
    began = time.perf_counter()
    try:
        results = run_baselines(
            root, scenario, crop, split, config.episodes, config.sessions, config.seed,
            model=finished.get("a2c"), learners=tuple(p for a, p in finished.items() if a != "a2c"), robot=robot,
            split_rule=config.split_rule,
        )  # fmt: skip
    except UserError as error:
        if robot is None or "reaches" not in str(error):
            raise
        print(f"{key}: {error}", flush=True)
        record(skipped_stage(scenario, crop, robot), 0.0, str(error))
        return None
    path.parent.mkdir(parents=True, exist_ok=True)
    write_or_rescue(path, partial(write_json, results), "the results")
    learners = ", ".join(a.upper() for a in finished) or "no learner yet"
    record(f"{key}: evaluate", time.perf_counter() - began, f"split {split}, {learners}")
    print(format_table(results), flush=True)
    return results


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
    from davis_ag.atomic_files import prove_writable_file, prove_writable_folder
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.provenance import code_version, machine_summary
    from davis_ag.scene.camera import Camera
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE, StageClock
    from davis_ag.workflows.reproduce.learners import model_path, train_learner
    from davis_ag.workflows.reproduce.pages.robot import write_robot_page
    from davis_ag.workflows.reproduce.run import stage_recorder, validate_once
    from davis_ag.workflows.stages import generate_scenes

    check_disk(config, Path(out).expanduser().absolute(), pairs)
    out = prove_writable_folder(out)  # absolute at once: Helios moves the working directory
    results_md = prove_writable_file(results_md, "--results")
    root = out / "dataset"
    state_path = out / "state.json"
    state = RunState.load(state_path)
    state.config = json.loads(json.dumps(asdict(config)))
    state.save(state_path)
    clock = StageClock(out / CLOCK_FILE, code_version(), machine=machine_summary())
    record = stage_recorder(state, state_path)
    camera = Camera(*config.size)
    for scenario_name, crop_name in pairs:
        scenario, crop = config.specs(scenario_name, crop_name)
        key = group_key(scenario_name, crop_name)
        requests = [
            SceneRequest(scenario, crop, i, config.seed, camera, structures=config.structures)
            for i in range(config.scenes(scenario_name))
        ]
        state.scene_folders[key] = [r.folder for r in requests]
        print(f"== {key}: {len(requests)} scene(s) at {config.size[0]}x{config.size[1]}", flush=True)
        began = time.perf_counter()
        if not all(g["skipped"] for g in generate_scenes(requests, root)):
            record(f"{key}: generate", time.perf_counter() - began)
        if not validate_once(root / requests[0].folder.split("/")[0], state, f"{key}: validate", clock, record):
            return 1
    robots: tuple[str | None, ...] = (None, *config.robots)
    cells = [(pair, robot) for robot in robots for pair in pairs]
    reached = []
    for (scenario_name, crop_name), robot in cells:
        print(f"== {cell_key(scenario_name, crop_name, robot)}: baselines", flush=True)
        if evaluate_cell(config, out, scenario_name, crop_name, robot, state, record) is not None:
            reached.append(((scenario_name, crop_name), robot))
        write_robot_page(results_md, config, state, out, pairs)
    for (scenario_name, crop_name), robot in reached:
        key = cell_key(scenario_name, crop_name, robot)
        timesteps = config.timesteps(scenario_name)
        for algo in config.learners:
            stage = f"{key}: train {algo.upper()}"
            with clock.timing(stage) as sitting:
                trained = train_learner(
                    algo, root, scenario_name, crop_name, model_path(out, key, algo), timesteps, config, robot=robot
                )
                if trained is None:
                    sitting.discard()
            if trained is not None:
                record(stage, clock.seconds(stage), f"{timesteps} steps under {robot or 'no robot'}")
        evaluate_cell(config, out, scenario_name, crop_name, robot, state, record)
        write_robot_page(results_md, config, state, out, pairs)
        print(f"wrote {results_md}", flush=True)
    return 0

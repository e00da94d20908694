"""The ``davis-ag reproduce`` workflow: the paper's Table 4 (section VI), or the ``crops`` ladder,
end to end at a size that fits.

Stages, for each group of the configuration in turn (Table 4: SP strawberry, then MP vine; the
crops run: every plant-library crop's ``sp`` and ``row``), each resumable (finished scenes are
skipped, a trained model's zip and an evaluation's JSON are reused, a killed training resumes from
its checkpoint): the data, its validation and split, A2C and PPO beside it with the same budget,
the benchmark. ``--results`` (docs/results.md or docs/crops.md) is rewritten after every
benchmark, so a run cut short still leaves what it measured.
"""

from __future__ import annotations

import json
import os
import time
from dataclasses import asdict
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Protocol

from davis_ag.benchmark.results import EvaluationResults, MeanScore, TrainScore, TrainSplit
from davis_ag.workflows.reproduce.configs import ReproduceConfig, check_disk
from davis_ag.workflows.reproduce.groups import group_key
from davis_ag.workflows.reproduce.state import RunState, StageRecord, without_episodes

if TYPE_CHECKING:
    from davis_ag.workflows.reproduce.clock import StageClock


class Record(Protocol):
    """Writes a stage's record into the run's state (:class:`StageRecord`'s fields) and saves it."""

    def __call__(
        self,
        stage: str,
        seconds: float,
        note: str = "",
        code: str | None = None,
        check_seconds: float | None = None,
        stamp: str | None = None,
    ) -> None:
        """Record ``stage``; ``code`` None: the code running now."""


def reproduce(
    config: ReproduceConfig,
    out: Path,
    results_md: Path,
    pairs: list[tuple[str, str]] | tuple[tuple[str, str], ...] | None = None,
) -> int:
    """Generate, validate, split, train and benchmark each scenario; write ``results_md``.

    Args:
        config: The size of the run.
        out: Work folder (``dataset``, ``models``, ``results``, ``state.json``).
        results_md: The Markdown file to (re)write.
        pairs: ``(scenario, crop)`` pairs to run (default: the configuration's).

    Returns:
        0 on success, 1 when a dataset failed validation.
    """
    from davis_ag.atomic_files import prove_writable_file, prove_writable_folder, write_or_rescue
    from davis_ag.benchmark.evaluation import write_json
    from davis_ag.benchmark.results_table import format_table
    from davis_ag.figures.result_charts import plot_results
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.provenance import code_version, machine_summary
    from davis_ag.scene.camera import Camera
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE, StageClock, generation_seconds
    from davis_ag.workflows.reproduce.learners import model_path, train_learner
    from davis_ag.workflows.stages import evaluation_split, generate_scenes, run_baselines

    pairs = config.pairs if pairs is None else pairs
    check_disk(config, Path(out).expanduser().absolute(), pairs)
    out = prove_writable_folder(out)  # absolute at once: Helios moves the working directory
    results_md = prove_writable_file(results_md, "--results")
    root = out / "dataset"
    state_path = out / "state.json"
    state = RunState.load(state_path)
    configured = json.loads(json.dumps(asdict(config)))
    # A state from before the split rules ran under scenes, as the field's default says.
    if state.config and {"split_rule": "scenes", **state.config} != configured:
        print(
            f"note: {out} was started with another configuration; finished stages are reused "
            "only where their files match",
            flush=True,
        )
    state.config = configured
    state.save(state_path)  # `--status` reads the run from its first stage on, not after it
    clock = StageClock(out / CLOCK_FILE, code_version(), machine=machine_summary())
    record = stage_recorder(state, state_path)

    camera = Camera(*config.size)
    for scenario_name, crop_name in pairs:
        scenario, crop = config.specs(scenario_name, crop_name)
        n = config.scenes(scenario_name)
        key = group_key(scenario_name, crop_name)
        requests = [
            SceneRequest(scenario, crop, i, config.seed, camera, structures=config.structures) for i in range(n)
        ]
        state.scene_folders[key] = [r.folder for r in requests]
        print(f"== {key}: {n} scene(s) at {config.size[0]}x{config.size[1]}", flush=True)
        with clock.timing(f"{key}: generate") as sitting:
            generated = generate_scenes(requests, root)  # also writes splits.json
            if all(g["skipped"] for g in generated):
                sitting.discard()
        record(f"{key}: generate", *generation_seconds(root, [r.folder for r in requests], clock, f"{key}: generate"))
        group = root / requests[0].folder.split("/")[0]
        if not validate_once(group, state, f"{key}: validate", clock, record):
            return 1
        split = evaluation_split(root, scenario_name, crop_name, config.split_rule)
        timesteps = config.timesteps(scenario_name)
        models = {}
        for algo in config.learners:
            models[algo] = model_path(out, key, algo)
            stage = f"{key}: train {algo.upper()}"
            with clock.timing(stage) as sitting:
                if train_learner(algo, root, scenario_name, crop_name, models[algo], timesteps, config) is None:
                    sitting.discard()
            if clock.seconds(stage):
                record(
                    stage, clock.seconds(stage), f"{timesteps} steps, {clock.sittings(stage)} sitting(s) on the clock"
                )
        print(f"benchmark on split {split!r}: {config.sessions} x {config.episodes} episodes", flush=True)
        results_json = out / "results" / f"{key}.json"
        results = _reusable_results(
            results_json,
            list(models.values()),
            split,
            split_scene_ids(root, scenario_name, split, crop_name, config.split_rule),
            config,
        )
        if results is None:
            with clock.timing(f"{key}: evaluate"):
                results = run_baselines(
                    root,
                    scenario_name,
                    crop_name,
                    split,
                    config.episodes,
                    config.sessions,
                    config.seed,
                    model=models.get("a2c"),
                    learners=tuple(path for algo, path in models.items() if algo != "a2c"),
                    split_rule=config.split_rule,
                )
                write_or_rescue(results_json, partial(write_json, results), "the results")
                plot_results(results, results_json.with_suffix(".png"))
            record(f"{key}: evaluate", clock.seconds(f"{key}: evaluate"), f"split {split}")
        else:
            print(f"reusing {results_json}", flush=True)
        added = add_train_split(results, root, scenario_name, crop_name, config.split_rule)
        if add_train_scores(results, root, scenario_name, crop_name, models, config) or added:
            write_or_rescue(results_json, partial(write_json, results), "the results")
        print(format_table(results), flush=True)
        state.results[config.result_key(scenario_name, crop_name)] = without_episodes(results)
        evaluated = state.stages[f"{key}: evaluate"]
        # A reused evaluation keeps the code that ran it.
        record(f"{key}: evaluate", evaluated.seconds, evaluated.note, evaluated.code)
        write_page(results_md, config, state, out)
        print(f"wrote {results_md}", flush=True)
    return 0


def stage_recorder(state: RunState, state_path: Path) -> Record:
    """The run's :class:`Record`: a stage's record written into ``state`` and saved at once."""
    from davis_ag.provenance import code_version

    def record(
        stage: str,
        seconds: float,
        note: str = "",
        code: str | None = None,
        check_seconds: float | None = None,
        stamp: str | None = None,
    ) -> None:
        state.stages[stage] = StageRecord(
            seconds=round(seconds, 1),
            note=note,
            code=code or code_version(),
            check_seconds=check_seconds,
            stamp=stamp,
        )
        state.save(state_path)

    return record


def write_page(path: Path, config: ReproduceConfig, state: RunState, out: Path | None) -> None:
    """Write the run's page from its records: Table 4's results page, or the crops run's.

    Args:
        path: The page.
        config: The run's configuration (its ``page`` says which).
        state: The run's records.
        out: The run's folder, for the records beside its state (None: not read).
    """
    if config.page == "crops":
        from davis_ag.workflows.reproduce.pages.crops import write_crops_md

        write_crops_md(path, config, state, out)
    else:
        from davis_ag.workflows.reproduce.pages.results import write_results_md

        write_results_md(path, config, state, out)


def validate_once(group: Path, state: RunState, stage: str, clock: StageClock, record: Record) -> bool:
    """Validate ``group`` on the run's ``clock`` unless the last sitting validated the same files
    with the same code (:func:`davis_ag.data.validation_stamp.validation_stamp`): a sound report
    is reused, so a resumed paper-scale run does not re-read 9 GB of views at every sitting.

    Args:
        group: The group's scenes (``DATA/Single-Strawberry``).
        state: The run's records (the stage's stamp of its last sound validation).
        stage: The stage's name (``sp-strawberry: validate``).
        clock: The run's clock.
        record: Writes the stage's record (:func:`reproduce`'s).

    Returns:
        Whether the data is sound (the problems are printed where it is not).
    """
    from davis_ag.data.validate import validate_dataset
    from davis_ag.data.validation_stamp import validation_stamp

    stamp = validation_stamp(group)
    earlier = state.stages.get(stage)
    if earlier is not None and earlier.stamp == stamp:
        print(f"{earlier.note} (validated before; its files and the validator are unchanged)", flush=True)
        return True
    with clock.timing(stage):
        began = time.perf_counter()
        report = validate_dataset(group, workers=os.cpu_count() or 1)
        # A check is done whole at each sitting whose code changed: its own time is the stage's
        # cost, where the clock adds up every such sitting. Timed inside the sitting, so it never
        # counts the clock's own file writes (slow on a busy disk).
        check = round(time.perf_counter() - began, 1)
    print(report.summary(), flush=True)
    record(stage, clock.seconds(stage), report.summary(), check_seconds=check, stamp=stamp if report.ok else None)
    for problem in report.problems[:20]:
        print(problem, flush=True)
    return report.ok


def split_scene_ids(root: Path, scenario: str, split: str, crop: str, rule: str = "scenes") -> list[str]:
    """The ids of a split's scenes of one group under a split rule, as the environment takes them."""
    from davis_ag.benchmark.splits import as_dataset, select_scenes

    return [s.id for s in select_scenes(as_dataset(root), scenario, split, crop, rule)]


def _reusable_results(
    path: Path, models: list[Path], split: str, scenes: list[str], config: ReproduceConfig
) -> EvaluationResults | None:
    """An earlier evaluation of the same models, protocol and split scenes (``scenes``: a group
    that grew moves scenes between the splits), or ``None`` to evaluate anew.

    One made before a learner of the run (PPO) existed is run anew with every row: the episodes
    are seeded, so the rows it had come out as they were, and the page is never half one
    evaluation, half another.

    Raises:
        UserError: for a file whose summaries its episodes do not give
            (:func:`davis_ag.benchmark.summaries.check_summaries`): the page is never written
            from an edited summary, and the file is left for its owner to look at.
    """
    from davis_ag.benchmark.exact import BEST_FIXED
    from davis_ag.benchmark.results import load_results
    from davis_ag.benchmark.summaries import check_summaries
    from davis_ag.errors import UserError

    try:
        results = load_results(path, check=False)
    except UserError:  # missing, not JSON or not results of this schema: evaluated anew
        return None
    try:
        check_summaries(results, str(path))
    except UserError as error:
        raise UserError(f"{error}; or move it aside to evaluate the run anew") from None
    protocol = results.protocol
    try:
        fresh = all(path.stat().st_mtime >= model.stat().st_mtime for model in models)
    except OSError:
        return None
    same = (
        protocol.split == split
        and sorted(protocol.scenes) == sorted(scenes)
        and protocol.episodes == config.episodes
        and protocol.sessions == config.sessions
        and protocol.seed == config.seed
        and (protocol.split_rule or "scenes") == config.split_rule
    )
    # Evaluations from before the Best fixed action row and the uniform start rule are run anew.
    current = protocol.start_rule == "pairs" and BEST_FIXED in results.policies
    every = all(_row_name(model) in results.policies for model in models)
    return results if fresh and same and current and every else None


def _row_name(model: Path) -> str:
    """The evaluation row of a run's model (``models/ppo_sp-strawberry.zip``: ``PPO``)."""
    return model.name.split("_", 1)[0].upper()


def add_train_split(results: EvaluationResults, root: Path, scenario: str, crop: str, rule: str = "scenes") -> bool:
    """Add the yardstick of the split A2C's snapshot was chosen on: every fixed action's exact
    expectations on train (``results.train_split``); an evaluation that has it is left alone.

    Args:
        results: The evaluation (changed in place).
        root: The dataset root.
        scenario: ``sp``, ``mp`` or ``row``.
        crop: The group's crop.
        rule: The run's split rule.

    Returns:
        Whether it was added (the results file needs writing).
    """
    from davis_ag.benchmark.exact import split_fixed_actions

    if results.train_split is not None:
        return False
    results.train_split = TrainSplit.model_validate(split_fixed_actions(root, scenario, "train", crop, rule))
    return True


def add_train_scores(
    results: EvaluationResults, root: Path, scenario: str, crop: str, models: dict[str, Path], config: ReproduceConfig
) -> bool:
    """Score each learner's kept model on the train split with the test's protocol, on episodes of
    its own (``results.train_split.learners``); learners scored already are left alone.

    A snapshot is kept for the best of its train-split scores, so that score is the largest of
    many noisy ones and runs high (the winner's curse); fresh episodes give the train score to set
    beside the test's.

    Args:
        results: The evaluation (changed in place).
        root: The dataset root.
        scenario: ``sp``, ``mp`` or ``row``.
        crop: The group's crop.
        models: Each learner's model (``a2c``: its zip).
        config: The run's configuration (sessions, episodes, seed).

    Returns:
        Whether a score was added (the results file needs writing).
    """
    from davis_ag.benchmark.evaluation import evaluate
    from davis_ag.benchmark.policies import ModelPolicy

    train = results.train_split
    if train is None:
        return False
    if train.learners is None:
        train.learners = {}
    scored = train.learners
    todo = [path for algo, path in models.items() if algo.upper() not in scored and Path(path).is_file()]
    if not todo:
        return False
    fresh = evaluate(
        [ModelPolicy(path) for path in todo],
        root,
        scenario=scenario,
        split="train",
        sessions=config.sessions,
        episodes=config.episodes,
        seed=config.seed,
        crop=crop,
        baselines=False,
        keep_episodes=False,
        split_rule=config.split_rule,
    )
    for name, row in fresh.policies.items():
        scored[name] = TrainScore(
            oer_tau=MeanScore(mean=row.oer_tau.mean, std=row.oer_tau.std, sem=row.oer_tau.sem),
            sessions=config.sessions,
            episodes=config.episodes,
        )
    return True

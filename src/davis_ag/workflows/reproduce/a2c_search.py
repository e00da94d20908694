"""``davis-ag reproduce --config a2c-search``: A2C settings searched on the train split only.

The paper-scale run's A2C learns less than PPO on the same train split (docs/results.md), so this
run asks which A2C settings reach what PPO reaches there. On one group (SP strawberry, the
configuration's own dataset under ``OUT/dataset``), each stage resumable:

1. the group's scenes (finished ones skipped) and their validation;
2. Rand and the Best fixed action on the train split, so the page has its yardsticks at once;
3. each of its candidates in turn
   (:func:`~davis_ag.workflows.reproduce.a2c_candidates.candidates_of`: the 10-scene search's at
   the paper's budget; the paper-scale search's longer budget first) trained on the train split
   (:func:`~davis_ag.workflows.reproduce.learners.train_learner`: reused when finished with the
   same settings, resumed from its checkpoint when killed), then every finished
   candidate scored with Rand and the Best fixed action on fresh train-split episodes (the test's
   protocol, another draw than the snapshot scores that kept the model), and the page rewritten.

Nothing here reads the test split: every evaluation is of ``split="train"``, and the choice is the
candidate A2C with the highest train-split OER_tau.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

from davis_ag.errors import UserError
from davis_ag.workflows.reproduce.a2c_candidates import (
    EVALUATE,
    MARKER,
    SPLIT,
    Candidate,
    candidate_model,
    candidates_of,
    group_of,
    results_path,
)
from davis_ag.workflows.reproduce.configs import ReproduceConfig, check_disk
from davis_ag.workflows.reproduce.state import RunState

if TYPE_CHECKING:
    from davis_ag.benchmark.results import EvaluationResults


def _reusable(
    path: Path, config: ReproduceConfig, scenes: list[str], rows: dict[str, Path]
) -> EvaluationResults | None:
    """The evaluation in ``path`` when it is of the train split's scenes and the run's protocol, has
    exactly the finished candidates' ``rows`` and is newer than each of their models; else None."""
    from davis_ag.benchmark.exact import BEST_FIXED
    from davis_ag.benchmark.results import load_results

    try:
        results = load_results(path)
        fresh = all(path.stat().st_mtime >= model.stat().st_mtime for model in rows.values())
    except (UserError, OSError):
        return None
    p = results.protocol
    same = (
        (p.split, sorted(p.scenes), p.episodes, p.sessions, p.seed) == (SPLIT, sorted(scenes), config.episodes, config.sessions, config.seed)
        and (p.split_rule or "scenes") == config.split_rule
        and set(results.policies) == {*rows, "Rand", BEST_FIXED}
    )  # fmt: skip
    return results if fresh and same else None


def evaluate_on_train(
    config: ReproduceConfig, out: Path, candidates: tuple[Candidate, ...], record: Any
) -> EvaluationResults:
    """Every finished candidate, Rand and the Best fixed action on fresh train-split episodes,
    unless the file of an earlier sitting holds the same (:func:`_reusable`).

    Args:
        config: The run (protocol, seed, split rule).
        out: The run folder.
        candidates: The search's candidates; those with a model are scored.
        record: The run's stage recorder.

    Returns:
        The evaluation (``protocol.split == "train"``), episodes kept for the paired gaps.
    """
    from davis_ag.atomic_files import write_or_rescue
    from davis_ag.benchmark.evaluation import evaluate, write_json
    from davis_ag.benchmark.policies import ModelPolicy
    from davis_ag.workflows.reproduce.run import split_scene_ids

    scenario, crop, key = group_of(config)
    root = out / "dataset"
    scenes = split_scene_ids(root, scenario, SPLIT, crop, config.split_rule)
    models = {c.row(config): candidate_model(out, config, c) for c in candidates}
    rows = {row: model for row, model in models.items() if model.is_file()}
    path = results_path(out, config)
    results = _reusable(path, config, scenes, rows)
    if results is not None:
        return results
    began = time.perf_counter()
    results = evaluate(
        [ModelPolicy(model, name=row) for row, model in rows.items()],
        root,
        scenario=scenario,
        split=SPLIT,
        sessions=config.sessions,
        episodes=config.episodes,
        seed=config.seed,
        crop=crop,
        baselines=["Rand"],  # with the Best fixed action and every fixed action's exact expectation
        keep_episodes=True,
        split_rule=config.split_rule,
    )
    path.parent.mkdir(parents=True, exist_ok=True)
    write_or_rescue(path, partial(write_json, results), "the results")
    record(f"{key}: {EVALUATE}", time.perf_counter() - began, f"split {SPLIT}, {len(rows)} candidate(s)")
    return results


def train_candidate(
    config: ReproduceConfig, out: Path, candidate: Candidate, clock: Any, record: Any, **train_kwargs: Any
) -> None:
    """Train one candidate on the train split on the run's clock, unless its model is reusable.

    Args:
        config: The run.
        out: The run folder.
        candidate: What to train.
        clock: The run's :class:`~davis_ag.workflows.reproduce.clock.StageClock`.
        record: The run's stage recorder.
        **train_kwargs: Passed on to ``train_agent`` (tests: a small network).
    """
    from davis_ag.workflows.reproduce.learners import train_learner

    scenario, crop, key = group_of(config)
    stage, steps = f"{key}: train {candidate.key}", candidate.timesteps(config)
    model = candidate_model(out, config, candidate)
    with clock.timing(stage) as sitting:
        trained = train_learner(
            candidate.algo, out / "dataset", scenario, crop, model, steps, config, candidate.settings(), **train_kwargs
        )
        if trained is None:
            sitting.discard()
    if trained is not None:
        record(stage, clock.seconds(stage), f"{steps} steps, {clock.sittings(stage)} sitting(s) on the clock")


def check_page(results_md: Path) -> None:
    """Refuse a page that exists without the run's markers: it would be replaced whole (the
    Table 4 page, docs/results.md, is another run's).

    Raises:
        UserError: naming the page and the one to use.
    """
    from davis_ag.atomic_files import read_page

    if results_md.is_file() and f"<!-- {MARKER}:start -->" not in read_page(results_md, "--results"):
        raise UserError(
            f"--results {results_md} has no <!-- {MARKER}:start --> section and would be replaced whole: "
            "use docs/a2c-search.md, or a new file"
        )


def reproduce_a2c_search(
    config: ReproduceConfig,
    out: Path,
    results_md: Path,
    candidates: tuple[Candidate, ...] | None = None,
    **train_kwargs: Any,
) -> int:
    """Generate and validate the group, then train and score each candidate on the train split;
    write ``results_md`` after each.

    Args:
        config: The run (``page="a2c-search"``; its first pair is the group).
        out: Work folder (``dataset``, ``models``, ``results``, ``state.json``).
        results_md: The page (docs/a2c-search.md's section, or a page of its own).
        candidates: What to train (None: :func:`~davis_ag.workflows.reproduce.a2c_candidates.candidates_of`
            the configuration's; tests: tiny budgets).
        **train_kwargs: Passed on to ``train_agent`` (tests: a small network).

    Returns:
        0 on success, 1 when the dataset failed validation.
    """
    from davis_ag.atomic_files import prove_writable_file, prove_writable_folder
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.provenance import code_version, machine_summary
    from davis_ag.scene.camera import Camera
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE, StageClock
    from davis_ag.workflows.reproduce.pages.a2c_search import write_search_page
    from davis_ag.workflows.reproduce.run import stage_recorder, validate_once
    from davis_ag.workflows.stages import generate_scenes

    scenario, crop, key = group_of(config)
    candidates = candidates or candidates_of(config)
    check_page(Path(results_md))  # before anything is made: another run's page is never replaced
    check_disk(config, Path(out).expanduser().absolute(), config.pairs[:1])
    out = prove_writable_folder(out)  # absolute at once: Helios moves the working directory
    results_md = prove_writable_file(results_md, "--results")
    state_path = out / "state.json"
    state = RunState.load(state_path)
    state.config = json.loads(json.dumps(asdict(config)))
    state.save(state_path)  # `--status` reads the run from its first stage on
    clock = StageClock(out / CLOCK_FILE, code_version(), machine=machine_summary())
    record = stage_recorder(state, state_path)
    scenario_spec, crop_spec = config.specs(scenario, crop)
    camera = Camera(*config.size)
    requests = [SceneRequest(scenario_spec, crop_spec, i, config.seed, camera) for i in range(config.sp_scenes)]
    state.scene_folders[key] = [r.folder for r in requests]
    print(f"== {key}: {len(requests)} scene(s) at {config.size[0]}x{config.size[1]}", flush=True)
    began = time.perf_counter()
    if not all(g["skipped"] for g in generate_scenes(requests, out / "dataset")):
        record(f"{key}: generate", time.perf_counter() - began)
    if not validate_once(out / "dataset" / requests[0].folder.split("/")[0], state, f"{key}: validate", clock, record):
        return 1
    evaluate_on_train(config, out, candidates, record)
    write_search_page(results_md, config, state, out, candidates)
    for candidate in candidates:
        print(f"== {key}: {candidate.row(config)} on the {SPLIT} split", flush=True)
        train_candidate(config, out, candidate, clock, record, **train_kwargs)
        evaluate_on_train(config, out, candidates, record)
        write_search_page(results_md, config, state, out, candidates)
        print(f"wrote {results_md}", flush=True)
    return 0

"""``davis-ag reproduce --config a2c-search``: A2C settings searched on the train split only.

The paper-scale run's A2C learns less than PPO on the same train split (docs/results.md), so this
run asks which A2C settings reach what PPO reaches there. On one group (SP strawberry, the
configuration's own dataset under ``OUT/dataset``), each stage resumable:

1. the group's scenes (finished ones skipped) and their validation;
2. Rand and the Best fixed action on the train split, so the page has its yardsticks at once;
3. each of :data:`CANDIDATES` in turn (the paper's budget first, the longer one last) trained on
   the train split (:func:`~davis_ag.workflows.reproduce.learners.train_learner`: reused when
   finished with the same settings, resumed from its checkpoint when killed), then every finished
   candidate scored with Rand and the Best fixed action on fresh train-split episodes (the test's
   protocol, another draw than the snapshot scores that kept the model), and the page rewritten.

Nothing here reads the test split: every evaluation is of ``split="train"``, and the choice is the
candidate A2C with the highest train-split OER_tau.
"""

from __future__ import annotations

import json
import time
from dataclasses import asdict, dataclass
from functools import partial
from pathlib import Path
from typing import TYPE_CHECKING, Any

from davis_ag.errors import UserError
from davis_ag.workflows.reproduce.configs import ReproduceConfig, check_disk
from davis_ag.workflows.reproduce.groups import group_key
from davis_ag.workflows.reproduce.state import RunState

if TYPE_CHECKING:
    from davis_ag.benchmark.results import EvaluationResults
    from davis_ag.workflows.reproduce.status import StageStatus

#: The page's marker (docs/a2c-search.md), and the run's only split.
MARKER = "a2c-search"
SPLIT = "train"
#: The stage that scores the candidates on the train split.
EVALUATE = "evaluate on train"


@dataclass(frozen=True)
class Candidate:
    """One setting set and budget of the search.

    Attributes:
        key: Its name in file and stage names (``a2c-zoo-atari``: ``models/a2c-zoo-atari_sp-strawberry.zip``).
        label: Its row's name without the steps (``A2C zoo-atari``).
        algo: ``a2c``, or ``ppo`` for the target.
        preset: The setting set (:data:`davis_ag.benchmark.algorithms.SETTINGS_PRESETS`; PPO's
            ``ours`` is the zoo's Atari settings, :data:`~davis_ag.benchmark.algorithms.SB3_SETTINGS`).
        source: Where its settings come from, in words.
        budget: Its steps over the run's (``sp_timesteps``, the paper's 300K).
        over: Settings over the preset's (tests: a short PPO rollout); None: none.
    """

    key: str
    label: str
    algo: str
    preset: str
    source: str
    budget: float = 1.0
    over: dict[str, Any] | None = None

    def timesteps(self, config: ReproduceConfig) -> int:
        """Environment steps it trains for in ``config``'s run."""
        return round(config.sp_timesteps * self.budget)

    def row(self, config: ReproduceConfig) -> str:
        """Its row in the evaluation and on the page (``A2C ours 300K``)."""
        return f"{self.label} {steps_text(self.timesteps(config))}"

    def settings(self) -> dict[str, Any] | None:
        """What :func:`~davis_ag.workflows.reproduce.learners.train_learner` takes: A2C's resolved
        set (with its ``n_envs`` where it carries one), PPO's settings over ours (None: ours)."""
        from davis_ag.benchmark.algorithms import resolve_settings

        if self.algo != "a2c":
            return None if self.over is None else dict(self.over)
        return {**resolve_settings(self.preset), **(self.over or {})}

    def shown_settings(self) -> dict[str, Any]:
        """Every setting it trains with over SB3's defaults, as its training record keeps them."""
        from davis_ag.workflows.reproduce.learners import learner_stamp

        stamp = learner_stamp(self.algo, 0, self.settings())
        return dict(stamp["a2c_settings" if self.algo == "a2c" else "sb3_settings"])


#: The search (docs/a2c-search.md says why each): our A2C at the paper's budget, the target (PPO
#: as the Table 4 run trains it), the zoo's Atari A2C, SB3's defaults, and ours at 10/3 of the budget
#: (1M steps for the paper's 300K), in the order the run takes them: the cheap rows first.
CANDIDATES: tuple[Candidate, ...] = (
    Candidate(
        "a2c-ours",
        "A2C ours",
        "a2c",
        "ours",
        "the Table 4 run's: SB3's A2C defaults with an entropy bonus and normalised advantages",
    ),
    Candidate(
        "ppo-zoo-atari",
        "PPO zoo-atari",
        "ppo",
        "ours",
        "the target, as the Table 4 run trains it: RL Baselines3 Zoo, hyperparams/ppo.yml, `atari`",
    ),
    Candidate("a2c-zoo-atari", "A2C zoo-atari", "a2c", "zoo-atari", "RL Baselines3 Zoo, hyperparams/a2c.yml, `atari`"),
    Candidate("a2c-sb3", "A2C sb3", "a2c", "sb3", "Stable-Baselines3's A2C defaults alone"),
    Candidate(
        "a2c-ours-long", "A2C ours", "a2c", "ours", "the Table 4 run's, 10/3 of the paper's budget", budget=10 / 3
    ),
)


def steps_text(steps: int) -> str:
    """``300K``, ``1M``, ``64``: a budget as the page names it."""
    if steps >= 1_000_000 and steps % 1_000_000 == 0:
        return f"{steps // 1_000_000}M"
    return f"{steps // 1000}K" if steps >= 1000 and steps % 1000 == 0 else str(steps)


def group_of(config: ReproduceConfig) -> tuple[str, str, str]:
    """The run's one group: ``(scenario, crop, key)``."""
    scenario, crop = config.pairs[0]
    return scenario, crop, group_key(scenario, crop)


def candidate_model(out: Path, config: ReproduceConfig, candidate: Candidate) -> Path:
    """A candidate's model (``models/a2c-zoo-atari_sp-strawberry.zip``)."""
    from davis_ag.workflows.reproduce.learners import model_path

    return model_path(out, group_of(config)[2], candidate.key)


def results_path(out: Path, config: ReproduceConfig) -> Path:
    """The train-split evaluation of every finished candidate with Rand and the Best fixed action."""
    return out / "results" / f"{group_of(config)[2]}-{SPLIT}.json"


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
    candidates: tuple[Candidate, ...] = CANDIDATES,
    **train_kwargs: Any,
) -> int:
    """Generate and validate the group, then train and score each candidate on the train split;
    write ``results_md`` after each.

    Args:
        config: The run (``page="a2c-search"``; its first pair is the group).
        out: Work folder (``dataset``, ``models``, ``results``, ``state.json``).
        results_md: The page (docs/a2c-search.md's section, or a page of its own).
        candidates: What to train (tests: tiny budgets).
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
    check_disk(config, Path(out).expanduser().absolute(), config.pairs[:1])
    out = prove_writable_folder(out)  # absolute at once: Helios moves the working directory
    results_md = prove_writable_file(results_md, "--results")
    check_page(results_md)
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


def search_stages(
    out: Path, config: ReproduceConfig, seconds: Any, candidates: tuple[Candidate, ...] = CANDIDATES
) -> list[StageStatus]:
    """The run's stages after its data for ``--status``: each candidate's training (one not started
    timed at the rate a finished candidate of the same algorithm trained at) and the scoring.

    Args:
        out: The run folder.
        config: The run.
        seconds: ``stage -> seconds on the clock or None`` (the status's).
        candidates: The search's candidates.

    Returns:
        One :class:`~davis_ag.workflows.reproduce.status.StageStatus` per stage.
    """
    from dataclasses import replace

    from davis_ag.benchmark.results import load_results
    from davis_ag.workflows.reproduce.learners import training_record
    from davis_ag.workflows.reproduce.status import UNDER_WAY, StageStatus, _training_status

    key = group_of(config)[2]
    stages = []
    for candidate in candidates:
        stage, steps = f"{key}: train {candidate.key}", candidate.timesteps(config)
        status = _training_status(out, key, candidate.key, steps, stage, seconds(stage))
        if status.progress in ("not started", UNDER_WAY):
            rates = [
                training_record(out, key, c.key).get("steps_per_second") for c in candidates if c.algo == candidate.algo
            ]
            if rate := next((r for r in rates if r), None):
                left = max(steps / rate - (status.seconds or 0.0), 0.0)
                status = replace(status, progress=f"{status.progress}; timed at {rate:.1f} steps/s", left_s=left)
        stages.append(status)
    try:
        scored = set(load_results(results_path(out, config), check=False).policies)
    except UserError:
        scored = set()
    wanted = {c.row(config) for c in candidates}
    done = wanted <= scored
    progress = f"{len(wanted & scored)} of {len(wanted)} candidates scored" if scored else "not started"
    stages.append(StageStatus(f"{key}: {EVALUATE}", done, progress, seconds(f"{key}: {EVALUATE}")))
    return stages

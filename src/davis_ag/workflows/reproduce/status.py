"""``davis-ag reproduce --status``: where a long run stands, read from its files, touching nothing.

A ``paper-scale`` run takes many sittings; its log says what the last one did. The status says what
each stage of the whole run has done (scenes made, steps trained, evaluations written), how long it
has worked on the stage's clock, and about how long is left: for a stage under way (a learner at the
rate of its last sitting, a generate stage at the mean time of its scenes so far, or at the rate of
the views drawn before its first scene ends), for a learner not started, at the rate the same
learner trained at on the run's other group (in a run of cells, the median rate of the cells that
trained it), and for a validation not started, at the views per
second of the other group's last whole check; the stages with no rate yet are named, not guessed.
Reading it while the run goes on is safe: it writes nothing, every file it reads but one is written
atomically, and the one that grows (a scene's journal of views) may vanish as its scene ends, which
counts it as not under way.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from davis_ag.workflows.reproduce.configs import ReproduceConfig, disk_line
from davis_ag.workflows.reproduce.groups import group_key
from davis_ag.workflows.reproduce.state import RunState, StageRecord, run_config

if TYPE_CHECKING:
    from davis_ag.workflows.reproduce.cells import Cell


@dataclass(frozen=True)
class StageStatus:
    """One stage of a run as its files show it.

    Attributes:
        stage: The stage's name, as in the run's clock and results page (``sp-strawberry: train A2C``).
        done: Whether it has finished.
        progress: What it has done, in words (``62 of 86 scenes``, ``not started``).
        seconds: Its wall time so far on the run's clock (or its record), None when it has none.
        left_s: About how long is left, where it is under way: a learner's at its last sitting's
            rate, a generate stage's at the mean time of its scenes made so far (before the first
            ends, at the rate of the views drawn on the stage's clock).
    """

    stage: str
    done: bool
    progress: str
    seconds: float | None = None
    left_s: float | None = None


#: A learner's stage on the clock with no checkpoint yet.
UNDER_WAY = "under way, no checkpoint yet"


def run_status(out: Path) -> tuple[ReproduceConfig, list[StageStatus]]:
    """Every stage of the run in ``out``, in the order the run takes them.

    Args:
        out: The run's work folder (``--out``).

    Returns:
        The run's configuration and one :class:`StageStatus` per stage.

    Raises:
        UserError: when ``out`` holds no run.
    """
    from davis_ag.generate.dataset_files import complete_scenes
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE, read_clock

    state = RunState.load(out / "state.json")
    config = run_config(state, out / "state.json")
    recorded = state.stages
    clock = read_clock(out / CLOCK_FILE)

    def seconds(stage: str) -> float | None:
        if stage in recorded and stage.endswith((": generate", ": validate")):
            return recorded[stage].seconds  # scenes made before the clock are counted there
        sittings = clock.get(stage)
        return sum(s["seconds"] for s in sittings) if sittings else None

    made = set(complete_scenes(out / "dataset"))
    stages: list[StageStatus] = []
    for scenario, crop in config.pairs:
        key = group_key(scenario, crop)
        stage = f"{key}: generate"
        stages.append(_generation_status(out / "dataset", config, scenario, crop, state, made, seconds(stage)))
        stage = f"{key}: validate"
        note = recorded[stage].note if stage in recorded else None
        stages.append(
            StageStatus(stage, bool(note and note.endswith(": sound")), note or "not started", seconds(stage))
        )
        if not note and seconds(stage) is not None:
            stages[-1] = replace(stages[-1], progress="started, not finished")
        elif not note:
            stages[-1] = _validation_from_elsewhere(config, clock, recorded, scenario, crop, stages[-1])
        if config.page in ("robot", "structures", "a2c-search"):
            continue  # their learners and evaluations are per cell, or per candidate: after the data
        timesteps = config.timesteps(scenario)
        for algo in config.learners:
            stage = f"{key}: train {algo.upper()}"
            stages.append(_training_status(out, key, algo, timesteps, stage, seconds(stage)))
            if stages[-1].progress in ("not started", UNDER_WAY):
                stages[-1] = _estimated_from_elsewhere(out, config, key, algo, timesteps, stages[-1])
        stage = f"{key}: evaluate"
        written = (out / "results" / f"{key}.json").is_file()
        progress = f"{config.sessions} x {config.episodes} episodes written" if written else "not started"
        stages.append(StageStatus(stage, written, progress, seconds(stage)))
        if not written and seconds(stage) is None:
            stages[-1] = _evaluation_from_elsewhere(config, clock, out, scenario, crop, stages[-1])
    if config.page == "robot":
        from davis_ag.workflows.reproduce.robot_cells import robot_cells

        stages += _cells_status(out, config, state, seconds, robot_cells(out, config, config.pairs))
    elif config.page == "structures":
        from davis_ag.workflows.reproduce.structure_cells import structure_cells

        cells = [cell for _, cell in structure_cells(out, config, config.pairs)]
        stages += _cells_status(out, config, state, seconds, cells)
    if config.page == "a2c-search":
        stages += _search_stages(out, config, seconds)
    return config, stages


def _cells_status(
    out: Path, config: ReproduceConfig, state: RunState, seconds: Any, cells: list[Cell]
) -> list[StageStatus]:
    """A run of cells (:mod:`davis_ag.workflows.reproduce.cells`), in its order: every cell's
    baselines, then cell by cell its learners and its evaluation with them."""
    from davis_ag.workflows.reproduce.cells import load_cell, unreached_stage

    rows = {cell.key: (set(r.policies) if (r := load_cell(out, cell)) else None) for cell in cells}
    baselines, learners = [], []
    for cell in cells:
        unreached = state.stages.get(unreached_stage(cell))
        if unreached is not None:
            baselines.append(StageStatus(f"{cell.key}: baselines", True, unreached.note))
            continue
        done = rows[cell.key] is not None
        baselines.append(StageStatus(f"{cell.key}: baselines", done, "written" if done else "not started"))
        for algo in config.learners:
            stage, steps = f"{cell.key}: train {algo.upper()}", config.timesteps(cell.scenario)
            status = _training_status(out, cell.key, algo, steps, stage, seconds(stage))
            if status.progress in ("not started", UNDER_WAY):
                status = _timed_from_other_cells(out, cells, algo, steps, status)
            learners.append(status)
        wanted = {a.upper() for a in config.learners}
        done = wanted <= (rows[cell.key] or set()) and rows[cell.key] is not None
        progress = "written with " + ", ".join(sorted(wanted)) if done else "not started"
        learners.append(StageStatus(f"{cell.key}: evaluate", done, progress, seconds(f"{cell.key}: evaluate")))
    return baselines + learners


def _timed_from_other_cells(out: Path, cells: list[Cell], algo: str, steps: int, status: StageStatus) -> StageStatus:
    """A cell's learner not started (or with no checkpoint yet), timed at the median rate the same
    learner trained at in the run's cells that have finished it (their scenes and robots differ,
    so it is a rough time), less the time it has run."""
    import statistics

    from davis_ag.workflows.reproduce.learners import training_record

    rates = [r for cell in cells if (r := training_record(out, cell.key, algo).get("steps_per_second"))]
    if not rates:
        return status
    rate = statistics.median(rates)
    return _timed_at(status, steps, rate, f"the median {rate:.1f} steps/s of {len(rates)} cell(s) trained")


def _timed_at(status: StageStatus, steps: int, rate: float, source: str) -> StageStatus:
    """``status`` (a learner not started, or with no checkpoint yet) timed at ``rate`` steps/s, less
    the time it has run; ``source`` says where the rate comes from. A learner already past the time
    the rate gives (a busier machine, a paused run) gets no guess."""
    whole, spent = steps / rate, status.seconds or 0.0
    if spent >= whole:
        return replace(status, progress=f"{status.progress}; past the {whole / 3600:.2f} h that {source} gives")
    return replace(status, progress=f"{status.progress}; timed at {source}", left_s=whole - spent)


def _search_stages(out: Path, config: ReproduceConfig, seconds: Any) -> list[StageStatus]:
    """The run's stages after its data for ``--status``: each candidate's training (one not started
    timed at the rate a finished candidate of the same algorithm trained at) and the scoring.

    Args:
        out: The run folder.
        config: The run.
        seconds: ``stage -> seconds on the clock or None`` (the status's).

    Returns:
        One :class:`StageStatus` per stage.
    """
    from davis_ag.benchmark.results import load_results
    from davis_ag.errors import UserError
    from davis_ag.workflows.reproduce.a2c_candidates import EVALUATE, candidates_of, group_of, results_path
    from davis_ag.workflows.reproduce.learners import training_record

    key, candidates = group_of(config)[2], candidates_of(config)
    stages = []
    for candidate in candidates:
        stage, steps = f"{key}: train {candidate.key}", candidate.timesteps(config)
        status = _training_status(out, key, candidate.key, steps, stage, seconds(stage))
        if status.progress in ("not started", UNDER_WAY):
            rates = [
                training_record(out, key, c.key).get("steps_per_second") for c in candidates if c.algo == candidate.algo
            ]
            if rate := next((r for r in rates if r), None):
                status = _timed_at(status, steps, rate, f"{rate:.1f} steps/s")
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


def _generation_status(
    root: Path,
    config: ReproduceConfig,
    scenario: str,
    crop: str,
    state: RunState,
    made: set[str],
    seconds: float | None,
) -> StageStatus:
    """A generate stage from its scene folders: the scenes made, and the views drawn so far in
    those under way (their hidden partial folders' journals), so a stage of long scenes shows
    progress before its first scene ends.
    """
    from davis_ag.generate.scene_writer import JOURNAL, partial_dir
    from davis_ag.scene.specs import scene_folder
    from davis_ag.scene.view_grid import views_per_scene

    key, wanted = group_key(scenario, crop), config.scenes(scenario)
    scenario_spec, crop_spec = config.specs(scenario, crop)
    recorded = state.scene_folders.get(key, [])
    # The run records its folders as the stage starts; before that they are the first `wanted` of the group.
    folders = recorded or [scene_folder(scenario_spec, crop_spec, i) for i in range(wanted)]
    count = sum(folder in made for folder in folders)
    drawn = under_way = 0
    for folder in folders:
        journal = partial_dir(root / folder) / JOURNAL
        if folder in made:
            continue
        try:
            with open(journal, "rb") as lines:
                drawn += sum(1 for _ in lines)
        except OSError:  # not begun, or finished and moved into place since `made` was read
            continue
        under_way += 1
    started = bool(recorded) or count > 0 or under_way > 0
    progress = f"{count} of {wanted} scenes" if started else "not started"
    if under_way:
        progress += f"; {under_way} more under way ({drawn:,} views drawn)"
    views = views_per_scene(scenario_spec, crop_spec)
    left = _generation_left(root, [f for f in folders if f in made], wanted - count, views)
    if left is None and seconds and drawn and not count:
        # No scene finished yet: the views drawn on this stage's clock give the rate.
        left = (wanted * views - drawn) * seconds / drawn
    return StageStatus(f"{key}: generate", bool(recorded) and count == wanted, progress, seconds, left)


def _generation_left(root: Path, made: list[str], remaining: int, views: int) -> float | None:
    """About how long the ``remaining`` scenes of a group take: the mean time of its scenes made
    (``scene.json``'s ``timing_s``), in rounds of as many scene processes as this machine runs at once.

    A scene resumed from an earlier run's views recorded only the time of the views it drew
    itself; its drawing time is scaled up to all ``views`` of the scene (a stopped run's scenes
    are often all resumed ones, and they are the only rate there is).
    """
    import json

    from davis_ag.formats.layout import SCENE_METADATA
    from davis_ag.generate.run_progress import default_workers
    from davis_ag.workflows.reproduce.clock import scene_seconds

    if remaining <= 0:
        return None
    times = []
    for folder in made:
        try:
            timing = json.loads((root / folder / SCENE_METADATA).read_text()).get("timing_s", {})
        except (OSError, ValueError):
            continue
        earlier = int(timing.get("views_from_an_earlier_run", 0))
        if not timing or earlier >= views:
            continue
        if earlier:
            timing = {**timing, "draw_and_label": float(timing.get("draw_and_label", 0.0)) * views / (views - earlier)}
        times.append(scene_seconds(timing))
    # Each scene is one process's: the remaining ones go in rounds of as many as run at once.
    return -(-remaining // default_workers()) * sum(times) / len(times) if times else None


def _training_status(out: Path, key: str, algo: str, timesteps: int, stage: str, seconds: float | None) -> StageStatus:
    """A learner's stage from its saved model, or the checkpoint of a run under way."""
    from davis_ag.benchmark.training import checkpoint_paths
    from davis_ag.workflows.reproduce.learners import load_json_object, model_path, training_record

    model = model_path(out, key, algo)
    if model.is_file():
        selection = training_record(out, key, algo).get("selection", {})
        return StageStatus(stage, True, f"{timesteps:,} steps trained{_best(selection.get('scores'))}", seconds)
    record = load_json_object(checkpoint_paths(model)[1])
    done = int(record.get("timesteps_done", 0))
    if not done:
        return StageStatus(stage, False, "not started" if seconds is None else UNDER_WAY, seconds)
    left = None
    if sittings := record.get("sittings"):
        last = sittings[-1]
        steps, spent = last["to_step"] - last["from_step"], last["seconds"]
        if steps > 0 and spent > 0:
            left = (timesteps - done) * spent / steps
    progress = f"{done:,} of {timesteps:,} steps at its last checkpoint ({100 * done / timesteps:.0f} %)"
    return StageStatus(stage, False, progress + _best(record.get("selection")), seconds, left)


def _estimated_from_elsewhere(
    out: Path, config: ReproduceConfig, key: str, algo: str, timesteps: int, status: StageStatus
) -> StageStatus:
    """A learner not started, or started with no checkpoint yet to time it by, timed at the rate the
    same learner trained at on another group of the run (the same network and observations; the
    scenes differ), where one has finished, less the time it has run."""

    from davis_ag.workflows.reproduce.learners import training_record

    for other in (group_key(s, c) for s, c in config.pairs):
        rate = training_record(out, other, algo).get("steps_per_second") if other != key else None
        if rate:
            return _timed_at(status, timesteps, rate, f"{other}'s {rate:.1f} steps/s")
    return status


def _validation_from_elsewhere(
    config: ReproduceConfig,
    clock: dict[str, list[dict[str, Any]]],
    recorded: dict[str, StageRecord],
    scenario: str,
    crop: str,
    status: StageStatus,
) -> StageStatus:
    """A validation not started, timed at the views per second of another group's last whole
    check (every view is read, at the run's one image size), where one has passed."""

    from davis_ag.scene.view_grid import views_per_scene

    views = config.scenes(scenario) * views_per_scene(*config.specs(scenario, crop))
    for other_scenario, other_crop in config.pairs:
        other = group_key(other_scenario, other_crop)
        sittings = clock.get(f"{other}: validate")
        if other == group_key(scenario, crop) or not sittings or f"{other}: validate" not in recorded:
            continue
        checked = config.scenes(other_scenario) * views_per_scene(*config.specs(other_scenario, other_crop))
        check = recorded[f"{other}: validate"].check_seconds  # one whole check (None: a record from before it)
        took = sittings[-1]["seconds"] if check is None else check
        rate = checked / max(float(took), 1e-9)
        return replace(
            status,
            progress=f"not started; {views:,} views, timed at {other}'s last check ({rate:.0f} views/s)",
            left_s=views / rate,
        )
    return status


def _evaluation_from_elsewhere(
    config: ReproduceConfig,
    clock: dict[str, list[dict[str, Any]]],
    out: Path,
    scenario: str,
    crop: str,
    status: StageStatus,
) -> StageStatus:
    """An evaluation not started, timed at what another group's took (the same policies and
    episodes; the scenes differ), one of the same scenario first, where one has been written."""
    key = group_key(scenario, crop)
    others = sorted(config.pairs, key=lambda pair: pair[0] != scenario)  # the same scenario first
    for other in (group_key(s, c) for s, c in others):
        sittings = clock.get(f"{other}: evaluate")
        if other == key or not sittings or not (out / "results" / f"{other}.json").is_file():
            continue
        took = sum(float(sitting["seconds"]) for sitting in sittings)
        return replace(status, progress=f"not started; timed at {other}'s {took:.0f} s", left_s=took)
    return status


def _best(scores: Any) -> str:
    """``; best train-split OER_tau .459 at 90,000 steps`` from a run's snapshot scores, or ``""``."""
    if not isinstance(scores, list) or not scores:
        return ""
    best = max(scores, key=lambda s: s["oer_tau"])
    return f"; best train-split OER_tau {best['oer_tau']:.3f} at {best['step']:,} steps"


def format_status(out: Path) -> str:
    """The run's status as a Markdown table under one line naming the run."""
    config, stages = run_status(out)
    lines = [
        f"`{config.name}` run in {out}: {config.scenes_in_words()} at {config.size[0]}x{config.size[1]}, "
        f"learners {', '.join(a.upper() for a in config.learners)}",
        "",
        "| stage | done | what its files show | hours on the clock | about hours left |",
        "|---|---|---|---|---|",
    ]
    for s in stages:
        hours = f"{s.seconds / 3600:.2f}" if s.seconds is not None else "-"
        left = f"{s.left_s / 3600:.1f}" if s.left_s is not None else "-"
        lines.append(f"| {s.stage} | {'yes' if s.done else 'no'} | {s.progress} | {hours} | {left} |")
    timed = [s for s in stages if not s.done and s.left_s is not None]
    untimed = [s.stage for s in stages if not s.done and s.left_s is None]
    if timed or untimed:
        lines += ["", f"About {sum(s.left_s or 0.0 for s in timed) / 3600:.1f} hours left in the stages timed above"]
        if untimed:
            # By step, in the order a group's stages run: "generate of sp-olive, row-olive; evaluate of ...".
            by_step: dict[str, list[str]] = {s.stage.partition(": ")[2]: [] for s in stages}
            for stage in untimed:
                key, _, step = stage.partition(": ")
                by_step[step].append(key)
            named = "; ".join(f"{step} of {', '.join(keys)}" for step, keys in by_step.items() if keys)
            lines[-1] += f", and {len(untimed)} not timed yet (no rate measured for them): {named}"
        lines[-1] += "."
    if config.page not in ("robot", "structures"):  # a cells run's variants make datasets of their own
        lines += ["", disk_line(config, out)]
    return "\n".join(lines)

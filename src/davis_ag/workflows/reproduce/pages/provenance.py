"""How a ``davis-ag reproduce`` run was made, read from its records for its results page: the code,
plants, renderer and image size of each group's scenes (their ``scene.json``), how each model was
trained (its ``NAME.training.json``) and the wall time and code of every stage (``state.json`` and
the run's clock)."""

from __future__ import annotations

from collections import Counter
from pathlib import Path
from typing import Any

from davis_ag.formats.layout import SCENE_METADATA
from davis_ag.formats.scene_file import CameraRecord, RendererRecord, read_scene_file_or_empty
from davis_ag.workflows.reproduce.groups import GROUPS
from davis_ag.workflows.reproduce.learners import LEARNERS, training_record
from davis_ag.workflows.reproduce.state import RunState, StageRecord

#: Steps that a later sitting does whole again (a validation whose code changed, an evaluation),
#: where generation and training resume: their clock adds up the repeats.
REDONE_WHOLE = ("validate", "evaluate")


def one_whole_hours(step: str, entry: StageRecord | None, sittings: list[dict[str, Any]]) -> float | None:
    """Hours one whole run of a step that each sitting does whole (``validate``) took, when the
    clock holds more than one sitting of it; None otherwise (the clock's total is then its cost).

    Args:
        step: The stage's step (``validate``).
        entry: The stage's record in ``state.json`` (None: none yet): its ``check_seconds`` where
            the run recorded it.
        sittings: The stage's sittings on the run's clock; a record without ``check_seconds`` (a
            run from before it) is read by the last, which completed the stage.

    Returns:
        The hours, or None.
    """
    if step not in REDONE_WHOLE or len(sittings) < 2:
        return None
    check = entry.check_seconds if entry is not None else None
    seconds = sittings[-1]["seconds"] if check is None else check
    return float(seconds) / 3600


def _counted(counter: Counter) -> str:
    return "; ".join(f"{value} ({n} scene{'s' if n > 1 else ''})" for value, n in counter.most_common())


def scene_provenance(dataset: Path, scenes: list[str]) -> list[str]:
    """One line per fact about how a group's scenes were made, from their scene.json files."""
    versions: Counter[str] = Counter()
    plants: Counter[str] = Counter()
    renderers: Counter[str] = Counter()
    sizes: Counter[str] = Counter()
    for scene in scenes:
        meta = read_scene_file_or_empty(dataset / scene / SCENE_METADATA)
        versions[(meta.generator.version if meta.generator else None) or "unrecorded"] += 1
        # Scenes from before the Canopy Generator plants record no generator: PlantArchitecture's.
        plants[f"`--plants {meta.plant_generator or 'architecture'}`"] += 1
        renderer = meta.renderer or RendererRecord()
        renderers[
            f"{renderer.name or '?'} renderer, {renderer.look or '?'} look, antialiasing: "
            f"{renderer.antialiasing or '?'}"
        ] += 1
        camera = meta.camera or CameraRecord()
        sizes[f"{camera.width or '?'}x{camera.height or '?'}"] += 1
    lines = [
        f"code: {_counted(versions)}"
        + (
            " — made by more than one version of the code (`davis-ag verify DATA/GROUP/NNN` makes a "
            "scene again with the code at hand and says whether every file comes out the same)"
            if len(versions) > 1
            else ""
        ),
        f"plants grown by {_counted(plants)}",
        f"drawn with the {_counted(renderers)}",
        f"image size {_counted(sizes)}",
    ]
    return lines


def _code_version(path: Path) -> str:
    """The code version a scene.json records, or ``unrecorded``."""
    generator = read_scene_file_or_empty(path).generator
    return (generator.version if generator else None) or "unrecorded"


def training_provenance(record: dict[str, Any]) -> str:
    """A sentence on how a model was trained: steps, sittings, the code of each, steps per second."""
    sittings = record.get("sittings", [])
    codes = Counter(s.get("code", "unrecorded") for s in sittings)
    algorithm = record.get("algorithm", "A2C")
    settings = record.get("a2c_settings" if algorithm == "A2C" else "sb3_settings")
    text = (
        f"{record.get('timesteps', 0):,} steps in {len(sittings)} sitting(s), "
        f"{record.get('seconds', 0) / 3600:.2f} h, {record.get('steps_per_second', 0):.1f} steps/s; "
        f"network `{record.get('arch', '?')}`, {record.get('n_envs', '?')} environments, settings "
        + (
            ", ".join(f"{k}={v}" for k, v in settings.items()) or "none changed"
            if settings is not None
            else "not recorded (SB3's defaults)"
        )
        + f" over SB3's {algorithm} defaults, code "
        + ", ".join(codes)
    )
    if len(codes) > 1:
        text += " — the code changed between sittings"
    selection = record.get("selection")
    if selection and selection.get("kept_step") is not None:
        scores = selection["scores"]
        kept = next(s for s in scores if s["step"] == selection["kept_step"])
        last = max(scores, key=lambda s: s["step"])
        text += (
            f"; kept the snapshot at {kept['step']:,} steps, the best of {len(scores)} scored on the "
            f"train split ({selection['episodes']} {selection['play']} episodes each, every "
            f"{selection['every']:,} steps): train OER_tau {kept['oer_tau']:.3f}, the last snapshot's "
            f"{last['oer_tau']:.3f}"
        )
    else:
        text += "; kept the last snapshot"
    return text


def how_made(state: RunState, out: Path | None) -> list[str]:
    """The "How this run was made" section, from scene.json files, training records and stages."""
    lines = ["## How this run was made", ""]
    if out is None:
        return [*lines, "No work folder was given, so the run's records were not read.", ""]
    for scenario, key in GROUPS.items():
        scenes = state.scene_folders.get(key, [])
        if not scenes:
            continue
        lines.append(f"- **{key}**, {len(scenes)} scene(s):")
        lines += [f"  - {line}" for line in scene_provenance(out / "dataset", scenes)]
        for learner in LEARNERS:
            record = training_record(out, key, learner)
            if record:
                lines.append(f"  - {learner}: {training_provenance(record)}")
    return [*lines, ""]


def stage_rows(state: RunState, out: Path | None) -> list[tuple[str, float, str, str]]:
    """The wall time per stage, each with the code that did its work and a note.

    A stage's entry in ``state.json`` is rewritten by every sitting that passes it, even one that
    only skipped finished scenes or resumed a training run. So the code of a generate stage is read
    from its scenes' ``scene.json``, and a training stage's rate and code from the model's
    training record (every sitting); its time is the run's clock's (every sitting, the time redone
    after a kill included: :mod:`davis_ag.workflows.reproduce.clock`), or the record's for a run from
    before the clock.

    Returns:
        ``(stage, seconds, code, note)`` rows in the run's order.
    """
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE, read_clock

    clock = read_clock(out / CLOCK_FILE) if out is not None else {}
    rows = []
    for stage, entry in state.stages.items():
        key, _, step = stage.partition(": ")
        seconds, code, note = entry.seconds, entry.code or "unrecorded", entry.note
        scenes = state.scene_folders.get(key)
        if out is not None and step == "generate" and scenes:
            code = _counted(Counter(_code_version(out / "dataset" / scene / SCENE_METADATA) for scene in scenes))
        record: dict[str, Any] = {}
        learner = step.removeprefix("train ")
        if step.startswith("train ") and learner in LEARNERS and out is not None:  # only training has a record
            record = training_record(out, key, learner)
        if record.get("sittings"):
            sittings = record["sittings"]
            timed = clock.get(stage, [])
            seconds = sum(s["seconds"] for s in timed) if timed else record.get("seconds", seconds)
            code = ", ".join(dict.fromkeys(s.get("code", "unrecorded") for s in sittings))
            note = (
                f"{record.get('timesteps', 0):,} steps in {len(sittings)} sitting(s), "
                f"{record.get('steps_per_second', 0):.1f} steps/s over the sittings' wall time"
                + (f"; {len(timed)} sitting(s) on the run's clock" if timed else "")
            )
        one = one_whole_hours(step, entry, clock.get(stage, []))
        if one is not None:
            note += (
                f"; {len(clock[stage])} sittings on the run's clock, each doing the whole {step} again "
                f"(its code changed, or a sitting was stopped): one whole {step} took {one:.2f} h"
            )
        rows.append((stage, seconds, code, note))
    return rows

"""What a training run keeps when its output cannot be written (a full disk, a folder it cannot
write): the model in memory is never lost to a failed write. It goes to a rescue folder
(:func:`davis_ag.atomic_files.rescue_folder`) with its training record, whatever ``--keep`` says
and however short the run, unless a file beside the output already holds what the run keeps;
the one line of the failure says where it is and how to use it."""

from __future__ import annotations

from pathlib import Path
from typing import Any

from davis_ag.atomic_files import rescue_folder, write_json_atomic
from davis_ag.benchmark.checkpoints import save_model
from davis_ag.benchmark.selection import KeepBestOnTrain, snapshot_path
from davis_ag.benchmark.training_record import training_record_path
from davis_ag.errors import UserError


def rescued_selection(selection: KeepBestOnTrain | None, model: Any) -> dict[str, Any]:
    """What the record of a model kept elsewhere says of the snapshot choice: the scores, with a
    best whose snapshot could not be written, and the model's own step as the kept one."""
    if selection is None:
        return {}
    scores = sorted([*selection.scores, *([selection.unsaved] if selection.unsaved else [])], key=lambda s: s["step"])
    return {"selection": {**selection.record(), "scores": scores, "kept_step": int(model.num_timesteps)}}


def keep_what_it_trained(
    error: OSError,
    model: Any,
    total_timesteps: int,
    final: Path,
    selection: KeepBestOnTrain | None,
    model_file: Path,
    record: dict[str, Any],
) -> str:
    """The one line of a training run whose output (or checkpoint) could not be written before its
    final model was in place: what failed, where what it trained is now, and how to use it.

    The model in memory is written to a rescue folder (:func:`davis_ag.atomic_files.rescue_folder`),
    its training record beside it, whatever ``--keep`` says and however short the run, unless a
    file beside ``final`` already holds what the run keeps: the best snapshot of a finished
    ``--keep best-train`` run (none better failed to be written), or the last checkpoint of a run
    stopped before its budget, which the same command resumes (:func:`what_survives`). When that
    write fails too, the line names both failures and what survives."""
    steps = int(model.num_timesteps)
    finished = steps >= total_timesteps
    best = selection.best if selection is not None else None
    unsaved = selection.unsaved if selection is not None else None
    failed = (
        f"training finished but its output {final} could not be written ({_reason(error)})"
        if finished
        else f"training stopped at {steps} of {total_timesteps} steps ({_reason(error)})"
    )
    if steps == 0 or (not finished and unsaved is None and model_file.is_file()):
        return what_survives(error, final, selection, model_file)
    if (
        selection is not None
        and finished
        and best is not None
        and unsaved is None
        and snapshot_path(final, best["step"]).is_file()
    ):
        return (
            f"{failed}; the best snapshot ({best['step']} steps, train-split {selection.score_text(best)}) "
            f"is kept in {snapshot_path(final, best['step'])}: move it to {final} to use it"
        )
    score = (
        f", train-split {selection.score_text(unsaved)}, the best"
        if selection is not None and unsaved is not None
        else ""
    )
    what = f"the trained model ({steps} steps{score})" if finished else f"the model so far ({steps} steps{score})"
    beside = _kept_beside(final, selection, model_file)
    try:
        folder = rescue_folder()
    except UserError as again:
        return f"{failed}, nor could {what} be kept elsewhere ({again}); {_survives(what, beside)}"
    kept = folder / final.name
    try:
        save_model(model, kept)
    except OSError as again:
        try:
            folder.rmdir()
        except OSError:
            pass
        return f"{failed}, nor could {what} be kept in {kept} ({again.strerror or again}); {_survives(what, beside)}"
    try:
        write_json_atomic(training_record_path(kept), record)
        use = f"move it (and {training_record_path(kept).name} beside it) to {final.parent} to use it"
    except OSError:
        use = f"move it to {final} to use it (its training record could not be written)"
    also = f"; {beside}" if beside is not None and not finished else ""
    return f"{failed}; {what} is kept in {kept}: {use}{also}"


def _survives(what: str, beside: str | None) -> str:
    """What survives a run whose model could be kept nowhere: a file beside its output, or nothing."""
    if beside is None:
        return f"{what} is lost: free the space and run again"
    return f"{beside}: free the space and run the same command again to finish"


def _reason(error: OSError) -> str:
    """An operating-system failure in a few words, with the file it names."""
    return (f"{error.filename}: " if error.filename else "") + (error.strerror or str(error))


def _kept_beside(final: Path, selection: KeepBestOnTrain | None, model_file: Path) -> str | None:
    """Which finished model of the run a file beside ``final`` holds (the best snapshot so far, or
    the last checkpoint), and where, as a phrase; None when none does."""
    best = selection.best if selection is not None else None
    if selection is not None and best is not None and snapshot_path(final, best["step"]).is_file():
        return (
            f"the best snapshot so far ({best['step']} steps, train-split {selection.score_text(best)}) "
            f"is kept in {snapshot_path(final, best['step'])}"
        )
    if model_file.is_file():
        return f"the last checkpoint is kept in {model_file}"
    return None


def what_survives(error: OSError, final: Path, selection: KeepBestOnTrain | None, model_file: Path) -> str:
    """The one line of a training run that a failure of the machine (a full disk) ended: what
    failed, and which finished model survives where (the final model, the best snapshot so far,
    or the last checkpoint), so nothing finished is lost or claimed where it is not."""
    best = selection.best if selection is not None else None
    if final.is_file() and (best is None or not snapshot_path(final, best["step"]).is_file()):
        kept = f"the trained model is saved in {final} (its training record is not)"
    else:
        kept = _kept_beside(final, selection, model_file) or "no snapshot was finished yet"
    return f"training stopped: {_reason(error)}; {kept}: free the space and run the same command again to finish"

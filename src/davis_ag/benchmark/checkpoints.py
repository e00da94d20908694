"""A training run's checkpoint beside its output: writing it every so many steps, whether a run may
resume it, and loading it.

A checkpoint is SB3's zip of the model (with its optimiser state and step count) beside a JSON
record of the run's settings, steps done, sittings, learning curve and snapshot scores
(:class:`CheckpointEvery` writes both, :func:`save_model` the zip atomically). By the output rule (docs/errors.md) the same
run's checkpoint is resumed; one of another run, or a damaged one, is discarded only with
``--force``, and otherwise refused in one line offering both ways on.
"""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

from stable_baselines3.common.callbacks import BaseCallback

from davis_ag.atomic_files import atomic_output, write_json_atomic
from davis_ag.benchmark.algorithms import SB3_DEFAULT_SETTINGS
from davis_ag.benchmark.progress import LearningCurve
from davis_ag.benchmark.selection import KeepBestOnTrain, last_multiple
from davis_ag.errors import UserError, stops_held
from davis_ag.provenance import code_version


def resumable(
    settings_file: Path, model_file: Path, settings: dict[str, Any]
) -> tuple[int, list, list, list, str] | None:
    """Steps done, sittings, learning curve, snapshot scores so far and the environments' seeding
    (``env_seeds``) of a checkpoint of a run with the same settings, else None."""
    try:
        saved = json.loads(settings_file.read_text())
    except (OSError, ValueError):
        return None
    if not model_file.is_file() or not isinstance(saved, dict):
        return None
    done = saved.pop("timesteps_done", None)
    sittings = saved.pop("sittings", [])
    curve = saved.pop("curve", [])
    scores = saved.pop("selection", [])
    # Checkpoints from before settings were recorded trained A2C with SB3's defaults.
    if saved.get("algorithm", "A2C") == "A2C":
        saved.setdefault("a2c_settings", SB3_DEFAULT_SETTINGS)
    saved.setdefault("start_rule", "scene")  # and drew starts scene first
    saved.setdefault("keep", "last")  # and kept the last snapshot
    # Checkpoints from before the train scenes were recorded are taken for the split as it is.
    saved.setdefault("train_scenes", settings.get("train_scenes"))
    # ... and from before the seed streams seeded environment i with seed + i: resumed so.
    env_seeds = saved.pop("env_seeds", "seed+i")
    wanted = {k: v for k, v in settings.items() if k != "env_seeds"}
    if saved.get("dataset") == "/":
        # Checkpoints before this version recorded Path.root ("/") for any dataset given as a
        # path; they are taken as they were then, for whatever dataset the run names.
        saved["dataset"] = settings["dataset"]
    if saved != wanted or not isinstance(done, int) or not isinstance(sittings, list):
        return None
    curve, scores = curve if isinstance(curve, list) else [], scores if isinstance(scores, list) else []
    return done, sittings, curve, scores, str(env_seeds)


def check_checkpoint(
    settings_file: Path, model_file: Path, settings: dict[str, Any], force: bool
) -> tuple[int, list, list, list, str] | None:
    """What to resume from a checkpoint beside the output, by the output rule: the same run's is
    resumed; one of another run, or a damaged one, is discarded only with ``force``.

    Returns:
        As :func:`resumable`, or None to start afresh (no checkpoint, or ``force`` discarded one).

    Raises:
        UserError: for a damaged checkpoint or one of other settings, without ``force``: one line
            with both ways on (start over with --force, or keep it).
    """
    if not settings_file.exists() and not model_file.exists():
        return None
    problem = _checkpoint_problem(settings_file, model_file, settings)
    if problem is None:
        return resumable(settings_file, model_file, settings)
    if not force:
        raise UserError(
            f"{model_file}: {problem}: run again with --force to discard it and start over, or stop here to keep it"
        )
    print(f"note: {model_file.name}: {problem}; --force: starting over", flush=True)
    model_file.unlink(missing_ok=True)
    settings_file.unlink(missing_ok=True)
    return None


def _checkpoint_problem(settings_file: Path, model_file: Path, settings: dict[str, Any]) -> str | None:
    """Why a checkpoint cannot be resumed by a run of ``settings``, or None when it can."""
    import zipfile

    if not model_file.is_file() or not zipfile.is_zipfile(model_file):
        return "the checkpoint is damaged (its model is missing or not a zip file), so it cannot be resumed"
    if resumable(settings_file, model_file, settings) is not None:
        return None
    try:
        saved = json.loads(settings_file.read_text())
    except (OSError, ValueError):
        return f"the checkpoint is damaged ({settings_file.name} is unreadable), so it cannot be resumed"
    if not isinstance(saved, dict):
        return f"the checkpoint is damaged ({settings_file.name} is not a record), so it cannot be resumed"
    rules = (saved.get("split_rule") or "scenes", settings.get("split_rule") or "scenes")  # scenes records none
    # Another split rule trains on other scenes too: named as such, not as scenes added.
    differ = [f"split rule {rules[0]!r}, not {rules[1]!r}"] if rules[0] != rules[1] else []
    skip = ("dataset", "env_seeds", "split_rule") + (("train_scenes",) if differ else ())
    differ += [
        "another train split (scenes added or removed)"
        if key == "train_scenes"
        else f"{key} {saved.get(key)!r}, not {settings[key]!r}"
        for key in settings
        if key in saved and saved[key] != settings[key] and key not in skip
    ]
    differ += ["another dataset"] if saved.get("dataset") not in (settings["dataset"], "/", None) else []
    return f"it is the checkpoint of another run ({'; '.join(differ[:3]) or 'older settings'}), which this one cannot resume"


def load_checkpoint(algorithm: Any, model_file: Path, env: Any, device: str) -> Any:
    """Load a checkpoint's model with its SB3 ``algorithm`` class, a damaged one as one line with
    both ways on.

    Raises:
        UserError: when SB3 cannot read it.
    """
    try:
        return algorithm.load(model_file, env=env, device=device)
    except Exception as error:  # zipfile, pickle, torch and SB3 each raise their own
        if isinstance(error, (MemoryError, OSError)):
            raise
        raise UserError(
            f"{model_file}: the checkpoint is damaged ({type(error).__name__}: {error}), so it "
            "cannot be resumed: run again with --force to discard it and start over, or stop "
            "here to keep it"
        ) from None


def save_model(model: Any, path: Path) -> None:
    """Save an SB3 model atomically (a kill mid-save leaves the previous file). A stop asked for
    while it saves (Ctrl-C, SIGTERM) takes effect once the file is in place: cut inside torch's
    zip writer, it would surface as torch's RuntimeError instead of a stop."""
    with stops_held(), atomic_output(path, "wb") as handle:
        model.save(handle)


class Sittings:
    """The sittings of one training run: for each, the code that ran, torch's thread count (a run
    trains the same weights bit for bit only on the same count), the steps and the seconds. A run
    resumed from a checkpoint keeps the sittings before it, so its record says how it was made
    (and whether the code or the threads changed between sittings)."""

    def __init__(self, earlier: list[dict[str, Any]], first_step: int) -> None:
        import torch

        self.earlier, self.first_step, self.start = earlier, first_step, time.perf_counter()
        self.threads = torch.get_num_threads()

    def upto(self, step: int) -> list[dict[str, Any]]:
        """Every sitting, this one up to ``step``."""
        now = {
            "code": code_version(),
            "torch_threads": self.threads,
            "from_step": self.first_step,
            "to_step": step,
            "seconds": round(time.perf_counter() - self.start, 1),
        }
        return [*self.earlier, now]


class CheckpointEvery(BaseCallback):
    """Saves the model, the run's settings and its sittings every ``every`` environment steps."""

    def __init__(
        self,
        every: int,
        model_file: Path,
        settings_file: Path,
        settings: dict[str, Any],
        sittings: Sittings,
        curve: LearningCurve,
        selection: KeepBestOnTrain | None,
    ) -> None:
        super().__init__()
        self.every, self.model_file, self.settings_file, self.settings = every, model_file, settings_file, settings
        self.sittings, self.curve, self.selection = sittings, curve, selection
        self._last = 0

    def _on_training_start(self) -> None:
        self._last = last_multiple(self.model.num_timesteps, self.every)

    def _on_step(self) -> bool:
        return True

    def _on_rollout_start(self) -> None:
        # Between rollouts, after the last one's update: a checkpoint inside a rollout holds the
        # model without it, and the resumed run would lose those steps' update but count them.
        if self.model.num_timesteps - self._last >= self.every:
            self._last = last_multiple(self.model.num_timesteps, self.every)
            with stops_held():  # the model and its settings file, both or neither, before a stop
                self._save()

    def _save(self) -> None:
        save_model(self.model, self.model_file)
        scores = self.selection.scores if self.selection else []
        write_json_atomic(
            self.settings_file,
            {
                **self.settings,
                "timesteps_done": int(self.model.num_timesteps),
                "sittings": self.sittings.upto(int(self.model.num_timesteps)),
                "curve": self.curve.points,
                "selection": scores,
            },
        )
        if self.selection:  # the checkpoint now names the best snapshot: older ones can go
            self.selection.prune()

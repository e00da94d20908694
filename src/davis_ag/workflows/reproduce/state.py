"""A ``davis-ag reproduce`` run's records (``OUT/state.json``) as a typed model: its configuration,
each stage's time and note, each group's evaluation and each group's scene folders.

The run writes it after every stage; ``--status``, ``--rewrite-results`` and the pages read it.
Each group's evaluation is kept as :class:`~davis_ag.benchmark.results.EvaluationResults` without
its episodes (the whole file, episodes included, stays in ``OUT/results/GROUP.json``), so the
state stays small. A state written before this model (each evaluation kept as a reduced summary)
is read by taking each evaluation again from its results file.
"""

from __future__ import annotations

import json
import os
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from davis_ag.benchmark.results import EvaluationResults, PairedGap, load_results
from davis_ag.errors import UserError
from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.groups import GROUPS, SCENARIO_CROPS, group_key


class StageRecord(BaseModel):
    """One stage's record, rewritten by every sitting that passes the stage.

    Attributes:
        seconds: Its wall time as the sitting that wrote it measured it (the run's clock adds
            up every sitting: :mod:`davis_ag.workflows.reproduce.clock`).
        note: What it did, in words (``split test``, a validation's summary).
        code: The code version that did its work (None: a record from before it was kept).
        check_seconds: A validation's own time for one whole check.
        stamp: A sound validation's stamp of its files and validator
            (:func:`davis_ag.data.validation_stamp.validation_stamp`): the same stamp is not
            validated again.
    """

    model_config = ConfigDict(extra="forbid")

    seconds: float
    note: str = ""
    code: str | None = None
    check_seconds: float | None = None
    stamp: str | None = None


class RunState(BaseModel):
    """A run's records: what ``OUT/state.json`` holds.

    Attributes:
        config: The run's configuration as JSON (``dataclasses.asdict`` of its
            :class:`~davis_ag.workflows.reproduce.configs.ReproduceConfig`; :func:`run_config`
            reads it back); None before a run started.
        stages: Each stage's record, by name (``sp-strawberry: train A2C``), in the run's order.
        results: Each evaluated group's results without episodes, by
            :meth:`~davis_ag.workflows.reproduce.configs.ReproduceConfig.result_key`.
        scene_folders: Each group's scene folders (``Single-Strawberry/000``), by group.
    """

    model_config = ConfigDict(extra="forbid")

    config: dict[str, Any] | None = None
    stages: dict[str, StageRecord] = Field(default_factory=dict)
    results: dict[str, EvaluationResults] = Field(default_factory=dict)
    scene_folders: dict[str, list[str]] = Field(default_factory=dict)

    @classmethod
    def load(cls, path: str | os.PathLike[str]) -> RunState:
        """Read a run's ``state.json``: an empty state where there is none yet.

        An evaluation kept in an older form (a reduced summary) is read again from the group's
        results file beside it (``results/GROUP.json``); where that is missing or not sound, it
        is left out, so the run evaluates the group again.

        Args:
            path: The ``state.json`` file.

        Returns:
            The run's state.

        Raises:
            UserError: for a file that is there but not a run's state (damaged, or not JSON): a
                run that took it for no run would start its records afresh over it.
        """
        path = Path(path)
        if not path.exists():
            return cls()
        damaged = UserError(
            f"{path}: not a reproduce state file (damaged or not JSON): move it aside to start the "
            "run's records afresh (scenes and models already made are reused)"
        )
        try:
            data = json.loads(path.read_text())
        except (OSError, ValueError):
            raise damaged from None
        if not isinstance(data, dict) or not isinstance(data.get("results", {}), dict):
            raise damaged
        stored: dict[str, Any] = data.pop("results", {})
        data.pop("scenes", None)  # runs before 0.2.0 timed their scenes here; clock.json does now
        try:
            state = cls.model_validate(data)
        except ValidationError:
            raise damaged from None
        for key, entry in stored.items():
            results = _stored_results(entry, _results_file(state, path, key))
            if results is not None:
                state.results[key] = results
        return state

    def save(self, path: str | os.PathLike[str]) -> Path:
        """Write the state to ``path`` as indented JSON, atomically.

        Args:
            path: The ``state.json`` file.

        Returns:
            ``path``.
        """
        from davis_ag.atomic_files import write_json_atomic

        data: dict[str, Any] = {} if self.config is None else {"config": self.config}
        data["stages"] = {
            name: record.model_dump(mode="json", exclude_none=True) for name, record in self.stages.items()
        }
        data["results"] = {key: results.as_json() for key, results in self.results.items()}
        data["scene_folders"] = self.scene_folders
        return write_json_atomic(path, data, indent=2)


def run_config(state: RunState, path: Path) -> ReproduceConfig:
    """The configuration a run's ``state.json`` records.

    Args:
        state: The run's state.
        path: Its ``state.json``, for the message.

    Returns:
        The run's configuration (a run from before PPO trained A2C alone).

    Raises:
        UserError: when ``state.json`` records none (no run started in that folder), or one that
            is damaged.
    """
    if not state.config:
        raise UserError(f"{path}: no reproduce run started there (no configuration in its state.json)")
    try:
        saved = dict(state.config)
        saved.update(
            size=tuple(saved["size"]),
            mp_extent=tuple(saved["mp_extent"]) if saved.get("mp_extent") else None,
            learners=tuple(saved.get("learners", ("a2c",))),  # a run from before PPO trained A2C alone
            pairs=tuple(tuple(pair) for pair in saved.get("pairs", SCENARIO_CROPS)),
            robots=tuple(saved.get("robots", ())),
        )
        return ReproduceConfig(**saved)
    except (TypeError, KeyError, ValueError) as error:
        raise UserError(
            f"{path}: its configuration is damaged ({type(error).__name__}: {error}): move the file aside "
            "to start the run's records afresh"
        ) from None


def without_episodes(results: EvaluationResults) -> EvaluationResults:
    """An evaluation as the run's state keeps it: every policy's episodes left out.

    Each learner's (A2C's, PPO's) gap to the Best fixed action is the evaluation's own
    (``PolicyResult.paired``); where the evaluation has none, or one from before the interval
    over scenes, it is made from the episodes first
    (:func:`davis_ag.benchmark.paired.a2c_against_best_fixed`, with the evaluation's seed).

    Args:
        results: The evaluation, as its results file holds it.

    Returns:
        A copy without episodes; ``results`` is left as it was.
    """
    from davis_ag.benchmark.exact import BEST_FIXED
    from davis_ag.benchmark.paired import a2c_against_best_fixed, lacks_scene_interval
    from davis_ag.workflows.reproduce.learners import LEARNERS

    whole: dict[str, Any] | None = None
    policies = {}
    for name, policy in results.policies.items():
        paired = dict(policy.paired)
        kept = paired.get(BEST_FIXED)
        if name in LEARNERS and (kept is None or lacks_scene_interval(kept.model_dump(exclude_none=True))):
            whole = results.as_json() if whole is None else whole
            made = a2c_against_best_fixed(whole, name)
            if made is not None:
                paired[BEST_FIXED] = PairedGap.model_validate(made)
        policies[name] = policy.model_copy(update={"episodes": None, "paired": paired})
    return results.model_copy(update={"policies": policies}).model_copy(deep=True)


def _results_file(state: RunState, path: Path, key: str) -> Path:
    """The results file (``results/GROUP.json`` beside ``state.json``) of the evaluation that the
    state keeps under ``key``: by scenario (``sp``) in Table 4's runs, by group in the crops run."""
    try:
        config = run_config(state, path)
        groups = {config.result_key(scenario, crop): group_key(scenario, crop) for scenario, crop in config.pairs}
    except UserError:  # no configuration to read it from: Table 4's groups, else the key is the group
        groups = {}
    return path.parent / "results" / f"{groups.get(key) or GROUPS.get(key, key)}.json"


def _stored_results(entry: Any, results_file: Path) -> EvaluationResults | None:
    """An evaluation as the state keeps it; one kept in an older form, from its results file."""
    try:
        return EvaluationResults.model_validate(entry)
    except ValidationError:
        pass
    try:
        return without_episodes(load_results(results_file))
    except UserError:  # missing, damaged or edited: the run evaluates the group again
        return None

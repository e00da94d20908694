"""The learners' stage of ``davis-ag reproduce``: each learner (the paper's A2C, PPO beside it)
trained on the train split with the same budget, reused when finished, resumed when killed."""

from __future__ import annotations

import json
import time
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import write_json_atomic

#: The learners a run may train, as their rows are named (the paper's A2C first).
LEARNERS = ("A2C", "PPO")
#: Which snapshot of each learner's run is evaluated: the best on the train split
#: (:mod:`davis_ag.benchmark.selection`).
KEEP = "best-train"


def load_json_object(path: Path) -> dict[str, Any]:
    """A JSON file's object, or {} when it is missing, unreadable or not an object."""
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return {}
    return data if isinstance(data, dict) else {}


def model_path(out: Path, group: str, learner: str = "A2C") -> Path:
    """Where a run keeps a group's model of a learner (``models/a2c_<group>.zip``, ``ppo_...``)."""
    return out / "models" / f"{learner.lower()}_{group}.zip"


def training_record(out: Path | None, group: str, learner: str = "A2C") -> dict[str, Any]:
    """A run's training record of a learner (A2C by default) for a group; {} without a run
    folder or a record."""
    from davis_ag.benchmark.training_record import training_record_path

    return load_json_object(training_record_path(model_path(out, group, learner))) if out else {}


def learner_stamp(algo: str, timesteps: int, settings: dict[str, Any] | None = None) -> dict[str, Any]:
    """What a finished model of ``algo`` must have been made with to be reused (its stamp
    ``MODEL.json``): steps, settings (``settings``, default ours: A2C's tuned ones, the zoo's Atari
    settings for PPO) and keep rule. A2C's stamp keeps the keys it had before PPO, so its models are reused."""
    from davis_ag.benchmark.algorithms import A2C_SETTINGS, SB3_SETTINGS

    if algo == "a2c":
        return {"timesteps": timesteps, "a2c_settings": A2C_SETTINGS if settings is None else settings, "keep": KEEP}
    chosen = SB3_SETTINGS[algo] if settings is None else {**SB3_SETTINGS[algo], **settings}
    return {"algorithm": algo.upper(), "timesteps": timesteps, "sb3_settings": chosen, "keep": KEEP}


def train_learner(
    algo: str,
    root: Path,
    scenario: str,
    crop: str,
    model: Path,
    timesteps: int,
    config: Any,
    settings: dict[str, Any] | None = None,
    **train_kwargs: Any,
) -> float | None:
    """Train one learner of a run on the train split, unless its finished model is reusable.

    A model made with other settings, steps or keep rule (or before they were recorded: those
    kept the last snapshot) is trained anew; a killed run resumes from its checkpoint, which
    :func:`davis_ag.benchmark.training.train_agent` keeps beside the model.

    Args:
        algo: ``a2c`` or ``ppo`` (:data:`davis_ag.benchmark.algorithms.ALGORITHMS`).
        root: The dataset root.
        scenario, crop: What to train on.
        model: The model's ``.zip`` (:func:`model_path`).
        timesteps: Environment steps.
        config: The run's :class:`~davis_ag.workflows.reproduce.configs.ReproduceConfig` (seed, environments).
        settings: The algorithm's settings over ours (tests: a short PPO rollout); None: ours. One
            that carries ``n_envs`` (``zoo-atari``) trains with that many environments.
        **train_kwargs: Passed on to ``train_agent`` (tests: a small network, a callback).

    Returns:
        The seconds this sitting trained, or None when the finished model was reused.
    """
    from davis_ag.benchmark.training import train_agent

    stamp = model.with_suffix(".json")
    made = {"keep": "last", **load_json_object(stamp)}
    wanted = learner_stamp(algo, timesteps, settings)
    # A setting set that carries its environments (zoo-atari's 16) trains with them, not the run's.
    n_envs = (settings or {}).get("n_envs", config.n_envs)
    if (
        model.is_file()
        and all(made.get(k) == v for k, v in wanted.items())
        and _split_unchanged(model, root, scenario, crop, config.split_rule)
        and _made_as_configured(model, config, train_kwargs.get("arch", "paper"), n_envs)
    ):
        return None
    network = "the paper's network" + (" as features extractor" if algo != "a2c" else "")
    print(f"training {algo.upper()} ({network}) on {scenario} train split for {timesteps} steps", flush=True)
    start = time.perf_counter()
    train_agent(
        root,
        scenario,
        total_timesteps=timesteps,
        seed=config.seed,
        out_path=model,
        n_envs=n_envs,
        crop=crop,
        device="cpu",
        keep=KEEP,
        algo=algo,
        settings="ours" if settings is None else settings,
        force=True,
        split_rule=config.split_rule,
        **train_kwargs,
    )  # its own work folder: a checkpoint of other settings is redone, as said above
    seconds = time.perf_counter() - start
    write_json_atomic(stamp, {**wanted, "seconds": seconds})
    return seconds


def _made_as_configured(model: Path, config: Any, arch: str, n_envs: int) -> bool:
    """Whether a finished model's training record names the run's seed, number of environments
    (``n_envs``: the run's, or its setting set's) and network, which the page states for it; a
    model without a record is taken as it is."""
    from davis_ag.benchmark.training_record import training_record_path

    record = load_json_object(training_record_path(model))
    wanted = {"seed": config.seed, "n_envs": n_envs, "arch": arch}
    return all(record.get(key, value) == value for key, value in wanted.items())


def _split_unchanged(model: Path, root: Path, scenario: str, crop: str, rule: str = "scenes") -> bool:
    """Whether a finished model was trained on today's train split under the run's split rule (a
    group that grew moves scenes between the splits); a model from before the scenes were
    recorded is taken as it is."""
    from davis_ag.benchmark.splits import as_dataset, select_scenes
    from davis_ag.benchmark.training_record import recorded_split_rule, recorded_train_scenes

    trained_on = recorded_train_scenes(model)
    if trained_on is None:
        return True
    chosen = select_scenes(as_dataset(root), scenario, "train", crop, rule)
    return (recorded_split_rule(model) or "scenes") == rule and trained_on == sorted(s.id for s in chosen)

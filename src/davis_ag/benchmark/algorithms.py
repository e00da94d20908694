"""The algorithms ``davis-ag train --algo`` trains and their settings: the paper's A2C (its settings
chosen on the train split), PPO and DQN (Stable-Baselines3's defaults), and sb3-contrib's
algorithms for a discrete action space (RecurrentPPO, QR-DQN, TRPO, MaskablePPO; the ``contrib``
extra)."""

from __future__ import annotations

from typing import Any

from davis_ag.errors import UserError

#: The algorithms :func:`davis_ag.benchmark.training.train_agent` trains (``davis-ag train --algo``),
#: and the class each names (:func:`davis_ag.benchmark.sb3_models.algorithm_class`).
CLASS_NAMES: dict[str, str] = {
    "a2c": "A2C",
    "ppo": "PPO",
    "dqn": "DQN",
    "recurrentppo": "RecurrentPPO",
    "qrdqn": "QRDQN",
    "trpo": "TRPO",
    "maskableppo": "MaskablePPO",
}
ALGORITHMS: tuple[str, ...] = tuple(CLASS_NAMES)
#: The policy an algorithm trains on images, where it is not SB3's ``CnnPolicy``.
POLICY_NAMES: dict[str, str] = {"recurrentppo": "CnnLstmPolicy"}


def algorithm_of(algo: str) -> Any:
    """The class ``davis-ag train --algo`` names (sb3-contrib's: one line naming the extra when missing)."""
    from davis_ag.benchmark.sb3_models import algorithm_class

    return algorithm_class(CLASS_NAMES[algo])


#: PPO's and DQN's settings on top of Stable-Baselines3's defaults. PPO: RL Baselines3 Zoo's
#: settings for Atari (``hyperparams/ppo.yml``, the zoo's set for a ``CnnPolicy`` on images with
#: our 8 environments), not SB3's defaults, which are made for small vector observations: with
#: 8 environments SB3's 2,048-step rollouts leave 300K steps 19 policy updates (the zoo's
#: 128-step rollouts, 293: whole rollouts until the budget is reached), and its 10 epochs of 64-sample batches cost more per step than the
#: zoo's 4 epochs of 256 (``make bench``'s training table, docs/performance.md). ``lin_X``: X falling
#: linearly to 0 over the run (:func:`sb3_arguments`). DQN: SB3's replay
#: buffer holds 1M transitions, which at 224x224x4 bytes per observation (twice: the next one
#: too) is 400 GB; 10,000 keep it near 2 GB (one copy, ``optimize_memory_usage``, which needs
#: ``handle_timeout_termination`` off: our episodes end with terminated, never truncated).
#: Not tuned: the paper trains A2C only, and no change was measured on the train split.
SB3_SETTINGS: dict[str, dict[str, Any]] = {
    "ppo": {
        "n_steps": 128,
        "n_epochs": 4,
        "batch_size": 256,
        "learning_rate": "lin_2.5e-4",
        "clip_range": "lin_0.1",
        "vf_coef": 0.5,
        "ent_coef": 0.01,
    },
    "dqn": {
        "buffer_size": 10_000,
        "optimize_memory_usage": True,
        "replay_buffer_kwargs": {"handle_timeout_termination": False},
    },
}
#: QR-DQN's replay buffer as DQN's (the same 224x224x4 observations); the other contrib algorithms
#: train with sb3-contrib's defaults and ``--set``.
SB3_SETTINGS["qrdqn"] = dict(SB3_SETTINGS["dqn"])
#: The settings a ``lin_X`` value may be given to: those SB3 takes as a schedule.
SCHEDULES = ("learning_rate", "clip_range", "clip_range_vf")


def sb3_arguments(settings: dict[str, Any]) -> dict[str, Any]:
    """The keyword arguments SB3 takes for a setting set: each ``lin_X`` (RL Baselines3 Zoo's
    notation, kept as text so settings stay JSON in records and checkpoints) as SB3's own
    schedule from X at the start to 0 at the end, an optimiser named in ``policy_kwargs`` as its
    class (:data:`OPTIMIZERS`), and without ``n_envs`` (the run's, :func:`environments_of`).

    Raises:
        UserError: for a ``lin_`` value that is not a number or is given to another setting.
    """
    import importlib

    from stable_baselines3.common.utils import LinearSchedule

    arguments = {key: value for key, value in settings.items() if key != "n_envs"}  # the run's, not SB3's
    if isinstance(chosen := settings.get("policy_kwargs"), dict) and "optimizer_class" in chosen:
        module, name = OPTIMIZERS[chosen["optimizer_class"]]
        arguments["policy_kwargs"] = {**chosen, "optimizer_class": getattr(importlib.import_module(module), name)}
    for key, value in settings.items():
        if not (isinstance(value, str) and value.startswith("lin_")):
            continue
        try:
            start = float(value.removeprefix("lin_"))
        except ValueError:
            start = None
        if key not in SCHEDULES or start is None:
            raise UserError(f"setting {key}={value}: lin_X (X a number) is for {', '.join(SCHEDULES)} only")
        arguments[key] = LinearSchedule(start, 0.0, 1.0)
    return arguments


#: The A2C settings we train with, on top of Stable-Baselines3's defaults (the paper gives none).
#: ``normalize_advantage`` scales each update's advantages to unit variance, so the size of the
#: reward (``max(OER_tau - OER_0, 0)**2``, about .02 on average) stops setting the step size;
#: ``ent_coef=0.01`` is then the usual entropy bonus, which keeps the policy from turning into a
#: point mass on one move over a long run. Measured on the train split only
#: (docs/benchmark.md): after enough steps A2C learns policies whose most likely move differs
#: from start to start with these settings, with SB3's defaults and with the bonus alone (which
#: left the flattest policy and the lowest sampled score); these learnt a little faster early on.
#: What made the evaluated A2C a fixed action was chiefly too little training played
#: deterministically (see ``DETERMINISTIC_PLAY`` in policies.py).
A2C_SETTINGS: dict[str, Any] = {"ent_coef": 0.01, "normalize_advantage": True}
#: Stable-Baselines3's own A2C defaults for the settings above (what ``--a2c-settings sb3`` trains).
SB3_DEFAULT_SETTINGS: dict[str, Any] = {"ent_coef": 0.0, "normalize_advantage": False}
#: RL Baselines3 Zoo's A2C for Atari (``hyperparams/a2c.yml``, its ``atari`` entry, the zoo's set
#: for a ``CnnPolicy`` on images): 16 environments, ``ent_coef=0.01``, ``vf_coef=0.25`` and SB3's
#: ``RMSpropTFLike`` optimiser (TensorFlow's RMSprop, as Stable Baselines 2 and OpenAI's baselines
#: trained A2C) with ``eps=1e-5``; everything else SB3's defaults. The optimiser is named by text
#: and the environments are a setting of the run, so the set stays JSON in records and checkpoints
#: (:func:`sb3_arguments` builds the class; :func:`environments_of` takes ``n_envs``).
ZOO_ATARI_SETTINGS: dict[str, Any] = {
    **SB3_DEFAULT_SETTINGS,
    "ent_coef": 0.01,
    "vf_coef": 0.25,
    "policy_kwargs": {"optimizer_class": "RMSpropTFLike", "optimizer_kwargs": {"eps": 1e-5}},
    "n_envs": 16,
}
#: Named setting sets of :func:`davis_ag.benchmark.training.train_a2c`.
SETTINGS_PRESETS: dict[str, dict[str, Any]] = {
    "ours": A2C_SETTINGS,
    "sb3": SB3_DEFAULT_SETTINGS,
    "zoo-atari": ZOO_ATARI_SETTINGS,
}
#: SB3 A2C keyword arguments a setting set may change, and ``n_envs``, the run's environments.
TUNABLE = (
    "ent_coef",
    "normalize_advantage",
    "learning_rate",
    "n_steps",
    "gamma",
    "vf_coef",
    "max_grad_norm",
    "gae_lambda",
    "policy_kwargs",
    "n_envs",
)
#: Environments a run trains with when neither it nor its setting set says.
DEFAULT_N_ENVS = 8
#: The optimisers a setting set may name in ``policy_kwargs`` (``optimizer_class``), by the
#: module and class :func:`sb3_arguments` imports: SB3's TensorFlow-like RMSprop and torch's own.
OPTIMIZERS: dict[str, tuple[str, str]] = {
    "RMSpropTFLike": ("stable_baselines3.common.sb2_compat.rmsprop_tf_like", "RMSpropTFLike"),
    "RMSprop": ("torch.optim", "RMSprop"),
    "Adam": ("torch.optim", "Adam"),
}
#: What ``policy_kwargs`` may hold in a setting set: the optimiser (the network is ``--arch``'s).
POLICY_SETTINGS = ("optimizer_class", "optimizer_kwargs")


def environments_of(settings: dict[str, Any], n_envs: int | None) -> int:
    """The environments a run trains with: ``n_envs`` where given, else its setting set's
    ``n_envs`` (``zoo-atari``: 16), else :data:`DEFAULT_N_ENVS`. A set that carries ``n_envs`` is
    given the number that runs, so its record says what trained.

    Args:
        settings: The resolved setting set (changed in place where it carries ``n_envs``).
        n_envs: The run's number (``--n-envs``), None where not given.

    Returns:
        The number of environments.
    """
    carried = settings.get("n_envs")
    chosen = n_envs if n_envs is not None else (carried or DEFAULT_N_ENVS)
    if carried is not None:
        settings["n_envs"] = chosen
    return int(chosen)


def check_policy_settings(algo: str, value: Any) -> None:
    """Refuse a ``policy_kwargs`` setting other than a known optimiser and its keyword arguments.

    Raises:
        UserError: naming what is wrong and what may be given.
    """
    shown = f"{algo.upper()} setting policy_kwargs={value!r}"
    if not isinstance(value, dict) or any(key not in POLICY_SETTINGS for key in value):
        raise UserError(f"{shown}: give a dict of {', '.join(POLICY_SETTINGS)} (the network is --arch's)")
    if value.get("optimizer_class", "RMSprop") not in OPTIMIZERS:
        raise UserError(f"{shown}: optimizer_class must be one of {', '.join(OPTIMIZERS)}")
    if not isinstance(value.get("optimizer_kwargs", {}), dict):
        raise UserError(f'{shown}: optimizer_kwargs must be a dict, e.g. {{"eps": 1e-5}}')


#: Settings that count something: whole numbers, at least 1. Every other number must not be
#: negative, but ``sde_sample_freq`` (-1 by default: never resample).
COUNTS = ("n_steps", "batch_size", "n_epochs", "buffer_size", "gradient_steps", "target_update_interval", "train_freq")


def check_setting_values(algo: str, settings: dict[str, Any]) -> None:
    """Refuse a setting whose value SB3 would take and then crash on, minutes later inside
    ``learn``: a value of another kind than SB3's default (``n_steps=abc``, ``gamma=yes``), a
    count below 1, a negative rate or coefficient, or a number that is not finite.

    Args:
        algo: A name of :data:`ALGORITHMS`.
        settings: The settings given (``--set`` or a dict), before SB3's defaults fill the rest.

    Raises:
        UserError: naming the setting, its value and what it must be.
    """
    import inspect
    import math

    defaults = {k: v.default for k, v in inspect.signature(algorithm_of(algo)).parameters.items()}
    for key, value in settings.items():
        default = defaults.get(key)
        if key == "policy_kwargs":
            check_policy_settings(algo, value)
            continue
        if key == "n_envs" and (isinstance(value, bool) or not isinstance(value, int) or value < 1):
            raise UserError(f"{algo.upper()} setting n_envs={value!r}: must be a whole number, at least 1")
        if (isinstance(value, str) and value.startswith("lin_")) or default is None or isinstance(value, dict):
            continue  # schedules are checked by sb3_arguments; None defaults take many kinds
        shown = f"{algo.upper()} setting {key}={value!r}"
        if isinstance(default, bool):
            if not isinstance(value, bool):
                raise UserError(f"{shown}: must be true or false")
        elif isinstance(default, (int, float)):
            if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value):
                raise UserError(f"{shown}: must be a number")
            if key in COUNTS and (not isinstance(value, int) or value < 1):
                raise UserError(f"{shown}: must be a whole number, at least 1")
            if key not in (*COUNTS, "sde_sample_freq") and value < 0:
                raise UserError(f"{shown}: must not be negative")


def resolve_settings(settings: str | dict[str, Any]) -> dict[str, Any]:
    """The SB3 A2C arguments a setting set names (see :data:`SETTINGS_PRESETS`).

    Raises:
        UserError: for an unknown preset or an argument outside :data:`TUNABLE`.
    """
    import copy

    if isinstance(settings, str):
        if settings not in SETTINGS_PRESETS:
            raise UserError(f"unknown A2C settings {settings!r}: choose one of {', '.join(SETTINGS_PRESETS)}")
        return copy.deepcopy(SETTINGS_PRESETS[settings])  # a run's record never shares the preset's dicts
    wrong = [k for k in settings if k not in TUNABLE]
    if wrong:
        raise UserError(f"A2C setting {wrong[0]!r} cannot be changed here: use {', '.join(TUNABLE)}")
    check_setting_values("a2c", settings)
    return {**SB3_DEFAULT_SETTINGS, **settings}


def resolve_sb3_settings(algo: str, settings: str | dict[str, Any]) -> dict[str, Any]:
    """PPO's or DQN's settings: :data:`SB3_SETTINGS` (``"ours"``), or those with a dict of the
    algorithm's own keyword arguments over them (short runs in tests: a shorter rollout).

    Raises:
        UserError: for an A2C preset other than ``ours``, or an argument the algorithm lacks.
    """
    import inspect

    if isinstance(settings, str):
        if settings != "ours":
            raise UserError(
                f"--a2c-settings {settings} is for --algo a2c; {algo} trains with its own settings and --set"
            )
        return dict(SB3_SETTINGS.get(algo, {}))
    known = inspect.signature(algorithm_of(algo)).parameters
    wrong = [k for k in settings if k not in known or k in ("policy", "env", "seed", "device", "verbose")]
    if wrong:
        raise UserError(f"{algo.upper()} setting {wrong[0]!r} cannot be changed here")
    check_setting_values(algo, settings)
    return {**SB3_SETTINGS.get(algo, {}), **settings}


def console_logger(verbose: int) -> Any:
    """The logger a model learns with: SB3's table on stdout when ``verbose``, else nothing.

    Set on every model before ``learn``: without one, SB3 makes a fresh empty ``/tmp/SB3-<time>``
    folder on every ``learn`` call and never removes it (a thousand a day under the test suite).

    Args:
        verbose: SB3 verbosity; 0 writes nothing.

    Returns:
        A ``stable_baselines3.common.logger.Logger`` for ``model.set_logger``.
    """
    import sys

    from stable_baselines3.common.logger import HumanOutputFormat, Logger

    return Logger(folder=None, output_formats=[HumanOutputFormat(sys.stdout)] if verbose else [])

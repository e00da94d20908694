"""The algorithms ``davis-ag train --algo`` trains besides the paper's A2C, and their settings
(A2C's own, tuned on the train split, are in :mod:`davis_ag.benchmark.training`)."""

from __future__ import annotations

from typing import Any

from davis_ag.errors import UserError

#: The algorithms :func:`davis_ag.benchmark.training.train_agent` trains (``davis-ag train --algo``).
ALGORITHMS: tuple[str, ...] = ("a2c", "ppo", "dqn")
#: PPO's and DQN's settings on top of Stable-Baselines3's defaults. PPO: none. DQN: SB3's replay
#: buffer holds 1M transitions, which at 224x224x4 bytes per observation (twice: the next one
#: too) is 400 GB; 10,000 keep it near 2 GB (one copy, ``optimize_memory_usage``, which needs
#: ``handle_timeout_termination`` off: our episodes end with terminated, never truncated).
#: Not tuned: the paper trains A2C only, and no change was measured on the train split.
SB3_SETTINGS: dict[str, dict[str, Any]] = {
    "ppo": {},
    "dqn": {
        "buffer_size": 10_000,
        "optimize_memory_usage": True,
        "replay_buffer_kwargs": {"handle_timeout_termination": False},
    },
}


def resolve_sb3_settings(algo: str, settings: str | dict[str, Any]) -> dict[str, Any]:
    """PPO's or DQN's settings: :data:`SB3_SETTINGS` (``"ours"``), or those with a dict of the
    algorithm's own keyword arguments over them (short runs in tests: a shorter rollout).

    Raises:
        UserError: for an A2C preset other than ``ours``, or an argument the algorithm lacks.
    """
    import inspect

    import stable_baselines3

    if isinstance(settings, str):
        if settings != "ours":
            raise UserError(f"--a2c-settings {settings} is for --algo a2c; {algo} trains with SB3's defaults")
        return dict(SB3_SETTINGS[algo])
    known = inspect.signature(getattr(stable_baselines3, algo.upper())).parameters
    wrong = [k for k in settings if k not in known or k in ("policy", "env", "seed", "device", "verbose")]
    if wrong:
        raise UserError(f"{algo.upper()} setting {wrong[0]!r} cannot be changed here")
    return {**SB3_SETTINGS[algo], **settings}

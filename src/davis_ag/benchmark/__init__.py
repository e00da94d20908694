"""Stage 9, the benchmark: DAVIS-Ag as a Gymnasium environment, target visibility maximisation (``davis_ag/TVM-v0``).

Importing this package registers the environment::

    import gymnasium, davis_ag.benchmark
    env = gymnasium.make("davis_ag/TVM-v0", dataset="data/", scenario="sp", split="train")

To score policies of your own beside the baselines (section V-D's protocol, any environment)::

    results = davis_ag.benchmark.evaluate([my_policy], dataset="data/", scenario="sp")

Beside it, ``davis_ag/TVMContinuous-v0`` (:mod:`davis_ag.live.tvm_continuous`): the same task with
a continuous camera pose, drawn live from regrown scenes. Both are registered by name
(:mod:`davis_ag.environments`), so nothing of it (Helios, the renderer) loads until it is made.
"""

from __future__ import annotations

import importlib
import time
from typing import Any

import gymnasium as gym
import numpy as np

from davis_ag.benchmark.cache import OBS_SIZE
from davis_ag.benchmark.tvm import MAX_START_OER, TVMEnv
from davis_ag.environments import CONTINUOUS_ID, TVM_ID, register_environments

#: All grid environments this package registers (tests parametrize over it).
ENV_IDS: tuple[str, ...] = (TVM_ID,)

register_environments()


def benchmark_steps(env: gym.Env, n: int = 20_000, seed: int = 0) -> float:
    """Measure environment steps per second with uniformly random actions.

    Resets (not timed separately: they are part of the rate, as in training) whenever an
    episode ends. Actions are drawn before the clock starts so only the environment is timed.

    Args:
        env: A TVM environment (wrapped or not).
        n: Steps to time.
        seed: Seeds the first reset and the action draw.

    Returns:
        Steps per second.
    """
    space = env.action_space
    assert isinstance(space, gym.spaces.Discrete)  # the grid's moves
    actions = np.random.default_rng(seed).integers(space.n, size=n)
    env.reset(seed=seed)
    start = time.perf_counter()
    for a in actions:
        _, _, terminated, truncated, _ = env.step(a)
        if terminated or truncated:
            env.reset()
    return n / (time.perf_counter() - start)


def __getattr__(name: str) -> Any:
    """``evaluate`` (:func:`davis_ag.benchmark.evaluation.evaluate`), loaded when first used: making
    an environment needs this package, not the evaluation (pydantic, the code version of
    :mod:`davis_ag.provenance`)."""
    if name == "evaluate":
        return importlib.import_module("davis_ag.benchmark.evaluation").evaluate
    raise AttributeError(f"module {__name__!r} has no attribute {name!r}")


#: What users call; the helpers (``benchmark_steps`` here, the scene cache in
#: :mod:`davis_ag.benchmark.cache`) are imported from their modules.
__all__ = [
    "CONTINUOUS_ID",
    "ENV_IDS",
    "MAX_START_OER",
    "OBS_SIZE",
    "TVM_ID",
    "TVMEnv",
    "evaluate",
]

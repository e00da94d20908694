"""Policies for TVMContinuous-v0: the heuristics that carry over to continuous moves, a greedy
look-ahead, and trained Stable-Baselines3 models.

Section IV-B's heuristics draw random grid moves from a set (LRD: left/right/done, UDD:
up/down/done, Rand: all). In continuous space "left or right" becomes a random sideways move of
random length, "up or down" a random climb, and Rand a uniform action; ``done`` has no
counterpart (a zero action stands still). Greedy has no grid counterpart: at each step it tries
``candidates`` random actions on the scene without slip (the environment's own renders, like the
grid's Oracle reads its tables) and takes the one that shows the target best. Every policy has
the :class:`davis_ag.benchmark.agents.Agent` interface (``reset(seed)``, ``act(obs, env)``) with
an action array in place of an index.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from davis_ag.errors import UserError
from davis_ag.live.tvm_continuous import TVMContinuousEnv

#: Which action components each heuristic moves (indices into the action: x, y, z, yaw, pitch).
HEURISTIC_AXES: dict[str, tuple[int, ...] | None] = {"LR": (0,), "UD": (2,), "Rand": None}


def continuous(env: gym.Env) -> TVMContinuousEnv:
    """The :class:`TVMContinuousEnv` under any wrappers.

    Raises:
        UserError: for another environment.
    """
    inner = getattr(env, "unwrapped", env)
    if not isinstance(inner, TVMContinuousEnv):
        raise UserError(f"expected a davis_ag/TVMContinuous-v0 environment, got {type(inner).__name__}")
    return inner


class RandomAxes:
    """Uniform random moves along some action components (LR, UD), or all of them (Rand)."""

    def __init__(self, name: str, axes: tuple[int, ...] | None, seed: int | None = None) -> None:
        """Args:
            name: Label in results tables.
            axes: Action components to draw (uniform in [-1, 1]); the rest stay 0. None: all.
            seed: Seed of the agent's generator until :meth:`reset` gets one.
        """
        self.name, self.axes = name, axes
        self._rng = np.random.default_rng(seed)

    def reset(self, seed: int | None = None) -> None:
        """Reseed (None keeps the stream)."""
        if seed is not None:
            self._rng = np.random.default_rng(seed)

    def act(self, obs: np.ndarray, env: gym.Env) -> np.ndarray:
        """One random action of the environment's shape."""
        size = continuous(env).action_space.shape[0]
        action = np.zeros(size, dtype=np.float32)
        axes = list(range(size)) if self.axes is None else list(self.axes)
        action[axes] = self._rng.uniform(-1.0, 1.0, size=len(axes))
        return action


class Greedy:
    """Tries ``candidates`` random actions (without slip) and plays the best for the target's OER;
    stands still when none beats staying."""

    def __init__(self, candidates: int = 8, seed: int | None = None) -> None:
        """Args:
            candidates: Actions tried per step (one render each).
            seed: Seed of the candidate draw.
        """
        self.name, self.candidates = "Greedy", int(candidates)
        self._rng = np.random.default_rng(seed)

    def reset(self, seed: int | None = None) -> None:
        """Reseed (None keeps the stream)."""
        if seed is not None:
            self._rng = np.random.default_rng(seed)

    def act(self, obs: np.ndarray, env: gym.Env) -> np.ndarray:
        """The best candidate action by the OER it would give."""
        inner = continuous(env)
        size = inner.action_space.shape[0]
        best, best_oer = np.zeros(size, dtype=np.float32), inner.oer
        for action in self._rng.uniform(-1.0, 1.0, size=(self.candidates, size)).astype(np.float32):
            reason, labels = inner.try_pose(inner.proposed(action, slip=False))
            if not reason and labels.oer[inner.target] > best_oer:
                best, best_oer = action, labels.oer[inner.target]
        return best


class ModelAgent:
    """A trained SB3 model (PPO or SAC) as a policy."""

    def __init__(self, model: Any, deterministic: bool = True) -> None:
        """Args:
            model: A loaded SB3 model, or the path of a PPO or SAC ``.zip``.
            deterministic: Take the mean action instead of sampling.

        Raises:
            UserError: when the file is missing or not a PPO/SAC model.
        """
        if isinstance(model, (str, os.PathLike)):
            model = load_model(Path(model))
        self.model, self.deterministic = model, deterministic
        self.name = type(model).__name__

    def reset(self, seed: int | None = None) -> None:
        """Nothing to reset: the policy is deterministic or sampled by SB3."""

    def check(self, env: gym.Env) -> None:
        """Refuse an environment whose action space the model was not trained for."""
        inner = continuous(env)
        if getattr(self.model.action_space, "shape", None) != inner.action_space.shape:
            raise UserError(f"the model takes actions of shape {self.model.action_space.shape}, the environment "
                            f"{inner.action_space.shape}: use a model trained with the same aim")

    def act(self, obs: np.ndarray, env: gym.Env) -> np.ndarray:
        """The model's action."""
        action, _ = self.model.predict(obs, deterministic=self.deterministic)
        return np.asarray(action, dtype=np.float32)


def load_model(path: Path) -> Any:
    """A saved PPO or SAC model.

    Raises:
        UserError: when the file is missing or holds neither.
    """
    from stable_baselines3 import PPO, SAC

    if not path.is_file():
        raise UserError(f"{path}: no such model file; train one with davis_ag.live.training.train_continuous")
    for algorithm in (PPO, SAC):
        try:
            return algorithm.load(path, device="cpu")
        except Exception:  # noqa: BLE001 - try the next algorithm; any failure means "not this one"
            continue
    raise UserError(f"{path}: not a Stable-Baselines3 PPO or SAC model")


#: Policy names :func:`build_policies` accepts (``Model`` also needs a model file).
POLICY_NAMES: tuple[str, ...] = ("LR", "UD", "Rand", "Greedy", "Model")


def build_policies(names: list[str], model: str | os.PathLike[str] | None = None,
                   deterministic: bool = True) -> list[Any]:
    """Policies by name, in order (case-insensitive; see :data:`POLICY_NAMES`); ``deterministic``
    is the model's (False: it samples its actions).

    Raises:
        UserError: for an unknown name, or ``Model`` without a model file.
    """
    policies: list[Any] = []
    for name in names:
        key = name.strip().lower()
        match = next((k for k in HEURISTIC_AXES if k.lower() == key), None)
        if match:
            policies.append(RandomAxes(match, HEURISTIC_AXES[match]))
        elif key == "greedy":
            policies.append(Greedy())
        elif key in ("model", "a2c", "ppo", "sac"):
            if model is None:
                raise UserError(f"policy {name} needs a trained model: pass --model model.zip")
            policies.append(ModelAgent(model, deterministic=deterministic))
        else:
            raise UserError(f"unknown continuous policy {name!r}: choose from {', '.join(POLICY_NAMES)}")
    return policies

"""Baselines for TVMContinuous-v0: the heuristics that carry over to continuous moves and a greedy
look-ahead. Trained models are :class:`davis_ag.benchmark.policies.ModelPolicy`, and every policy
is scored by :func:`davis_ag.benchmark.evaluation.evaluate_policies`, as on the grid.

Section V-B's heuristics draw random grid moves from a set (LRD: left/right/done, UDD:
up/down/done, Rand: all). In continuous space "left or right" becomes a random sideways move of
random length, "up or down" a random climb, and Rand a uniform action; ``done`` has no
counterpart (a zero action stands still). Greedy has no grid counterpart: at each step it tries
``candidates`` random actions on the scene without slip (the environment's own renders, like the
grid's Oracle reads its tables) and takes the one that shows the target best. Every policy is a
:class:`davis_ag.benchmark.policies.Policy` (``reset(seed)``, ``act(observation, info)``) with
an action array in place of an index; ``prepare(env)`` reads the environment first.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

import gymnasium as gym
import numpy as np

from davis_ag.benchmark.policies import Policy, SeededPolicy, baselines_by_name, unwrapped
from davis_ag.environments import CONTINUOUS_ID
from davis_ag.errors import UserError
from davis_ag.live.tvm_continuous import TVMContinuousEnv

#: Which action components each heuristic moves (indices into the action: x, y, z, yaw, pitch).
HEURISTIC_AXES: dict[str, tuple[int, ...] | None] = {"LR": (0,), "UD": (2,), "Rand": None}


def continuous(env: gym.Env) -> TVMContinuousEnv:
    """The :class:`TVMContinuousEnv` under any wrappers.

    Raises:
        UserError: for another environment.
    """
    return unwrapped(env, TVMContinuousEnv, CONTINUOUS_ID)


class RandomAxes(SeededPolicy):
    """Uniform random moves along some action components (LR, UD), or all of them (Rand)."""

    def __init__(self, name: str, axes: tuple[int, ...] | None, seed: int | None = None) -> None:
        """Args:
        name: Label in results tables.
        axes: Action components to draw (uniform in [-1, 1]); the rest stay 0. None: all.
        seed: Seed of the agent's generator until :meth:`reset` gets one.
        """
        super().__init__(seed)
        self.name, self.axes = name, axes
        self._size = 0

    def prepare(self, env: gym.Env) -> None:
        """Read the action's size (3 with ``aim="plant"``, 5 with ``"free"``)."""
        self._size = continuous(env).action_space.shape[0]

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        """One random action of the environment's shape."""
        size = self._size
        action = np.zeros(size, dtype=np.float32)
        axes = list(range(size)) if self.axes is None else list(self.axes)
        action[axes] = self._rng.uniform(-1.0, 1.0, size=len(axes))
        return action


class Greedy(SeededPolicy):
    """Tries ``candidates`` random actions (without slip) and plays the best for the target's OER;
    stands still when none beats staying."""

    def __init__(self, candidates: int = 8, seed: int | None = None) -> None:
        """Args:
        candidates: Actions tried per step (one render each).
        seed: Seed of the candidate draw.
        """
        super().__init__(seed)
        self.name, self.candidates = "Greedy", int(candidates)
        self._env: TVMContinuousEnv | None = None

    def prepare(self, env: gym.Env) -> None:
        """Keep the environment: its renders score the candidates."""
        self._env = continuous(env)

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> np.ndarray:
        """The best candidate action by the OER it would give."""
        inner = self._env
        if inner is None:
            raise UserError("Greedy plays only after prepare(env): evaluate it with davis_ag.benchmark.evaluate")
        size = inner.action_space.shape[0]
        best, best_oer = np.zeros(size, dtype=np.float32), inner.oer
        for action in self._rng.uniform(-1.0, 1.0, size=(self.candidates, size)).astype(np.float32):
            reason, labels = inner.try_pose(inner.proposed(action, slip=False))
            if not reason and labels is not None and labels.oer[inner.target] > best_oer:
                best, best_oer = action, labels.oer[inner.target]
        return best


#: Baseline names :func:`build_policies` accepts (trained models come from
#: :func:`davis_ag.benchmark.policies.policy_from_spec`), and what makes each.
BASELINES: dict[str, Callable[[], Policy]] = {
    **{name: partial(RandomAxes, name, axes) for name, axes in HEURISTIC_AXES.items()},
    "Greedy": Greedy,
}
POLICY_NAMES: tuple[str, ...] = tuple(BASELINES)


def build_policies(names: list[str]) -> list[Policy]:
    """Continuous baselines by name, in order (case-insensitive; see :data:`POLICY_NAMES`).

    Raises:
        UserError: for an unknown name (a trained model is a ``--policy MODEL.zip``).
    """
    return baselines_by_name(names, BASELINES, "continuous ")

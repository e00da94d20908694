"""The grid benchmark's baselines: the paper's heuristics (section V-B), every fixed action, and
an exact Oracle upper bound. Trained models are :class:`davis_ag.benchmark.policies.ModelPolicy`.

Every baseline is a :class:`davis_ag.benchmark.policies.Policy`: ``reset(seed)`` at the start of
an episode, then ``act(observation, info)`` once per step, returning an action index of the
environment. Their ``prepare(env)`` reads the environment's action names (SP and MP number them
differently); the Oracle also keeps the environment to read the episode's tables. None of them
looks at the image.
"""

from __future__ import annotations

from collections.abc import Callable
from functools import partial
from typing import Any

import gymnasium as gym
import numpy as np

from davis_ag.benchmark.exact import action_probabilities
from davis_ag.benchmark.policies import Policy, SeededPolicy, baselines_by_name, unwrapped
from davis_ag.benchmark.tvm import TVMEnv
from davis_ag.environments import TVM_ID
from davis_ag.errors import UserError

#: Section V-B action sets by agent name. Rand uses every action of the environment, which in
#: MP includes rotate_cw and rotate_ccw.
HEURISTIC_ACTIONS: dict[str, tuple[str, ...] | None] = {
    "LRD": ("left", "right", "done"),
    "UDD": ("up", "down", "done"),
    "Rand": None,
}


def tvm(env: gym.Env) -> TVMEnv:
    """The :class:`TVMEnv` under any wrappers.

    Raises:
        UserError: when ``env`` is not a TVM environment.
    """
    return unwrapped(env, TVMEnv, TVM_ID)


class HeuristicAgent(SeededPolicy):
    """Uniformly random actions from a fixed set of action names (LRD, UDD, Rand)."""

    def __init__(self, name: str, actions: tuple[str, ...] | None, seed: int | None = None) -> None:
        """Args:
        name: Label in results tables.
        actions: Action names to draw from; ``None`` means every action of the environment.
        seed: Seed of the agent's generator until the next :meth:`reset` with a seed.
        """
        super().__init__(seed)
        self.name = name
        self.actions = actions
        self._indices = np.zeros(0, dtype=np.int64)

    def prepare(self, env: gym.Env) -> None:
        """Map the action set to ``env``'s indices.

        Raises:
            UserError: when the environment lacks one of the actions.
        """
        names = tvm(env).action_names
        wanted = names if self.actions is None else self.actions
        missing = [a for a in wanted if a not in names]
        if missing:
            raise UserError(f"{self.name} needs actions {missing} that this environment lacks ({', '.join(names)})")
        self._indices = np.array([names.index(a) for a in wanted])

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> int:
        """Draw one action of the set, as an index of the environment :meth:`prepare` saw."""
        return int(self._indices[self._rng.integers(len(self._indices))])

    def action_probabilities(self, env: gym.Env) -> np.ndarray:
        """Probability of each action index of ``env`` at every step (uniform over the set)."""
        return action_probabilities(tvm(env).action_names, self.actions)


class FixedActionAgent:
    """Always plays the same action (by name): the trivial policies a learner must beat."""

    def __init__(self, action: str, name: str | None = None) -> None:
        """Args:
        action: The action's name (``down``, ``done``, ...).
        name: Label in results tables (default ``always <action>``).
        """
        self.action = action
        self.name = name or f"always {action}"
        self._index = -1

    def reset(self, seed: int | None = None) -> None:
        """Nothing to reset: the policy has no randomness."""

    def prepare(self, env: gym.Env) -> None:
        """Find the action's index in ``env``.

        Raises:
            UserError: when the environment has no such action.
        """
        names = tvm(env).action_names
        if self.action not in names:
            raise UserError(f"{self.name}: this environment has no action {self.action!r} ({', '.join(names)})")
        self._index = names.index(self.action)

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> int:
        """The action's index."""
        return self._index

    def action_probabilities(self, env: gym.Env) -> np.ndarray:
        """Probability 1 on the action, 0 elsewhere."""
        return action_probabilities(tvm(env).action_names, (self.action,))


def heuristic(name: str, seed: int | None = None) -> HeuristicAgent:
    """One of the paper's heuristic baselines by name (``LRD``, ``UDD``, ``Rand``, any case)."""
    for key, actions in HEURISTIC_ACTIONS.items():
        if key.lower() == name.lower():
            return HeuristicAgent(key, actions, seed)
    raise UserError(f"unknown heuristic {name!r}: choose one of {', '.join(HEURISTIC_ACTIONS)}")


def oracle_plan(next_view: np.ndarray, oer: np.ndarray, start: int, tau: int) -> list[int]:
    """The shortest action sequence that ends on the best OER reachable within ``tau`` steps.

    Breadth-first over views: a view first reached at depth ``d`` needs exactly ``d`` moves,
    and any view reached earlier can still end the episode by ``done``, so the best final OER
    over every action sequence is the best OER over views within ``tau`` moves. Ties go to the
    fewest moves, then to the lower action index at each step.

    Args:
        next_view: ``(n_views, n_moves)`` view each move leads to (refused moves stay).
        oer: ``(n_views,)`` the target's OER per view.
        start: The episode's first view.
        tau: Steps per episode.

    Returns:
        Move indices to play in order; the caller appends ``done`` when it is shorter than tau.
    """
    parent = {start: (-1, -1)}
    frontier = [start]
    best, best_oer = start, float(oer[start])
    for _ in range(tau):
        following = []
        for view in frontier:
            for move, nxt in enumerate(next_view[view].tolist()):
                if nxt not in parent:
                    parent[nxt] = (view, move)
                    following.append(nxt)
                    if float(oer[nxt]) > best_oer:
                        best, best_oer = nxt, float(oer[nxt])
        frontier = following
    moves = []
    while parent[best][0] >= 0:
        best, move = parent[best]
        moves.append(move)
    return moves[::-1]


class OracleAgent:
    """Exact upper bound: plays the :func:`oracle_plan` of the episode's start.

    Uses :meth:`davis_ag.benchmark.TVMEnv.move_table` (the environment's own tables, not the image),
    so it reaches the best final OER any policy can reach on the same episode.
    """

    name = "Oracle"

    def __init__(self) -> None:
        self._plan: list[int] = []
        self._env: TVMEnv | None = None

    def prepare(self, env: gym.Env) -> None:
        """Keep the environment: its tables are the Oracle's plan."""
        self._env = tvm(env)

    def reset(self, seed: int | None = None) -> None:
        """Forget the previous plan (the next :meth:`act` at step 0 plans anew)."""
        self._plan = []

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> int:
        """The next action of the plan; ``done`` once the plan is played out."""
        inner = self._env
        if inner is None:
            raise UserError("the Oracle plays only after prepare(env): evaluate it with davis_ag.benchmark.evaluate")
        if inner.steps_taken == 0:
            next_view, oer = inner.move_table()
            self._plan = oracle_plan(next_view, oer, inner.current_view, inner.tau)
        t = inner.steps_taken
        return self._plan[t] if t < len(self._plan) else inner.done_action


#: Baseline names :func:`build_agents` accepts (trained models come from
#: :func:`davis_ag.benchmark.policies.policy_from_spec`), and what makes each.
BASELINES: dict[str, Callable[[], Policy]] = {
    **{name: partial(heuristic, name) for name in HEURISTIC_ACTIONS},
    "Oracle": OracleAgent,
}
AGENT_NAMES: tuple[str, ...] = tuple(BASELINES)


def build_agents(names: list[str]) -> list[Policy]:
    """Baselines by name, in the order given (case-insensitive; see :data:`AGENT_NAMES`).

    Raises:
        UserError: for an unknown name (a trained model is a ``--policy MODEL.zip``).
    """
    return baselines_by_name(names, BASELINES)

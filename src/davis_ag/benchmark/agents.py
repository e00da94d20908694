"""Policies for target visibility maximisation: the paper's baselines (section IV-B), an exact
Oracle upper bound, and A2C (section IV-C) trained with Stable-Baselines3.

Every agent has the same small interface (:class:`Agent`): ``reset(seed)`` at the start of an
episode, then ``act(obs, env)`` once per step, returning an action index of ``env``. The
environment is passed so that heuristics can map action *names* to indices (SP and MP number
them differently) and so that the Oracle can read the episode's tables; learned agents only
look at ``obs``.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Protocol

import gymnasium as gym
import numpy as np
import torch

from davis_ag.benchmark import TVMEnv
from davis_ag.benchmark.exact import action_probabilities
from davis_ag.errors import UserError

#: Section IV-B action sets by agent name. Rand uses every action of the environment, which in
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
    inner = getattr(env, "unwrapped", env)
    if not isinstance(inner, TVMEnv):
        raise UserError(f"expected a davis_ag/TVM-v0 environment, got {type(inner).__name__}")
    return inner


class Agent(Protocol):
    """What the evaluation loop needs from a policy."""

    name: str

    def reset(self, seed: int | None = None) -> None:
        """Start an episode; ``seed`` fixes the agent's own randomness (if any)."""

    def act(self, obs: np.ndarray, env: gym.Env) -> int:
        """Choose an action index of ``env`` for the observation ``obs``."""


class HeuristicAgent:
    """Uniformly random actions from a fixed set of action names (LRD, UDD, Rand)."""

    def __init__(self, name: str, actions: tuple[str, ...] | None, seed: int | None = None) -> None:
        """Args:
            name: Label in results tables.
            actions: Action names to draw from; ``None`` means every action of the environment.
            seed: Seed of the agent's generator until the next :meth:`reset` with a seed.
        """
        self.name = name
        self.actions = actions
        self._rng = np.random.default_rng(seed)
        self._indices: dict[tuple[str, ...], np.ndarray] = {}

    def reset(self, seed: int | None = None) -> None:
        """Reseed the action draw (``None`` keeps the current stream)."""
        if seed is not None:
            self._rng = np.random.default_rng(seed)

    def act(self, obs: np.ndarray, env: gym.Env) -> int:
        """Draw one action of the set, as an index of ``env``."""
        names = tvm(env).action_names
        indices = self._indices.get(names)
        if indices is None:
            wanted = names if self.actions is None else self.actions
            missing = [a for a in wanted if a not in names]
            if missing:
                raise UserError(f"{self.name} needs actions {missing} that this environment "
                                f"lacks ({', '.join(names)})")
            indices = self._indices[names] = np.array([names.index(a) for a in wanted])
        return int(indices[self._rng.integers(len(indices))])

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

    def reset(self, seed: int | None = None) -> None:
        """Nothing to reset: the policy has no randomness."""

    def act(self, obs: np.ndarray, env: gym.Env) -> int:
        """The action's index in ``env``.

        Raises:
            UserError: when the environment has no such action.
        """
        names = tvm(env).action_names
        if self.action not in names:
            raise UserError(f"{self.name}: this environment has no action {self.action!r} "
                            f"({', '.join(names)})")
        return names.index(self.action)

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

    def reset(self, seed: int | None = None) -> None:
        """Forget the previous plan (the next :meth:`act` at step 0 plans anew)."""
        self._plan = []

    def act(self, obs: np.ndarray, env: gym.Env) -> int:
        """The next action of the plan; ``done`` once the plan is played out."""
        inner = tvm(env)
        if inner.steps_taken == 0:
            next_view, oer = inner.move_table()
            self._plan = oracle_plan(next_view, oer, inner.current_view, inner.tau)
        t = inner.steps_taken
        return self._plan[t] if t < len(self._plan) else inner.done_action


#: How the benchmark's A2C plays (``davis-ag reproduce``): False samples each action from the
#: policy. Played deterministically, a policy repeats a refused move for the rest of the episode
#: (the observation after a refused move is the same image), and a policy whose most likely
#: action is the same at every start is exactly a fixed action: on the train split
#: (tools/a2c_trials.py) a short-trained policy played deterministically was "always forward"
#: while sampling it scored higher; trained longer, deterministic play scored about one standard
#: deviation higher than sampling. Sampling is kept as the safe default on unseen scenes, where
#: the policy is least sure; the benchmark also reports the deterministic play as the row
#: ``A2C (deterministic)``.
A2C_DETERMINISTIC = False


class A2CAgent:
    """A trained SB3 model (A2C or any SB3 algorithm with ``predict``) as an :class:`Agent`."""

    name = "A2C"

    def __init__(self, model: Any, deterministic: bool = True, device: str = "cpu") -> None:
        """Args:
            model: A loaded SB3 model, or the path of a saved A2C ``.zip``.
            deterministic: Take the most likely action (default) instead of sampling.
            device: Torch device to load a saved model on.

        Raises:
            UserError: when the file is missing or not an SB3 model.
        """
        if isinstance(model, (str, os.PathLike)):
            from stable_baselines3 import A2C

            path = Path(model)
            if not path.is_file():
                raise UserError(f"{path}: no such model file; train one with `davis-ag train`")
            try:
                model = A2C.load(path, device=device)
            except Exception as error:  # noqa: BLE001 - any load failure is a bad file
                raise UserError(f"{path}: not a Stable-Baselines3 A2C model ({error}); "
                                "give the .zip `davis-ag train` wrote") from None
        self.model = model
        self.deterministic = deterministic

    def reset(self, seed: int | None = None) -> None:
        """Seed torch's sampling when acting stochastically (a no-op when deterministic)."""
        if seed is not None and not self.deterministic:
            torch.manual_seed(seed)

    def check(self, env: gym.Env) -> None:
        """Refuse an environment the model was not trained for, before any episode.

        Raises:
            UserError: when the model was trained for another action or observation space
                (e.g. an SP model on MP: 7 actions against 9).
        """
        inner = tvm(env)
        n = inner.action_space.n
        if getattr(self.model.action_space, "n", n) != n:
            raise UserError(f"the model has {self.model.action_space.n} actions, the {inner.scenario} "
                            f"environment {n}: use a model trained on the same scenario")
        shape = getattr(self.model.observation_space, "shape", None)
        # SB3 stores image spaces channels-first.
        if shape is not None and sorted(shape) != sorted(inner.observation_space.shape):
            raise UserError(f"the model takes observations of shape {shape}, the environment gives "
                            f"{inner.observation_space.shape}: use a model trained by davis-ag train")

    def act(self, obs: np.ndarray, env: gym.Env) -> int:
        """The model's action for ``obs``.

        Raises:
            UserError: when the model was trained for another action space (e.g. SP vs MP).
        """
        self.check(env)
        action, _ = self.model.predict(obs, deterministic=self.deterministic)
        return int(action)


#: Policy names :func:`build_agents` accepts (A2C also needs a model).
AGENT_NAMES: tuple[str, ...] = ("LRD", "UDD", "Rand", "Oracle", "A2C")


def build_agents(names: list[str], model: str | os.PathLike[str] | None = None,
                 deterministic: bool = True) -> list[Agent]:
    """Agents by name, in the order given (case-insensitive; see :data:`AGENT_NAMES`).

    Args:
        names: Policy names.
        model: Saved A2C model, required when ``A2C`` is among the names.
        deterministic: Whether A2C takes its most likely action.

    Returns:
        The agents.

    Raises:
        UserError: for an unknown name, or A2C without a model.
    """
    agents: list[Agent] = []
    for name in names:
        key = name.strip().lower()
        if key == "oracle":
            agents.append(OracleAgent())
        elif key == "a2c":
            if model is None:
                raise UserError("policy A2C needs a trained model: pass --model model.zip")
            agents.append(A2CAgent(model, deterministic=deterministic))
        else:
            if key not in {k.lower() for k in HEURISTIC_ACTIONS}:
                raise UserError(f"unknown policy {name!r}: choose from {', '.join(AGENT_NAMES)}")
            agents.append(heuristic(key))
    return agents

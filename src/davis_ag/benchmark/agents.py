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
from stable_baselines3.common.torch_layers import BaseFeaturesExtractor
from torch import nn

from davis_ag.atomic_files import atomic_output, prove_writable_file, write_or_rescue
from davis_ag.benchmark import TVMEnv
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


class PooledFeatures(BaseFeaturesExtractor):
    """A small feature extractor for quick runs and tests: 8x average pooling, one conv.

    NatureCNN (the paper's network) costs ~90 M multiply-adds per 224x224 observation; this
    one costs well under 1 M, so a few thousand A2C steps take seconds on a CPU. Not for
    results: the paper's numbers need ``arch="nature"``.
    """

    def __init__(self, observation_space: gym.spaces.Box, features_dim: int = 64) -> None:
        """Args:
            observation_space: Channels-first image space (SB3 transposes ours).
            features_dim: Size of the feature vector.
        """
        super().__init__(observation_space, features_dim)
        self.cnn = nn.Sequential(
            nn.AvgPool2d(8), nn.Conv2d(observation_space.shape[0], 16, 3, stride=2), nn.ReLU(),
            nn.Flatten())
        with torch.no_grad():
            n = self.cnn(torch.zeros(1, *observation_space.shape)).shape[1]
        self.head = nn.Sequential(nn.Linear(n, features_dim), nn.ReLU())

    def forward(self, observations: torch.Tensor) -> torch.Tensor:
        """Features of a batch of (already 0-1 scaled) observations."""
        return self.head(self.cnn(observations))


#: Network choices of :func:`train_a2c`: SB3 ``policy_kwargs`` by name.
ARCHITECTURES: dict[str, dict[str, Any]] = {
    # CnnPolicy's default NatureCNN is the paper's network: convs (8,4), (4,2), (3,1), then 512
    # features, with separate linear action and value heads.
    "nature": {},
    "pooled": {"features_extractor_class": PooledFeatures},
}


def make_vec_tvm(dataset: Any, scenario: str, n_envs: int, seed: int, split: str = "train",
                 crop: str | None = None, cache_dir: str | os.PathLike[str] | None = None) -> Any:
    """``n_envs`` TVM environments in one SB3 ``DummyVecEnv`` (each wrapped in ``Monitor``).

    The environment is fast (tens of thousands of steps/s), so subprocesses would only add
    pickling; the network is the cost. The dataset is opened once and shared.

    Args:
        dataset: Dataset root or opened dataset.
        scenario: ``sp`` or ``mp``.
        n_envs: Number of environments.
        seed: Environment ``i`` is seeded with ``seed + i``.
        split, crop, cache_dir: As for :class:`davis_ag.benchmark.TVMEnv`.

    Returns:
        The vectorised environment.
    """
    from stable_baselines3.common.env_util import make_vec_env

    from davis_ag.benchmark.tvm import as_dataset

    opened = as_dataset(dataset)
    kwargs = {"dataset": opened, "scenario": scenario, "split": split, "crop": crop,
              "cache_dir": cache_dir}
    return make_vec_env(TVMEnv, n_envs=n_envs, seed=seed, env_kwargs=kwargs)


def train_a2c(dataset: Any, scenario: str, total_timesteps: int = 300_000, seed: int = 0,
              out_path: str | os.PathLike[str] = "a2c.zip", n_envs: int = 8,
              crop: str | None = None, cache_dir: str | os.PathLike[str] | None = None,
              arch: str = "nature", device: str = "auto", verbose: int = 0,
              callback: Any = None) -> Path:
    """Train the paper's A2C agent on the train split and save it.

    Hyperparameters are Stable-Baselines3's A2C defaults (the paper gives none): learning rate
    7e-4, ``n_steps=5`` per environment and update, ``gamma=0.99``, ``gae_lambda=1``,
    ``ent_coef=0``, ``vf_coef=0.5``, ``max_grad_norm=0.5``, RMSprop (alpha 0.99, eps 1e-5);
    CnnPolicy scales the uint8 observation by 1/255. ``n_envs`` (8) is ours; the paper's
    300K timesteps count environment steps over all environments.

    Args:
        dataset: Dataset root or opened dataset.
        scenario: ``sp`` or ``mp``.
        total_timesteps: Environment steps to train for (300K in section VI).
        seed: Seeds SB3 (network init, action sampling) and the environments.
        out_path: Where to save the model (``.zip`` is added by SB3 if missing).
        n_envs: Parallel environments per update.
        crop: Train on one crop only (the paper: strawberry for SP, vine for MP).
        cache_dir: Observation cache folder (default under the dataset root).
        arch: ``nature`` (the paper's NatureCNN) or ``pooled`` (fast, for smoke tests).
        device: Torch device for SB3 (``auto``, ``cpu``, ``cuda``).
        verbose: SB3 verbosity.
        callback: Optional SB3 callback.

    Returns:
        The saved model's path.

    Raises:
        UserError: for a bad dataset, scenario, split or architecture.
    """
    from stable_baselines3 import A2C

    if arch not in ARCHITECTURES:
        raise UserError(f"unknown network {arch!r}: choose one of {', '.join(ARCHITECTURES)}")
    if total_timesteps < 1 or n_envs < 1:
        raise UserError("--timesteps and --n-envs must be positive")
    if not 0 <= seed < 2**32:
        raise UserError(f"--seed {seed}: use a whole number from 0 to {2**32 - 1}")
    check_device(device)
    out = Path(out_path).expanduser().absolute()
    out = out if out.suffix == ".zip" else out.with_name(out.name + ".zip")  # as SB3 names it
    prove_writable_file(out)  # before hours of training, not after
    env = make_vec_tvm(dataset, scenario, n_envs, seed, "train", crop, cache_dir)
    model = A2C("CnnPolicy", env, seed=seed, device=device, verbose=verbose,
                policy_kwargs=dict(ARCHITECTURES[arch]))
    model.learn(total_timesteps=total_timesteps, callback=callback)
    env.close()

    def save(path: Path) -> None:
        with atomic_output(path) as handle:
            model.save(handle)

    return write_or_rescue(out, save, "the trained model")


def check_device(device: str) -> None:
    """Refuse a torch device name torch does not know, before any work.

    Raises:
        UserError: naming the device and the choices.
    """
    if device == "auto":
        return
    try:
        torch.device(device)
    except (RuntimeError, ValueError, TypeError):
        raise UserError(f"--device {device!r} is not a torch device: use auto, cpu or cuda") from None


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

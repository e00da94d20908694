"""Train PPO (Stable-Baselines3) on TVMContinuous-v0 (its training curve: :mod:`davis_ag.figures.result_charts`).

PPO, not A2C: the action is continuous, and PPO is SB3's on-policy method for it that behaves
well on short runs; SAC (off-policy, replay buffer) would keep every 224x224x4 observation in
memory. Hyperparameters are SB3's PPO defaults except ``n_steps`` and ``batch_size``, shortened
so that an update comes every few dozen episodes (tau is 3 or 5 steps). The network is the
paper's (section V-C) or the pooled one for quick runs (:mod:`davis_ag.benchmark.networks`).
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np

from davis_ag.atomic_files import prove_writable_file, write_or_rescue
from davis_ag.benchmark.algorithms import console_logger
from davis_ag.benchmark.checkpoints import save_model
from davis_ag.benchmark.networks import ARCHITECTURES
from davis_ag.benchmark.training import model_path
from davis_ag.errors import UserError


class EpisodeLog(gym.Wrapper):
    """Records every finished episode: environment steps so far, reward, start and final OER."""

    def __init__(self, env: gym.Env) -> None:
        """Args:
        env: A TVMContinuous-v0 environment (its info carries ``oer_0`` and ``oer_t``).
        """
        super().__init__(env)
        self.records: list[dict] = []
        self._steps = 0
        self._reward = 0.0

    def step(self, action: Any) -> tuple:
        """Step and, at an episode's end, record it."""
        obs, reward, terminated, truncated, info = self.env.step(action)
        self._steps += 1
        self._reward += float(reward)
        if terminated or truncated:
            self.records.append(
                {
                    "timestep": self._steps,
                    "reward": self._reward,
                    "oer_0": float(info["oer_0"]),
                    "oer_tau": float(info["oer_t"]),
                }
            )
            self._reward = 0.0
        return obs, reward, terminated, truncated, info


def make_logged_env(
    dataset: str | os.PathLike[str], scenario: str, seed: int, **env_kwargs: Any
) -> tuple[gym.Env, EpisodeLog]:
    """One TVMContinuous-v0 environment that records its episodes (:class:`EpisodeLog`), seeded."""
    from stable_baselines3.common.monitor import Monitor

    from davis_ag.benchmark import CONTINUOUS_ID

    log = EpisodeLog(gym.make(CONTINUOUS_ID, dataset=dataset, scenario=scenario, **env_kwargs))
    env = Monitor(log)
    env.reset(seed=seed)
    env.action_space.seed(seed)
    return env, log


def _progress_printer(log: EpisodeLog, total: int, every: int):
    """An SB3 callback that prints steps done and the recent mean reward every ``every`` steps."""
    from stable_baselines3.common.callbacks import BaseCallback

    class Progress(BaseCallback):
        def _on_step(self) -> bool:
            if self.num_timesteps % every == 0 or self.num_timesteps == total:
                recent = [r["reward"] for r in log.records[-100:]]
                print(
                    f"PPO: {self.num_timesteps:,}/{total:,} steps, {len(log.records):,} episodes, mean reward "
                    f"of the last {len(recent)}: {np.mean(recent) if recent else 0.0:.4f}",
                    flush=True,
                )
            return True

    return Progress()


def train_continuous(
    dataset: str | os.PathLike[str],
    scenario: str = "sp",
    total_timesteps: int = 10_000,
    seed: int = 0,
    out_path: str | os.PathLike[str] = "ppo.zip",
    arch: str = "paper",
    n_steps: int = 128,
    batch_size: int = 32,
    verbose: int = 0,
    progress_every: int = 0,
    **env_kwargs: Any,
) -> tuple[Path, list[dict]]:
    """Train PPO on the train split (or one scene folder) and save it.

    Args:
        dataset: Dataset root made by ``davis-ag generate``, or one of its scene folders.
        scenario: ``sp`` or ``mp``.
        total_timesteps: Environment steps.
        seed: Seeds SB3 and the environment.
        out_path: Where to save the model (``.zip`` added if missing).
        arch: ``paper``, ``nature`` or ``pooled``.
        n_steps, batch_size: PPO's rollout length and minibatch size.
        verbose: SB3 verbosity.
        progress_every: Print progress every this many steps (0: silent).
        env_kwargs: More :class:`~davis_ag.live.tvm_continuous.TVMContinuousEnv` settings.

    Returns:
        The saved model's path and one record per finished episode: ``timestep`` (at its end),
        ``reward``, ``oer_0``, ``oer_tau``.

    Raises:
        UserError: for a bad architecture or number, or an environment that cannot be made.
    """
    from stable_baselines3 import PPO

    if arch not in ARCHITECTURES:
        raise UserError(f"unknown network {arch!r}: choose one of {', '.join(ARCHITECTURES)}")
    if total_timesteps < 1 or n_steps < 2 or batch_size < 2:
        raise UserError("total_timesteps must be positive, n_steps and batch_size at least 2")
    final = model_path(Path(out_path).expanduser().absolute())
    prove_writable_file(final)
    env, log = make_logged_env(dataset, scenario, seed, **env_kwargs)
    try:
        model = PPO(
            "CnnPolicy",
            env,
            n_steps=n_steps,
            batch_size=batch_size,
            seed=seed,
            device="cpu",
            verbose=verbose,
            policy_kwargs=dict(ARCHITECTURES[arch]),
        )
        model.set_logger(console_logger(verbose))
        model.learn(
            total_timesteps=total_timesteps,
            callback=_progress_printer(log, total_timesteps, progress_every) if progress_every else None,
        )
    finally:
        env.close()
    records = list(log.records)
    saved = write_or_rescue(final, lambda path: save_model(model, path), "the trained model")
    return saved, records

"""A trained model's episodes played in step: the same episodes as one at a time, for every way a
model plays, through Gymnasium's wrappers, and never under a wrapper that could change them."""

from __future__ import annotations

from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
import pytest

from davis_ag.benchmark import TVMEnv
from davis_ag.benchmark.agents import heuristic
from davis_ag.benchmark.evaluation import episode_seeds, evaluate_policies, run_episode
from davis_ag.benchmark.lockstep import BATCH, bare_grid, play_lockstep
from davis_ag.benchmark.networks import ARCHITECTURES
from davis_ag.benchmark.policies import ModelPolicy, prepare
from davis_ag.benchmark.selection import train_split_score


def _model(env: TVMEnv, algorithm: str, seed: int = 0) -> Any:
    """An untrained model: its actions are spread over every move, which tests the draws most."""
    import stable_baselines3

    extra: dict[str, Any] = {"A2C": {}, "PPO": {"n_steps": 16, "batch_size": 8}, "DQN": {"buffer_size": 100}}[algorithm]
    kwargs = dict(ARCHITECTURES["pooled"])
    return getattr(stable_baselines3, algorithm)(
        "CnnPolicy", env, seed=seed, device="cpu", policy_kwargs=kwargs, **extra
    )


def _one_at_a_time(env: Any, policy: ModelPolicy, resets: list[int], draws: list[int]) -> list[dict[str, Any]]:
    return [run_episode(env, policy, r, d, prepared=True) for r, d in zip(resets, draws)]


@pytest.mark.parametrize(
    ("scenario", "algorithm", "deterministic"),
    [("sp", "A2C", False), ("sp", "A2C", True), ("sp", "PPO", False), ("sp", "DQN", True), ("mp", "PPO", False)],
)
def test_lockstep_plays_the_episodes_played_one_at_a_time(
    scenario: str, algorithm: str, deterministic: bool, sp_root: Path, mp_root: Path, one_thread: None
) -> None:
    env = TVMEnv(sp_root if scenario == "sp" else mp_root, scenario, "all")
    policy = ModelPolicy(_model(env, algorithm), deterministic=deterministic)
    prepare(policy, env)
    resets, draws = episode_seeds(7, 1, 60)
    together = play_lockstep(env, policy, resets, draws)
    alone = _one_at_a_time(env, policy, resets, draws)
    assert together == alone
    # The episodes differ (a deterministic untrained model answers by the image: few sequences).
    assert len({tuple(r["actions"]) for r in alone}) > (1 if deterministic else 5)
    if not deterministic:  # every draw was tested, not one favourite move
        assert {a for r in alone for a in r["actions"]} == set(range(env.action_space.n))


def test_more_episodes_than_a_batch_and_the_env_left_as_it_was(sp_root: Path, one_thread: None) -> None:
    env = TVMEnv(sp_root, "sp", "all")
    policy = ModelPolicy(_model(env, "A2C", seed=3))
    prepare(policy, env)
    env.reset(seed=11)
    env.step(0)
    before = (env._scene, env._view, env._box, env._t, list(env._path))
    resets, draws = episode_seeds(0, 0, BATCH + 9)
    together = play_lockstep(env, policy, resets, draws)
    assert (env._scene, env._view, env._box, env._t, list(env._path)) == before  # forks, not the env, played
    assert together == _one_at_a_time(env, policy, resets, draws)


def test_gymnasiums_own_wrappers_play_in_step_and_others_one_at_a_time(sp_root: Path, one_thread: None) -> None:
    made = gym.make("davis_ag/TVM-v0", dataset=sp_root, scenario="sp", split="all")
    assert isinstance(bare_grid(made), TVMEnv)
    policy = ModelPolicy(_model(made.unwrapped, "PPO"))
    prepare(policy, made)
    resets, draws = episode_seeds(0, 0, 20)
    assert play_lockstep(made, policy, resets, draws) == _one_at_a_time(made, policy, resets, draws)

    class Darker(gym.ObservationWrapper):  # changes what the policy sees: only the wrapper knows how
        def observation(self, observation: np.ndarray) -> np.ndarray:
            return observation // 2

    darker = Darker(made)
    assert bare_grid(darker) is None and play_lockstep(darker, policy, resets, draws) is None
    assert play_lockstep(made, heuristic("Rand"), resets, draws) is None  # a policy without a model


def test_evaluation_and_snapshot_scores_are_those_of_one_at_a_time(sp_root: Path, one_thread: None) -> None:
    env = TVMEnv(sp_root, "sp", "all")
    model = _model(env, "A2C", seed=5)
    results = evaluate_policies(env, [ModelPolicy(model)], episodes=40, sessions=2, keep_episodes=True)
    resets, draws = episode_seeds(0, 1, 40)
    alone = _one_at_a_time(env, ModelPolicy(model), resets, draws)
    played = [e.model_dump(exclude={"session"}) for e in results.policies["A2C"].episodes if e.session == 1]
    assert [{k: r[k] for k in alone[0]} for r in played] == alone
    score = train_split_score(model, env, episodes=30)
    resets, draws = episode_seeds(12345, 0, 30)
    alone = _one_at_a_time(env, ModelPolicy(model), resets, draws)
    assert score["oer_tau"] == pytest.approx(np.mean([r["oer_tau"] for r in alone]), abs=1e-6)

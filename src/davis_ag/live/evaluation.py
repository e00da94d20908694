"""Evaluate policies on TVMContinuous-v0 with the grid benchmark's protocol (section V-C).

The same sessions, seeds and summary as :mod:`davis_ag.benchmark.evaluation`: episode ``e`` of
session ``s`` resets with a seed from ``SeedSequence([seed, s])`` (so every policy plays the same
starts; slip follows the environment's generator, so it differs once policies move
differently), the agent's own randomness from ``SeedSequence([seed, s, 1])``; per policy the mean
and standard deviation over sessions of the final OER, reward and episode length. The table and
chart are the grid benchmark's; actions are summarised by the mean absolute action component
instead of counts.
"""

from __future__ import annotations

from typing import Any

import numpy as np

from davis_ag.benchmark.evaluation import METRICS, play_sessions
from davis_ag.live.policies import continuous


def run_episode(env: Any, agent: Any, reset_seed: int, agent_seed: int | None = None) -> dict[str, Any]:
    """Play one episode.

    Returns:
        ``{"oer_0", "oer_tau", "reward", "length", "refused", "path", "actions"}``.
    """
    obs, info = env.reset(seed=reset_seed)
    agent.reset(agent_seed)
    total, actions, refused = 0.0, [], 0
    while True:
        action = agent.act(obs, env)
        actions.append([round(float(a), 4) for a in np.asarray(action).reshape(-1)])
        obs, reward, terminated, truncated, info = env.step(action)
        total += float(reward)
        refused += bool(info["refused"])
        if terminated or truncated:
            break
    return {"oer_0": float(info["oer_0"]), "oer_tau": float(info["oer_t"]), "reward": total,
            "length": len(actions), "refused": refused, "scene": info["scene"],
            "target_fruit": int(info["target_fruit"]), "path": info["path"], "actions": actions}


def evaluate_continuous(env: Any, agents: list[Any], episodes: int = 200, sessions: int = 3,
                        seed: int = 0, keep_episodes: bool = False) -> dict[str, Any]:
    """Run every agent on the same starts; results shaped as the grid benchmark's.

    Args:
        env: A TVMContinuous-v0 environment (wrapped or not).
        agents: Policies (:mod:`davis_ag.live.policies`).
        episodes, sessions, seed: The protocol (200, 3 and 0 in the paper's setting).
        keep_episodes: Also return every episode's record.

    Returns:
        ``{"protocol": {...}, "policies": {name: {metric: {"mean", "std", "sessions"}}}}``
        (metrics ``oer_tau``, ``reward``, ``length``, ``oer_0``, ``refused``).
    """
    inner = continuous(env)
    for agent in agents:
        check = getattr(agent, "check", None)
        if callable(check):
            check(env)
    results: dict[str, Any] = {
        "protocol": {"environment": "davis_ag/TVMContinuous-v0", "scenario": inner.scenario, "split": inner.split,
                     "tau": inner.tau, "episodes": episodes, "sessions": sessions, "seed": seed, "aim": inner.aim,
                     "scenes": [s.settings.metadata.scene for s in inner.scenes],
                     "actions": ["dx", "dy", "dz", "dyaw", "dpitch"][: inner.action_space.shape[0]]},
        "policies": {},
    }
    for agent in agents:
        summary, records = play_sessions(env, agent, run_episode, (*METRICS, "oer_0", "refused"), seed, sessions,
                                         episodes)
        moves = np.abs(np.array([a for r in records for a in r["actions"]], dtype=np.float64))
        summary["mean_abs_action"] = dict(zip(results["protocol"]["actions"], moves.mean(axis=0).round(4).tolist()))
        if keep_episodes:
            summary["episodes"] = records
        results["policies"][agent.name] = summary
    return results

"""Benchmark policies as in section V-C and Table 4.

Protocol: the test split; ``sessions`` (3) sessions of ``episodes`` (200) episodes. Episode
``e`` of session ``s`` resets the environment with a seed drawn from
``numpy.random.SeedSequence([seed, s])``, so every policy plays exactly the same episodes
(same scene, view and target); an agent's own randomness is seeded from
``SeedSequence([seed, s, 1])`` so that it never mirrors the environment's draws. Per policy
and session the mean final OER (``OER_tau``), cumulative reward and episode length are taken;
the table reports their mean and standard deviation (population, ``ddof=0``) over sessions.
Beside them: the standard error of each mean over all episodes (``sem``: the per-episode
standard deviation over the square root of the episode count), and, for the policies that
ignore the image (LRD, UDD, Rand, fixed actions), the exact expectation over the split's starts
(``exact``, :mod:`davis_ag.benchmark.exact`) that the sampled mean estimates. With
``best_fixed_action`` the row :data:`BEST_FIXED` is added: of the policies that always play the
same action, the one with the highest exact OER_tau on this split, played on the same episodes,
so that a learner that collapsed to one move is seen beside it.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any, Callable

import numpy as np

from davis_ag.atomic_files import write_json_atomic
from davis_ag.benchmark import TVMEnv
from davis_ag.benchmark.agents import Agent, FixedActionAgent
from davis_ag.benchmark import exact

#: Table 4's metrics: key in the results, row label.
METRICS: dict[str, str] = {"oer_tau": "OER_tau", "reward": "Cum. Reward", "length": "Ep. Length"}
#: The row of the best policy that always plays one action (see the module docstring).
BEST_FIXED = exact.BEST_FIXED


def episode_seeds(seed: int, session: int, episodes: int) -> tuple[list[int], list[int]]:
    """Reset seeds and agent seeds of one session.

    Args:
        seed: The evaluation's base seed.
        session: Session index.
        episodes: Episodes in the session.

    Returns:
        ``(reset_seeds, agent_seeds)``, one each per episode.
    """
    env_seeds = np.random.SeedSequence([seed, session]).generate_state(episodes)
    agent_seeds = np.random.SeedSequence([seed, session, 1]).generate_state(episodes)
    return [int(s) for s in env_seeds], [int(s) for s in agent_seeds]


def run_episode(env: TVMEnv, agent: Agent, reset_seed: int,
                agent_seed: int | None = None) -> dict[str, Any]:
    """Play one episode.

    Args:
        env: The environment (a :class:`TVMEnv`, wrapped or not).
        agent: The policy.
        reset_seed: Seed of ``env.reset``; fixes the scene, view and target.
        agent_seed: Seed of the agent's own randomness.

    Returns:
        ``{"oer_0", "oer_tau", "reward", "length", "scene", "target_fruit", "path",
        "actions"}``.
    """
    obs, info = env.reset(seed=reset_seed)
    agent.reset(agent_seed)
    total, actions = 0.0, []
    while True:
        action = agent.act(obs, env)
        actions.append(action)
        obs, reward, terminated, truncated, info = env.step(action)
        total += float(reward)
        if terminated or truncated:
            break
    return {"oer_0": float(info["oer_0"]), "oer_tau": float(info["oer_t"]), "reward": total,
            "length": len(actions), "scene": info["scene"], "target_fruit": int(info["target_fruit"]),
            "path": list(info["path"]), "actions": [int(a) for a in actions]}


def evaluate_agents(env: TVMEnv, agents: list[Agent], episodes: int = 200, sessions: int = 3,
                    seed: int = 0, keep_episodes: bool = False,
                    best_fixed_action: bool = False) -> dict[str, Any]:
    """Run every agent on the same episodes and summarise as Table 4.

    Args:
        env: The (test split) environment.
        agents: The policies; their ``name`` labels the results.
        episodes: Episodes per session (200 in the paper).
        sessions: Sessions (3 in the paper).
        seed: Base seed of the episode draw.
        keep_episodes: Also return every episode's record (what :func:`run_episode` returns
            plus its ``session``): ``davis-ag plot actions`` and ``episode`` draw from them.
        best_fixed_action: Add the :data:`BEST_FIXED` row (after ``agents``) and the exact
            expectations of every fixed action (``"fixed_actions"``).

    Returns:
        ``{"protocol": {...}, "policies": {name: {metric: {"mean", "std", "sem",
        "sessions"}}}}`` with metrics ``oer_tau``, ``reward``, ``length`` and ``oer_0``,
        ``"action_counts"`` per policy (action name to times chosen, over every episode; the
        protocol's ``"actions"`` lists the names in index order), ``"exact"`` (metric to
        expectation) for the policies that ignore the image, ``"play"`` (``deterministic`` or
        ``sampled``) for a learned policy, ``"action"`` for :data:`BEST_FIXED`, plus
        ``"episodes"`` per policy when ``keep_episodes``; with ``best_fixed_action`` also
        ``"fixed_actions"``: action name to its exact expectations.
    """
    inner = env.unwrapped if hasattr(env, "unwrapped") else env
    for agent in agents:  # a model made for another scenario is refused before any episode runs
        check = getattr(agent, "check", None)
        if callable(check):
            check(env)
    results: dict[str, Any] = {
        "protocol": {"scenario": inner.scenario, "split": inner.split, "tau": inner.tau,
                     "episodes": episodes, "sessions": sessions, "seed": seed,
                     "scenes": [s.id for s in inner.scenes], "dataset": str(inner.dataset.root),
                     "actions": list(inner.action_names), "start_rule": inner.start_rule,
                     "starts": int(len(inner.starts))},
        "policies": {},
    }
    agents = list(agents)
    if best_fixed_action:
        fixed = exact.fixed_action_expectations(inner)
        results["fixed_actions"] = fixed
        agents.append(FixedActionAgent(exact.best_fixed_action(fixed), name=BEST_FIXED))
    for agent in agents:
        summary, records = play_sessions(env, agent, run_episode, (*METRICS, "oer_0"), seed, sessions, episodes)
        chosen = np.bincount([a for r in records for a in r["actions"]],
                             minlength=len(inner.action_names))
        summary["action_counts"] = {n: int(c) for n, c in zip(inner.action_names, chosen)}
        probs = exact.agent_probabilities(agent, inner)
        if probs is not None:
            summary["exact"] = exact.expected_metrics(inner, probs)
        if isinstance(getattr(agent, "deterministic", None), bool):
            summary["play"] = "deterministic" if agent.deterministic else "sampled"
        if isinstance(agent, FixedActionAgent):
            summary["action"] = agent.action
        if keep_episodes:
            summary["episodes"] = records
        results["policies"][agent.name] = summary
    return results


def play_sessions(env: Any, agent: Any, play: Callable[..., dict[str, Any]], keys: tuple[str, ...], seed: int,
                  sessions: int, episodes: int) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """Play ``sessions`` x ``episodes`` seeded episodes (the same for every policy) and summarise.

    Args:
        env, agent: The environment and the policy.
        play: ``play(env, agent, reset_seed, agent_seed) -> record`` for one episode.
        keys: The record's numbers to average per session.
        seed, sessions, episodes: The protocol.

    Returns:
        Per key the mean, std and per-session values over sessions and the standard error of the
        mean over all episodes (``sem``); and every episode's record.
    """
    per_session: dict[str, list[float]] = {k: [] for k in keys}
    records = []
    for session in range(sessions):
        env_seeds, agent_seeds = episode_seeds(seed, session, episodes)
        runs = [play(env, agent, r, a) for r, a in zip(env_seeds, agent_seeds)]
        for key in per_session:
            per_session[key].append(float(np.mean([run[key] for run in runs])))
        records.extend({"session": session, **run} for run in runs)
    summary = {key: {"mean": float(np.mean(v)), "std": float(np.std(v)),
                     "sem": float(np.std([r[key] for r in records]) / np.sqrt(len(records))), "sessions": v}
               for key, v in per_session.items()}
    return summary, records


def _number(value: float) -> str:
    """Table 4 style: three decimals, no leading zero below 1 (``.433``)."""
    text = f"{value:.3f}"
    return text[1:] if text.startswith("0.") else text.replace("-0.", "-.")


def format_table(results: dict[str, Any]) -> str:
    """Plain-text Table 4: one row per metric, one column per policy, ``mean ±std``.

    Args:
        results: What :func:`evaluate_agents` returned.

    Returns:
        The table, lines joined by newlines.
    """
    protocol, policies = results["protocol"], results["policies"]
    names = list(policies)
    label = f"{protocol['scenario'].upper()} ({protocol['split']})"
    cells = [[label, "Metric", *names]]
    for key, title in METRICS.items():
        row = ["", title]
        for name in names:
            stat = policies[name][key]
            row.append(f"{_number(stat['mean'])} ±{_number(stat['std'])}")
        cells.append(row)
    exact = any("exact" in policies[name] for name in names)
    if exact:
        for key, title in METRICS.items():
            cells.append(["", f"{title} exact", *(_number(policies[n]["exact"][key]) if "exact" in policies[n]
                                                  else "-" for n in names)])
    widths = [max(len(row[i]) for row in cells) for i in range(len(cells[0]))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in cells]
    lines.insert(1, "-" * len(lines[0]))
    lines.append(f"mean ±std over {protocol['sessions']} sessions of {protocol['episodes']} "
                 f"episodes, tau={protocol['tau']}" + ("; exact: expectation over the split's starts" if exact else ""))
    if BEST_FIXED in policies:
        lines.append(f"{BEST_FIXED}: always {policies[BEST_FIXED]['action']}, the best single action "
                     "by exact OER_tau on this split")
    return "\n".join(lines)


def write_json(results: dict[str, Any], path: str | os.PathLike[str]) -> Path:
    """Write the results as indented JSON (atomically: temp file then rename)."""
    return write_json_atomic(path, results, indent=2)

"""Exact expectations of the policies that ignore the image: LRD, UDD, Rand and every fixed action.

Such a policy draws each action from the same probabilities at every step, whatever it sees, so
its episode is a Markov chain over the target's views whose moves are the environment's own
tables (:meth:`davis_ag.benchmark.TVMEnv.target_move_table`: a refused move stays). For a start
view the distribution over views is pushed forward one step at a time (dynamic programming over
the episode, ``tau`` steps): at step ``t`` the share still playing ends on ``done`` with its
probability (length ``t + 1``, final view the current one), the rest moves; whatever is still
playing after ``tau`` steps ends there (length ``tau``). The final-view distribution gives the
expected final OER, reward ``max(OER_tau - OER_0, 0) ** 2`` and length exactly; weighting each
start by the probability that ``reset`` draws it (:meth:`TVMEnv.start_probabilities`) gives the
expectation over the split's episodes, which a sampled evaluation estimates.
"""

from __future__ import annotations

import os
from typing import TYPE_CHECKING, Any

import numpy as np

from davis_ag.benchmark.tvm import TVMEnv
from davis_ag.errors import UserError

if TYPE_CHECKING:
    from davis_ag.benchmark.policies import Policy
    from davis_ag.data.reader import Dataset

#: The metrics computed exactly, as named in the evaluation's results.
EXACT_METRICS = ("oer_tau", "reward", "length")
#: The results row of the best policy that always plays one action (:func:`best_fixed_action`).
BEST_FIXED = "Best fixed action"


def action_probabilities(action_names: tuple[str, ...], chosen: tuple[str, ...] | None) -> np.ndarray:
    """Uniform probabilities over ``chosen`` action names (``None``: every action) as a vector.

    Raises:
        UserError: when a chosen name is not an action of the environment.
    """
    wanted = action_names if chosen is None else chosen
    missing = [a for a in wanted if a not in action_names]
    if missing:
        raise UserError(f"actions {missing} are not in this environment ({', '.join(action_names)})")
    probs = np.zeros(len(action_names))
    probs[[action_names.index(a) for a in wanted]] = 1.0 / len(wanted)
    return probs


def start_expectations(env: TVMEnv, probs: np.ndarray) -> dict[str, np.ndarray]:
    """Each start's expected final OER, reward and length under a fixed action distribution.

    Args:
        env: The environment (its split's starts and tables).
        probs: Probability of each action index of ``env`` at every step (sums to 1).

    Returns:
        ``{"oer_tau", "reward", "length"}``, each an array over :attr:`TVMEnv.starts` rows.
    """
    inner: TVMEnv = getattr(env, "unwrapped", env)
    probs = np.asarray(probs, dtype=float)
    if probs.shape != (len(inner.action_names),) or not np.isclose(probs.sum(), 1.0) or (probs < 0).any():
        raise UserError(f"action probabilities must be {len(inner.action_names)} non-negative numbers summing to 1")
    p_done = float(probs[inner.done_action])
    moves = [(a, float(p)) for a, p in enumerate(probs[: inner.done_action]) if p > 0]
    starts = inner.starts
    out = {key: np.zeros(len(starts)) for key in EXACT_METRICS}
    groups: dict[tuple[int, int], list[int]] = {}
    for row, (scene, box) in enumerate(starts.tolist()):
        groups.setdefault((scene, int(inner.caches[scene].box_fruit[box])), []).append(row)
    for (scene, fruit), rows in groups.items():
        next_view, oer = inner.target_move_table(scene, fruit)
        oer = np.nan_to_num(oer.astype(float), nan=0.0)  # views without a box are never entered
        cache = inner.caches[scene]
        views = cache.box_view[starts[rows, 1]]
        oer_0 = cache.box_oer[starts[rows, 1]].astype(float)
        playing = np.zeros((len(rows), cache.n_views))
        playing[np.arange(len(rows)), views] = 1.0
        final = np.zeros_like(playing)
        length = np.zeros(len(rows))
        for t in range(inner.tau):
            stopped = p_done * playing
            final += stopped
            length += (t + 1) * stopped.sum(axis=1)
            moved = np.zeros_like(playing)
            for action, p in moves:
                # Column j of ``playing`` flows to column next_view[j, action].
                np.add.at(moved.T, next_view[:, action], p * playing.T)
            playing = moved
        final += playing
        length += inner.tau * playing.sum(axis=1)
        gain = np.maximum(oer[None, :] - oer_0[:, None], 0.0) ** 2
        out["oer_tau"][rows] = final @ oer
        out["reward"][rows] = (final * gain).sum(axis=1)
        out["length"][rows] = length
    return out


def expected_metrics(env: TVMEnv, probs: np.ndarray) -> dict[str, float]:
    """The split's expected final OER, reward and length under a fixed action distribution,
    each start weighted by the probability that ``reset`` draws it.

    Args:
        env: The environment.
        probs: Probability of each action index at every step.

    Returns:
        ``{"oer_tau", "reward", "length"}``.
    """
    inner: TVMEnv = getattr(env, "unwrapped", env)
    weights = inner.start_probabilities()
    per_start = start_expectations(inner, probs)
    return {key: float(weights @ per_start[key]) for key in EXACT_METRICS}


def fixed_action_expectations(env: TVMEnv) -> dict[str, dict[str, float]]:
    """:func:`expected_metrics` of every policy that always plays one action, by action name."""
    inner: TVMEnv = getattr(env, "unwrapped", env)
    return {
        name: expected_metrics(inner, np.eye(len(inner.action_names))[a]) for a, name in enumerate(inner.action_names)
    }


def split_fixed_actions(
    dataset: Dataset | str | os.PathLike[str], scenario: str, split: str, crop: str | None, split_rule: str = "scenes"
) -> dict[str, Any]:
    """Every fixed action's exact expectations on one split of a dataset, and its start count.

    The yardstick on the split an A2C snapshot is chosen on (train): a snapshot that scores no
    better than always playing one move there has not learned to use the image.

    Args:
        dataset: A dataset root or an opened dataset.
        scenario: ``sp`` or ``mp``.
        split: ``train``, ``test`` or ``all``.
        crop: The crop (``None``: every crop of the scenario).
        split_rule: The split rule (:mod:`davis_ag.formats.splits`).

    Returns:
        ``{"split", "starts", "fixed_actions"}``; ``fixed_actions`` as :func:`fixed_action_expectations`.
    """
    env = TVMEnv(dataset, scenario=scenario, split=split, crop=crop, split_rule=split_rule)
    try:
        return {"split": split, "starts": len(env.starts), "fixed_actions": fixed_action_expectations(env)}
    finally:
        env.close()


def best_fixed_action(expectations: dict[str, dict[str, float]]) -> str:
    """The action whose fixed policy has the highest expected OER_tau (ties: the first action)."""
    return max(expectations, key=lambda name: expectations[name]["oer_tau"])


def agent_probabilities(agent: Policy, env: TVMEnv) -> np.ndarray | None:
    """The fixed action distribution of an agent that ignores the image, else ``None``.

    Agents say so with an ``action_probabilities(env)`` method (heuristics, fixed actions).
    """
    method = getattr(agent, "action_probabilities", None)
    return None if method is None else method(env)

"""Learners on row mapping: the benchmark's training run (:func:`davis_ag.benchmark.training.train_agent`:
its algorithms, network, checkpoints, seeds and snapshot rule) on RowMapping-v0.

RowMapping-v0's observation is TVM-v0's shape (the view and a fourth channel, here the memory), so
the paper's network reads it unchanged; its actions are the grid's moves without ``done``. A
snapshot is scored on the train split by its mean final coverage, as TVM-v0's is by OER_tau.
"""

from __future__ import annotations

from functools import partial
from typing import Any

from davis_ag.benchmark.selection import train_split_score
from davis_ag.benchmark.training import TrainingTask
from davis_ag.mapping.coverage import SEEN_FRACTION
from davis_ag.mapping.env import RowMappingEnv
from davis_ag.mapping.evaluation import play_episode
from davis_ag.mapping.results import episode_metrics


def mapping_records(env: Any, policy: Any, resets: list[int], draws: list[int]) -> list[dict[str, Any]]:
    """Play episode ``i`` from ``resets[i]`` with policy seed ``draws[i]`` (one after another).

    Returns:
        Per episode its ``coverage``, ``reward`` (the coverage gain) and ``length``.
    """
    budget = env.unwrapped.budget
    records = []
    for reset, draw in zip(resets, draws):
        episode = play_episode(env, policy, reset, draw, 0)
        coverage = episode_metrics(episode, budget)["coverage"]
        records.append(
            {"coverage": coverage, "reward": sum(episode.gains) / episode.fruit, "length": len(episode.actions)}
        )
    return records


def mapping_task(budget: int | None = None, seen_fraction: float = SEEN_FRACTION) -> TrainingTask:
    """Row mapping as a training task.

    Args:
        budget: Moves per episode (default: the environment's, the sweep's length).
        seen_fraction: The visible fraction a sighting needs.
    """
    settings: dict[str, Any] = {"seen_fraction": seen_fraction}
    if budget is not None:
        settings["budget"] = budget
    return TrainingTask(
        "mapping",
        RowMappingEnv,
        settings,
        score=partial(train_split_score, play=mapping_records, keys=("coverage", "reward", "length")),
        key="coverage",
        label="coverage",
    )

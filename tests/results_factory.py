"""Evaluation results made by hand for the page tests: each policy's OER_tau, a protocol, a learner's
gap to the Best fixed action, as the typed results a run's state keeps (no episodes)."""

from __future__ import annotations

from typing import Any, Literal

from davis_ag.benchmark.exact import BEST_FIXED
from davis_ag.benchmark.results import EvaluationResults, Metric, PairedGap, PolicyResult, Protocol, SceneGap

#: The grid actions of a single-plant evaluation.
SP_ACTIONS = ["forward", "backward", "left", "right", "up", "down", "done"]


def metric(mean: float, std: float = 0.01) -> Metric:
    """A metric of three sessions with ``mean`` and ``std``."""
    return Metric(mean=mean, std=std, sem=std, sessions=[mean - std, mean, mean + std])


def policy(oer_tau: float, std: float = 0.01, **fields: Any) -> PolicyResult:
    """A policy's row: OER_tau ``oer_tau`` ± ``std``; reward and length .5 ± .01, OER_0 .2 ± .01."""
    return PolicyResult(
        oer_tau=metric(oer_tau, std), reward=metric(0.5), length=metric(0.5), oer_0=metric(0.2), **fields
    )


def gap(
    mean: float,
    low: float,
    high: float,
    scenes: list[tuple[str, float, int, int]] | None = None,
    episodes: int = 600,
    **interval: float,
) -> PairedGap:
    """A paired gap; ``scenes``: ``(scene, gap, episodes, starts)`` each; ``interval``: ``scene_low``
    and ``scene_high``."""
    per_scene = [SceneGap(scene=s, gap=g, episodes=e, starts=n) for s, g, e, n in scenes or []]
    return PairedGap(gap=mean, low=low, high=high, episodes=episodes, per_scene=per_scene, **interval)


def results(
    oer: dict[str, float],
    gaps: dict[str, PairedGap] | None = None,
    scenes: list[str] | None = None,
    scenario: Literal["sp", "mp", "row"] = "sp",
    split: str = "test",
    **fields: Any,
) -> EvaluationResults:
    """An evaluation of the policies in ``oer`` (name: mean OER_tau), each learner in ``gaps`` with its
    gap to the Best fixed action; ``fields``: ``starts`` and ``split_rule`` (the protocol's), or the
    results' own fields."""
    protocol = Protocol(
        scenario=scenario,
        split=split,
        tau=3,
        episodes=200,
        sessions=3,
        seed=0,
        scenes=scenes if scenes is not None else ["Single-Strawberry/003", "Single-Strawberry/004"],
        dataset="tests",
        actions=SP_ACTIONS,
        starts=fields.pop("starts", None),
        start_rule="pairs",
        split_rule=fields.pop("split_rule", None),
    )
    rows = {name: policy(mean) for name, mean in oer.items()}
    for learner, paired in (gaps or {}).items():
        rows[learner].paired[BEST_FIXED] = paired
    return EvaluationResults(protocol=protocol, policies=rows, **fields)

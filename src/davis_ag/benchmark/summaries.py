"""Every summary of an evaluation, from its episodes: what the evaluation computes and what each
reader of a results file computes again before it trusts one.

A results file stores each policy's episodes and, beside them, their summary (Table 4's means and
stds over sessions, standard errors, action counts, paired gaps with their intervals). A reader
that ranked the stored summary would rank whatever someone typed into it; so the evaluation makes
its summaries here, and :func:`check_summaries` makes them again from the episodes and refuses a
file where one differs, naming the policy and the field. The episodes themselves are checked
against the dataset by ``davis-ag verify RESULTS.json --dataset DATA``
(:mod:`davis_ag.benchmark.replay`).
"""

from __future__ import annotations

import math
from dataclasses import asdict
from typing import Any

import numpy as np

from davis_ag.benchmark.exact import BEST_FIXED
from davis_ag.errors import UserError

#: The baselines every policy is compared with episode by episode, where the evaluation has them.
PAIRED_BASELINES: tuple[str, ...] = (BEST_FIXED, "Rand")
#: Metrics summarised over sessions: Table 4's, then the start's OER and, on the continuous
#: environment, the refused moves; with a robot, the seconds its moves took.
METRIC_KEYS: tuple[str, ...] = ("oer_tau", "reward", "length", "oer_0", "refused", "seconds")
#: How far a summary made again may differ from the stored one (JSON keeps floats exactly; this
#: only forgives another summation order).
TOLERANCE = 1e-9


def session_metrics(records: list[dict[str, Any]], keys: tuple[str, ...], sessions: int) -> dict[str, dict[str, Any]]:
    """Per key, the mean and population std of the session means, each session's mean and the
    standard error of the mean over all episodes (``sem``).

    Args:
        records: Every episode, each with its ``session``, in the order played.
        keys: The metrics to summarise.
        sessions: Sessions played (0 .. sessions - 1).
    """
    summary = {}
    for key in keys:
        per_session = [float(np.mean([r[key] for r in records if r["session"] == s])) for s in range(sessions)]
        values = [r[key] for r in records]
        summary[key] = {
            "mean": float(np.mean(per_session)),
            "std": float(np.std(per_session)),
            "sem": float(np.std(values) / np.sqrt(len(values))),
            "sessions": per_session,
        }
    return summary


def action_counts(records: list[dict[str, Any]], action_names: list[str] | tuple[str, ...]) -> dict[str, int]:
    """How often each grid action was played over all episodes."""
    chosen = np.bincount([a for r in records for a in r["actions"]], minlength=len(action_names))
    return {name: int(count) for name, count in zip(action_names, chosen)}


def mean_abs_action(records: list[dict[str, Any]], action_names: list[str] | tuple[str, ...]) -> dict[str, float]:
    """The mean magnitude of each continuous action component over all steps."""
    moves = np.abs(np.array([a for r in records for a in r["actions"]], dtype=np.float64))
    return dict(zip(action_names, moves.mean(axis=0).round(4).tolist()))


def paired_gaps(name: str, records: dict[str, list[dict[str, Any]]], seed: int) -> dict[str, dict[str, Any]]:
    """The paired gap of policy ``name`` to each of :data:`PAIRED_BASELINES` that played too, as
    the results file holds it (:class:`davis_ag.benchmark.results.PairedGap`'s fields).

    Raises:
        ValueError: when the two did not play the same episodes.
    """
    from davis_ag.benchmark.paired import paired_gap

    return {
        baseline: asdict(paired_gap(records[name], records[baseline], seed=seed))
        for baseline in PAIRED_BASELINES
        if baseline in records and baseline != name
    }


def check_summaries(results: Any, where: str) -> None:
    """Make every stored summary again from the episodes and refuse the file where one differs.

    Checked per policy: that it kept its episodes, ``sessions x episodes`` of them in session
    order; each metric's mean, std, sem and session means; the action counts (grid) or mean action
    magnitudes (continuous); every stored paired gap with its intervals and per-scene gaps (the
    bootstrap is seeded with the evaluation's seed, so it comes out as it was).

    Args:
        results: The results as read (:class:`davis_ag.benchmark.results.EvaluationResults`).
        where: The file, for the message.

    Raises:
        UserError: one line naming the file, the policy, the field, the stored and the recomputed value.
    """
    data = results.model_dump()
    protocol = data["protocol"]
    records: dict[str, list[dict[str, Any]]] = {}
    for name, policy in data["policies"].items():
        played = policy.get("episodes")
        if played is None:
            raise UserError(
                f"{where}: {name} kept no episodes, so its summary cannot be checked; evaluate it again "
                "with its episodes kept (davis-ag evaluate keeps them)"
            )
        expected = [s for s in range(protocol["sessions"]) for _ in range(protocol["episodes"])]
        if [e["session"] for e in played] != expected:
            raise UserError(
                f"{where}: {name} holds {len(played)} episodes, not {protocol['sessions']} sessions x "
                f"{protocol['episodes']} in session order as its protocol says; evaluate it again"
            )
        records[name] = played
        keys = tuple(k for k in METRIC_KEYS if policy.get(k) is not None)
        for key, metric in session_metrics(played, keys, protocol["sessions"]).items():
            _same(where, name, key, policy[key], metric)
        if policy.get("action_counts") is not None:
            _same(where, name, "action_counts", policy["action_counts"], action_counts(played, protocol["actions"]))
        if policy.get("mean_abs_action") is not None:
            moves = mean_abs_action(played, protocol["actions"])
            _same(where, name, "mean_abs_action", policy["mean_abs_action"], moves, tolerance=5e-5)
    for name, policy in data["policies"].items():
        stored = policy.get("paired") or {}
        try:
            gaps = paired_gaps(name, {n: records[n] for n in (name, *stored) if n in records}, protocol["seed"])
        except ValueError:  # paired_gap's refusal: the episodes are not the same starts
            raise UserError(
                f"{where}: {name} has paired gaps, but its episodes do not start where its baselines' do "
                "(scene, start, target): the episodes were edited after the evaluation; evaluate again to rank it"
            ) from None
        for baseline, gap in stored.items():
            if baseline not in gaps:
                raise UserError(
                    f"{where}: {name} has a gap to {baseline}, which is not among its policies; "
                    "evaluate them together again"
                )
            kept = {k: v for k, v in gap.items() if v is not None}  # one from before the interval over scenes lacks it
            _same(where, name, f"paired.{baseline}", kept, {k: v for k, v in gaps[baseline].items() if k in kept})


def _same(where: str, policy: str, field: str, stored: Any, made: Any, tolerance: float = TOLERANCE) -> None:
    """Refuse when ``stored`` and ``made`` differ (recursively), naming the first field that does."""
    difference = _first_difference(stored, made, field, tolerance)
    if difference is not None:
        path, old, new = difference
        old_text, new_text = _shown(old, new)
        raise UserError(
            f"{where}: {policy}'s {path} is {old_text} but its episodes give {new_text}: the summary "
            "does not match the episodes it summarises (edited after the evaluation?); evaluate again to rank it"
        )


def _first_difference(stored: Any, made: Any, path: str, tolerance: float) -> tuple[str, Any, Any] | None:
    if isinstance(stored, dict) and isinstance(made, dict):
        for key in sorted(set(stored) | set(made), key=str):
            if key not in stored or key not in made:
                return f"{path}.{key}", stored.get(key), made.get(key)
            found = _first_difference(stored[key], made[key], f"{path}.{key}", tolerance)
            if found:
                return found
        return None
    if isinstance(stored, (list, tuple)) and isinstance(made, (list, tuple)):
        if len(stored) != len(made):
            return f"{path} (length)", len(stored), len(made)
        for index, (a, b) in enumerate(zip(stored, made)):
            found = _first_difference(a, b, f"{path}[{index}]", tolerance)
            if found:
                return found
        return None
    if isinstance(stored, (int, float)) and isinstance(made, (int, float)) and not isinstance(stored, bool):
        close = math.isclose(float(stored), float(made), rel_tol=tolerance, abs_tol=tolerance)
        return None if close else (path, stored, made)
    return None if stored == made else (path, stored, made)


def _shown(a: Any, b: Any) -> tuple[str, str]:
    """Two differing values as text that tells them apart: numbers to as few digits as do (the
    table's three where they suffice), anything else as it is."""
    if isinstance(a, float) and isinstance(b, float):
        for digits in (3, 6, 9):
            if round(a, digits) != round(b, digits):
                return f"{a:.{digits}f}", f"{b:.{digits}f}"
    return repr(a), repr(b)

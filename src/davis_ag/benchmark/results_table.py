"""Table 4 as plain text from an :class:`~davis_ag.benchmark.results.EvaluationResults`: one row
per metric, one column per policy, the paired gaps, what the numbers rest on, and notes on what a
reader could mistake (a policy that plays one action, episodes that replay few starts)."""

from __future__ import annotations

from typing import Any

from davis_ag.benchmark.exact import BEST_FIXED
from davis_ag.benchmark.paired import FEW_SCENES
from davis_ag.benchmark.results import EvaluationResults, PolicyResult, Protocol, as_results, split_text, table_number
from davis_ag.benchmark.summaries import PAIRED_BASELINES

#: Table 4's metrics: key in the results, row label.
METRICS: dict[str, str] = {"oer_tau": "OER_tau", "reward": "Cum. Reward", "length": "Ep. Length"}


def format_table(results: EvaluationResults | dict[str, Any]) -> str:
    """Plain-text Table 4: one row per metric, one column per policy, ``mean ±std``, the paired
    gaps, and what the numbers rest on (the split's scenes and eligible starts).

    Args:
        results: What :func:`~davis_ag.benchmark.evaluation.evaluate_policies` returned (or its JSON).

    Returns:
        The table, lines joined by newlines.
    """
    results = as_results(results)
    protocol, policies = results.protocol, results.policies
    names = list(policies)
    label = f"{protocol.scenario.upper()} ({protocol.split})"
    cells = [[label, "Metric", *names]]
    for key, title in METRICS.items():
        row = ["", title]
        for name in names:
            stat = getattr(policies[name], key)
            row.append(f"{table_number(stat.mean)} ±{table_number(stat.std)}")
        cells.append(row)
    if any(policies[name].seconds for name in names):  # a robot moved the camera: what it cost
        cells.append(["", "Robot seconds", *(_seconds_cell(policies[n].seconds) for n in names)])
        cells.append(["", "OER gain per s", *(_gain_per_second(policies[n]) for n in names)])
    has_exact = any(policies[name].exact for name in names)
    if has_exact:
        for key, title in METRICS.items():
            cells.append(
                [
                    "",
                    f"{title} exact",
                    *(table_number(expected[key]) if (expected := policies[n].exact) else "-" for n in names),
                ]
            )
    baselines = [b for b in PAIRED_BASELINES if b in policies]
    shown_over_scenes = False
    for baseline in baselines:
        row, over_scenes = ["", f"gap to {baseline}"], ["", "  over scenes"]
        for name in names:
            gap = policies[name].paired.get(baseline)
            row.append(gap.text() if gap else "-")
            over_scenes.append((gap.scenes_text() if gap else None) or "-")
        cells.append(row)
        if any(cell != "-" for cell in over_scenes[2:]):
            cells.append(over_scenes)
            shown_over_scenes = True
    widths = [max(len(row[i]) for row in cells) for i in range(len(cells[0]))]
    lines = ["  ".join(c.ljust(w) for c, w in zip(row, widths)).rstrip() for row in cells]
    lines.insert(1, "-" * len(lines[0]))
    lines.append(
        f"mean ±std over sessions; {split_text(protocol)}"
        + ("; exact: expectation over the split's starts" if has_exact else "")
    )
    if baselines:
        lines.append(
            "gap: mean OER_tau minus the baseline's on the same episodes, [95 % bootstrap interval over episodes]"
            + (
                f"; over scenes: [the same, resampling the test scenes; coarse below {FEW_SCENES}]"
                if shown_over_scenes
                else ""
            )
        )
    if protocol.robot:
        where = "views" if protocol.environment == "davis_ag/TVM-v0" else "poses"
        lines.append(
            f"robot {protocol.robot['name']} ({protocol.robot['urdf']}, definition {protocol.robot['digest']}): "
            f"moves only between {where} it reaches; OER gain per s = (mean OER_tau - mean OER_0) / mean seconds"
        )
    if BEST_FIXED in policies:
        lines.append(
            f"{BEST_FIXED}: always {policies[BEST_FIXED].action}, the best single action by exact OER_tau on this split"
        )
    lines.extend(_warnings(results))
    return "\n".join(lines)


def replays_few_starts(protocol: Protocol) -> bool:
    """Whether an evaluation's episodes replay its split's eligible starts, each about twice or
    more: its intervals over episodes then say how sure the means are over those starts only.
    Section V-D's 3 x 200 episodes draw each start about once on a test split of Table 3's size."""
    return protocol.starts is not None and 2 * protocol.starts < protocol.episodes * protocol.sessions


def only_action(policy: PolicyResult) -> str | None:
    """The one action a policy played in every step of its episodes (a learner that collapsed to a
    fixed action), or None when it played several or its counts are not recorded."""
    played = [action for action, n in (policy.action_counts or {}).items() if n]
    return played[0] if len(played) == 1 else None


def _warnings(results: EvaluationResults) -> list[str]:
    """What a reader could mistake in the table: a policy that plays one action only (a collapsed
    learner looks like a method), and episodes that replay a few starts (the interval over
    episodes is then sure of those starts, not of the method)."""
    notes = []
    for name, policy in results.policies.items():
        if name != BEST_FIXED and (action := only_action(policy)):
            notes.append(f"note: {name} played {action} only: a fixed action, not a method; see {BEST_FIXED}")
    protocol = results.protocol
    if protocol.sessions == 1:
        notes.append("note: one session, so every ± (the spread of session means) is 0; section V-D plays 3")
    if replays_few_starts(protocol):
        notes.append(
            f"note: {protocol.sessions * protocol.episodes} episodes replay {protocol.starts} eligible starts: "
            "the intervals say how sure the means are over these starts, not over other scenes; "
            "a larger test split tells methods apart"
        )
    return notes


def _seconds_cell(stat: Any) -> str:
    return f"{stat.mean:.2f} ±{stat.std:.2f}" if stat else "-"


def _gain_per_second(policy: Any) -> str:
    """The OER an episode gained per robot second, as means over episodes (``-`` without seconds)."""
    if not policy.seconds or policy.seconds.mean <= 0:
        return "-"
    return f"{(policy.oer_tau.mean - policy.oer_0.mean) / policy.seconds.mean:.3f}"

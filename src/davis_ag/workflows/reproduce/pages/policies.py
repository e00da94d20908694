"""The parts of ``docs/results.md`` that show what each policy does, from a run's own records.

Per scenario: each learner (A2C, and PPO where the run trained it) against the ``Best fixed
action`` (:mod:`davis_ag.workflows.reproduce.pages.gaps`), its kept snapshot on the train split it was
chosen on, the exact expectations of the image-blind policies beside their sampled means, each
policy's action histogram (a table and Fig. 4c as a picture), and how each learner was trained and
played; then the learning curves (Fig. 4a) from the training records.
Pictures go to ``images/`` beside the page.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from davis_ag.benchmark.exact import BEST_FIXED, best_fixed_action
from davis_ag.benchmark.results import EvaluationResults, PolicyResult, TrainScore
from davis_ag.workflows.reproduce.groups import GROUPS
from davis_ag.workflows.reproduce.learners import LEARNERS, load_json_object, training_record
from davis_ag.workflows.reproduce.pages.gaps import (
    learner_gaps,
    paired_line,
    per_scene_table,
    scene_gap_figure,
    versus_best_fixed,
)
from davis_ag.workflows.reproduce.pages.paper_table4 import cell
from davis_ag.workflows.reproduce.state import RunState

#: Row order of the policies on the page.
POLICY_ORDER = ("A2C", "A2C (deterministic)", "PPO", "LRD", "UDD", "Rand", BEST_FIXED, "Oracle")
#: What each learner trains with besides the settings its record names (the SB3 defaults).
SB3_DEFAULTS_TEXT = {
    "A2C": "learning rate 7e-4, n_steps 5, gamma .99, vf_coef .5, max_grad_norm .5, RMSprop",
    "PPO": "gamma .99, gae_lambda .95, max_grad_norm .5, Adam; lin_X: X falling linearly to 0 over the run",
}


def learners_run(state: RunState, out: Path | None = None) -> list[str]:
    """The learners (:data:`LEARNERS`) this run evaluated or trained, from its records only (a run
    from before PPO names A2C alone, whatever the configuration now lists)."""
    rows = {name for result in state.results.values() for name in result.policies}
    return [
        learner
        for learner in LEARNERS
        if learner in rows or any(training_record(out, key, learner) for key in GROUPS.values())
    ]


def learners_in(policies: Mapping[str, PolicyResult]) -> list[str]:
    """The learners (:data:`LEARNERS`) an evaluation has a row of, in page order."""
    return [name for name in LEARNERS if name in policies]


def ordered(policies: Mapping[str, PolicyResult]) -> list[str]:
    """The run's policy names in page order (unknown names last, as they came)."""
    return [n for n in POLICY_ORDER if n in policies] + [n for n in policies if n not in POLICY_ORDER]


def exact_table(policies: Mapping[str, PolicyResult], fixed: dict[str, dict[str, float]] | None) -> list[str]:
    """Sampled mean ± standard error beside the exact expectation, per image-blind policy."""
    names = [n for n in ordered(policies) if policies[n].exact is not None]
    if not names:
        return []
    lines = [
        "Exact expectations (dynamic programming over the environment's move tables, every start "
        "of the split weighted as episodes draw it) beside the sampled means (± standard error of "
        "the mean over all episodes):",
        "",
        "| Policy | OER_tau sampled | OER_tau exact | Reward sampled | Reward exact | Length sampled | Length exact |",
        "|---|---|---|---|---|---|---|",
    ]
    for name in names:
        policy, row = policies[name], [name]
        exact = policy.exact or {}
        for key, stat in (("oer_tau", policy.oer_tau), ("reward", policy.reward), ("length", policy.length)):
            row += [f"{cell(stat.mean)} ± {cell(stat.sem)}", cell(exact[key])]
        lines.append("| " + " | ".join(row) + " |")
    if fixed:
        lines += [
            "",
            "Exact OER_tau of every fixed action on this split: "
            + ", ".join(f"{action} {cell(v['oer_tau'])}" for action, v in fixed.items())
            + ".",
        ]
    return [*lines, ""]


def action_table(policies: Mapping[str, PolicyResult], actions: list[str]) -> list[str]:
    """Share of each action per policy over every episode played (Fig. 4c as a table)."""
    names = [n for n in ordered(policies) if policies[n].action_counts is not None]
    if not names or not actions:
        return []
    lines = [
        "Share of each action over every step played (%):",
        "",
        "| Policy | " + " | ".join(actions) + " |",
        "|---" * (len(actions) + 1) + "|",
    ]
    for name in names:
        counts = policies[name].action_counts or {}
        total = max(sum(counts.values()), 1)
        lines.append(f"| {name} | " + " | ".join(f"{100 * counts.get(a, 0) / total:.0f}" for a in actions) + " |")
    return [*lines, ""]


def a2c_line(scenario: str, policies: Mapping[str, PolicyResult], out: Path | None, learner: str = "A2C") -> str | None:
    """How A2C (or another ``learner``) was trained (its settings, from the training record) and how
    it played."""
    from davis_ag.benchmark.algorithms import SB3_DEFAULT_SETTINGS

    if learner not in policies:
        return None
    record = training_record(out, GROUPS[scenario], learner)
    if learner == "A2C":
        settings = record.get("a2c_settings", SB3_DEFAULT_SETTINGS if record else None)
    else:
        settings = record.get("sb3_settings")
    changed = ", ".join(f"{k}={v}" for k, v in (settings or {}).items())
    trained = (
        "settings not recorded"
        if settings is None
        else (f"{changed} over " if changed else "")
        + f"Stable-Baselines3's {learner} defaults ({SB3_DEFAULTS_TEXT.get(learner, 'as SB3 sets them')})"
    )
    play = policies[learner].play or "deterministic"
    how = (
        "actions sampled from the policy"
        if play == "sampled"
        else "the most likely action at every step (deterministic)"
    )
    text = (
        f"{learner}: trained with {trained}, on starts drawn by the `{record.get('start_rule', 'scene')}` rule; "
        f"plays {how}."
    )
    if f"{learner} (deterministic)" in policies:
        text += f" `{learner} (deterministic)` is the same model taking its most likely action."
    if learner == "A2C":
        text += " The settings and the play were chosen on training scenes only (docs/benchmark.md)."
    else:
        text += (
            " Trained beside A2C on the same train split with the same steps, seed, network and "
            "keep-best-train rule; not tuned."
        )
    return text


@dataclass(frozen=True)
class TrainSplitGap:
    """A learner's kept snapshot against the best fixed action on the train split.

    Attributes:
        kept: The kept snapshot's OER_tau on fresh train episodes where the run scored it so,
            else its selection score.
        fresh: That fresh score's record (``oer_tau``, ``sessions``, ``episodes``), or None.
        best: The best fixed action's exact OER_tau on the train split.
        action: That action.
        starts: The train split's eligible starts.
        selection: The training record's ``selection`` (its kept step, episodes, play).
        scores: Its snapshot scores, OER_tau by step.
    """

    kept: float
    fresh: TrainScore | None
    best: float
    action: str
    starts: int
    selection: dict[str, Any]
    scores: dict[int, float]


def train_split_gap(
    scenario: str, result: EvaluationResults, out: Path | None, learner: str = "A2C"
) -> TrainSplitGap | None:
    """A learner's kept snapshot against the best fixed action on the train split, where it was chosen.

    Args:
        scenario: ``sp`` or ``mp``.
        result: The scenario's evaluation (its ``train_split``).
        out: The run's folder, for the learner's training record.
        learner: ``A2C`` or ``PPO``.

    Returns:
        The gap; None when the run has no train-split record for the learner.
    """
    train = result.train_split
    record = training_record(out, GROUPS[scenario], learner)
    selection = record.get("selection") or {}
    scores = {s["step"]: s["oer_tau"] for s in selection.get("scores", [])}
    if not train or not train.fixed_actions or selection.get("kept_step") not in scores:
        return None
    fixed = train.fixed_actions
    action = best_fixed_action(fixed)
    fresh = (train.learners or {}).get(learner)
    return TrainSplitGap(
        kept=fresh.oer_tau.mean if fresh else scores[selection["kept_step"]],
        fresh=fresh,
        best=fixed[action]["oer_tau"],
        action=action,
        starts=train.starts,
        selection=selection,
        scores=scores,
    )


def train_split_line(scenario: str, result: EvaluationResults, out: Path | None, learner: str = "A2C") -> str | None:
    """A learner's (A2C's) kept snapshot against the best fixed action on the train split, where it
    was chosen.

    Beside the test verdict this separates a policy that did not learn (no better than one move
    on the scenes it trained on) from one that does not carry over to unseen scenes.
    """
    found = train_split_gap(scenario, result, out, learner)
    if found is None:
        return None
    selection, scores = found.selection, found.scores
    gap = found.kept - found.best
    last_step = max(scores)
    chosen_by = f"{selection['episodes']} {selection['play']} episodes"
    fresh = found.fresh
    if fresh:
        # The selection score is the best of many noisy ones, so it runs high: fresh episodes say more.
        played = f"{fresh.sessions} x {fresh.episodes} fresh episodes, as on test"
        chosen_by = (
            f"{played}; {cell(scores[selection['kept_step']])} in the {chosen_by} that chose it, the best of "
            f"{len(scores)} such scores, which runs high"
        )
    return (
        f"On the train split ({found.starts:,} eligible starts), where the snapshot was chosen: {learner}'s "
        f"kept snapshot ({selection['kept_step']:,} steps) scores OER_tau {cell(found.kept)} "
        f"({chosen_by}), the best fixed action there "
        f"(always `{found.action}`) {cell(found.best)} exactly, {cell(abs(gap))} "
        f"{'above' if gap >= 0 else 'below'} it; "
        f"the last snapshot ({last_step:,} steps) {cell(scores[last_step])}. "
        "Above it on train but not on test: a policy that does not carry over to unseen scenes; "
        "not above it on train: a policy that did not learn."
    )


def action_figure(scenario: str, out: Path | None, page: Path) -> str | None:
    """Draw Fig. 4c/5 of the run's results into ``images/`` beside the page; its Markdown link."""
    from davis_ag.errors import UserError
    from davis_ag.figures.benchmark_plots import plot_actions

    results = load_json_object(out / "results" / f"{GROUPS[scenario]}.json") if out else {}
    if not results.get("policies"):
        return None
    target = page.parent / "images" / f"{page.stem}-{GROUPS[scenario]}-actions"
    try:
        plot_actions(results, target, formats=("png",), source=f"{GROUPS[scenario]}.json")
    except (UserError, KeyError, TypeError):
        return None  # results from before per-episode records: the table above still shows the shares
    return f"![actions per policy and A2C's choices, {GROUPS[scenario]}](images/{target.name}.png)"


def train_split_references(results: Mapping[str, EvaluationResults]) -> dict[str, float]:
    """The best fixed action's exact train-split OER_tau per group, labelled for the learning
    curve's snapshot panel, from each scenario's evaluation (``result.train_split``)."""
    references = {}
    for scenario, result in results.items():
        fixed = result.train_split.fixed_actions if result.train_split else None
        if fixed and scenario in GROUPS:
            action = best_fixed_action(fixed)
            references[f"{GROUPS[scenario]}: best fixed action (always {action}), exact"] = fixed[action]["oer_tau"]
    return references


def learning_curve_section(
    out: Path | None, page: Path, results: Mapping[str, EvaluationResults] | None = None
) -> list[str]:
    """Fig. 4a from the run's training records, drawn into ``images/`` beside the page, with the
    best fixed action's train-split score across the snapshots where ``results`` (the run's
    evaluations by scenario) hold it."""
    from davis_ag.errors import UserError
    from davis_ag.figures.training_curve import plot_learning_curve

    if out is None:
        return []
    found = {
        (key, learner): r
        for key in GROUPS.values()
        for learner in LEARNERS
        if (r := training_record(out, key, learner))
    }
    alone = {learner for _, learner in found} <= {"A2C"}
    # A2C alone (the paper's run) labels its curves by group only; beside another learner, each says which.
    records = {key if alone else f"{key} ({learner})": r for (key, learner), r in found.items()}
    title = "A2C learning curve" if alone else "Learning curves"
    if not records:
        return []
    target = page.parent / "images" / f"{page.stem}-learning-curve"
    try:
        plotted = plot_learning_curve(
            records, target, formats=("png",), references=train_split_references(results or {})
        )
    except UserError:
        return [
            f"## {title}",
            "",
            "The training records hold no learning curve (models trained before curves were kept).",
            "",
        ]
    lines = [
        f"## {title}",
        "",
        "Mean episodic reward per 1,000 training steps on the train split (Fig. 4a), read from "
        "each model's training record"
        + (
            "; below it, each snapshot's train-split OER_tau against the best fixed action's there "
            "(dashed), which a learner must pass to have learned more than one move:"
            if train_split_references(results or {})
            else ":"
        ),
        "",
        f"![{title}](images/{target.name}.png)",
        "",
    ]
    for key, data in plotted.data.items():
        smoothed = data["smoothed"]
        if smoothed:
            lines.append(
                f"- {key}: rolling mean {cell(smoothed[0])} at {data['steps'][0]:,} steps, "
                f"{cell(smoothed[-1])} at {data['steps'][-1]:,} steps."
            )
    return [*lines, ""]


def policy_sections(scenario: str, result: EvaluationResults, out: Path | None, page: Path) -> list[str]:
    """Everything the page shows per scenario about what the policies do."""
    policies = result.policies
    learners = learners_in(policies) or ["A2C"]
    lines: list[str] = []
    for learner in learners:
        for line in (versus_best_fixed(policies, learner), paired_line(result, learner)):
            if line:
                lines += [line, ""]
    gaps = learner_gaps(result, learners)
    lines += per_scene_table(gaps)
    chart = scene_gap_figure(scenario, result, gaps, page)
    if chart:
        lines += [chart, ""]
    if BEST_FIXED in policies:
        lines += [
            f"`{BEST_FIXED}` is the best of the policies that always play the same action, chosen "
            "by exact OER_tau on this split and played on the same episodes: a learner that "
            "collapsed to one move scores no better than it.",
            "",
        ]
    for learner in learners:
        for line in (train_split_line(scenario, result, out, learner), a2c_line(scenario, policies, out, learner)):
            if line:
                lines += [line, ""]
    lines += exact_table(policies, result.fixed_actions)
    lines += action_table(policies, list(result.protocol.actions))
    figure = action_figure(scenario, out, page)
    if figure:
        lines += [figure, ""]
    return lines

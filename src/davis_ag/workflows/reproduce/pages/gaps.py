"""Each learner against the ``Best fixed action`` on a results page: by the two rows' standard
deviations, episode by episode with the paired bootstrap intervals (over episodes and over test
scenes), and per test scene as a table and a chart.

A learner that collapsed to one move scores no better than the best fixed action, so these gaps,
not the learner's own OER_tau, say whether it learned anything that carries to unseen scenes.
"""

from __future__ import annotations

from collections.abc import Mapping
from pathlib import Path

from davis_ag.benchmark.exact import BEST_FIXED
from davis_ag.benchmark.paired import CONFIDENCE, FEW_SCENES, RESAMPLES
from davis_ag.benchmark.results import EvaluationResults, PairedGap, PolicyResult, SceneGap
from davis_ag.workflows.reproduce.groups import GROUPS
from davis_ag.workflows.reproduce.pages.paper_table4 import cell, signed


def versus_best_fixed(policies: Mapping[str, PolicyResult], learner: str = "A2C") -> str | None:
    """Whether a learner's OER_tau beats the Best fixed action's by more than their stds added."""
    if learner not in policies or BEST_FIXED not in policies:
        return None
    a, b = policies[learner].oer_tau, policies[BEST_FIXED].oer_tau
    gap, spread = a.mean - b.mean, a.std + b.std
    action = policies[BEST_FIXED].action or "?"
    verdict = "**beats** it" if gap > spread else "**does not beat** it by more than their standard deviations added"
    return (
        f"{learner} against `{BEST_FIXED}` (always `{action}`): OER_tau {cell(a.mean)} ± {cell(a.std)} "
        f"against {cell(b.mean)} ± {cell(b.std)}, {cell(gap) if gap >= 0 else '-' + cell(-gap)} "
        f"apart, stds added {cell(spread)}: {learner} {verdict}."
    )


def learner_gap(result: EvaluationResults, learner: str = "A2C") -> PairedGap | None:
    """A learner's (A2C's, PPO's) gap to the Best fixed action on the same episodes, as the
    evaluation made it; None where the evaluation has not both rows."""
    row = result.policies.get(learner)
    return row.paired.get(BEST_FIXED) if row is not None else None


def paired_line(result: EvaluationResults, learner: str = "A2C") -> str | None:
    """A learner minus the Best fixed action on the same episodes: the bootstrap interval and each
    test scene."""
    paired = learner_gap(result, learner)
    if paired is None:
        return None
    scenes = paired.per_scene
    if paired.scene_low is None or paired.scene_high is None:
        over_scenes = (
            "The interval covers the starts these test scenes hold, not other scenes; the per-scene gaps "
            "hint at how much the scene matters."
        )
    elif len(scenes) < FEW_SCENES:
        over_scenes = (
            f"Resampling the {len(scenes)} test scenes played instead says little with so few: its "
            f"{CONFIDENCE:.0%} interval, {signed(paired.scene_low)} to {signed(paired.scene_high)}, is "
            "about the range of their own gaps; the table below is the better hint of how another scene "
            "would score."
        )
    else:
        over_scenes = (
            f"Resampling the {len(scenes)} test scenes played instead (each with all its episodes: would the "
            f"gap hold on other scenes like these?), the {CONFIDENCE:.0%} interval is "
            f"{signed(paired.scene_low)} to {signed(paired.scene_high)}, "
            f"{_side(paired.scene_low, paired.scene_high)} zero."
        )
    return (
        f"Episode by episode (every policy plays the same {paired.episodes} episodes), {learner} minus "
        f"`{BEST_FIXED}`: {signed(paired.gap)}, {CONFIDENCE:.0%} bootstrap interval over episodes "
        f"{signed(paired.low)} to {signed(paired.high)} ({RESAMPLES:,} resamples), "
        f"{_side(paired.low, paired.high)} zero. "
        "{} is ahead on {} of the {} test scenes played (the table below). ".format(learner, *scenes_ahead(paired))
        + over_scenes
    )


def learner_gaps(result: EvaluationResults, learners: list[str]) -> dict[str, PairedGap]:
    """Each learner's paired gap to the Best fixed action in a scenario's evaluation, where it has one."""
    return {learner: p for learner in learners if (p := learner_gap(result, learner)) is not None}


def scenes_ahead(paired: PairedGap) -> tuple[int, int]:
    """The test scenes a learner is ahead on, and those its episodes played."""
    scenes = paired.per_scene
    return sum(s.gap > 0 for s in scenes), len(scenes)


def per_scene_table(gaps: dict[str, PairedGap]) -> list[str]:
    """Each learner minus the Best fixed action on each test scene (:func:`learner_gaps`), as a
    table (empty without gaps)."""
    if not gaps:
        return []
    scenes: dict[str, tuple[SceneGap, dict[str, float]]] = {}  # the first learner's record of it, each gap
    for learner, paired in gaps.items():
        for scene in paired.per_scene:
            scenes.setdefault(scene.scene, (scene, {}))[1][learner] = scene.gap
    lines = [
        f"Per test scene, each learner's mean OER_tau minus `{BEST_FIXED}`'s over the scene's episodes:",
        "",
        "| Scene | Episodes | Distinct starts | " + " | ".join(gaps) + " |",
        "|---|---:|---:|" + "---:|" * len(gaps),
    ]
    for name in sorted(scenes):
        first, row = scenes[name]
        cells = [signed(row[learner]) if learner in row else "-" for learner in gaps]
        lines.append(f"| {name} | {first.episodes} | {first.starts:,} | " + " | ".join(cells) + " |")
    lines.append("| ahead on | | | " + " | ".join("{} of {}".format(*scenes_ahead(p)) for p in gaps.values()) + " |")
    return [*lines, ""]


def scene_gap_figure(scenario: str, result: EvaluationResults, gaps: dict[str, PairedGap], page: Path) -> str | None:
    """Draw the per-scene gaps (:func:`learner_gaps`) into ``images/`` beside the page; its
    Markdown link (None without gaps)."""
    from davis_ag.figures.result_charts import plot_scene_gaps

    if not gaps:
        return None
    target = page.parent / "images" / f"{page.stem}-{GROUPS[scenario]}-scene-gaps.png"
    split = result.protocol.split
    plot_scene_gaps(
        {learner: gap.model_dump() for learner, gap in gaps.items()}, target, f"{GROUPS[scenario]}, {split} split"
    )
    return f"![each learner minus the Best fixed action per test scene, {GROUPS[scenario]}](images/{target.name})"


def _side(low: float, high: float) -> str:
    """Where an interval lies against zero: ``above``, ``below`` or ``on both sides of``."""
    return "above" if low > 0 else "below" if high < 0 else "on both sides of"

"""A Table 4 page's section on both readings of the paper's 70/30 split (issue 59), written from
the records of two ``reproduce`` runs of one configuration under different split rules.

Section V-D says "the same split is applied to use 70 % and 30 % data for training and test
environments". Read as a split of the scenes (``scenes``), no test scene was trained on; read as
a split of the episode starts (``starts``), the test starts come from the scenes the agent
trained on. The section sets each policy's OER_tau under both beside the paper's, each learner's
gain over Rand under both beside the paper's ("over 18 %"), and says from the numbers which
reading comes closer to the paper and how far a score moves with the reading alone.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass
from pathlib import Path

from davis_ag.benchmark.results import EvaluationResults
from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.pages.paper_table4 import PAPER_TABLE4, TITLES, cell, signed
from davis_ag.workflows.reproduce.pages.policies import ordered
from davis_ag.workflows.reproduce.pages.provenance import stage_rows
from davis_ag.workflows.reproduce.state import RunState

#: The learners whose gain over Rand the section gives (the paper reports A2C's).
LEARNER_NAMES = ("A2C", "PPO")
#: The section's heading, so a page's reader (and its test) can find it.
HEADING = "## Both readings of the paper's 70/30 split"


@dataclass(frozen=True)
class RuleRun:
    """One run of the comparison: its configuration, its records and its folder.

    Attributes:
        config: The run's configuration (its ``split_rule`` names the reading).
        state: Its records (``results`` per scenario, ``stages``).
        out: Its folder, for the stage times (None: the stage records alone).
    """

    config: ReproduceConfig
    state: RunState
    out: Path | None


def gain_over_rand(oer: float, rand: float) -> str:
    """A policy's OER_tau over Rand's in per cent, signed (``+18.7 %``), as section VI's "over 18 %"."""
    return f"{100 * (oer / rand - 1):+.1f} %"


def run_hours(run: RuleRun) -> float:
    """The run's wall time, the sum of its stage table's rows (the page's ``total``)."""
    return sum(seconds for _, seconds, _, _ in stage_rows(run.state, run.out)) / 3600


def split_rules_section(runs: Sequence[RuleRun]) -> list[str]:
    """The section's lines: per scenario both runs' OER_tau beside the paper's, the gains over Rand
    and what the numbers say.

    Args:
        runs: Two or more runs of one configuration under different split rules, the page's own
            first.

    Returns:
        Markdown lines, the heading first.
    """
    rules = [run.config.split_rule for run in runs]
    hours = ", ".join(f"`{run.config.split_rule}` {run_hours(run):.1f} h" for run in runs)
    lines = [
        HEADING,
        "",
        'Section V-D: "the same split is applied to use 70 % and 30 % data for training and test '
        'environments". Split by scene (`scenes`), no test episode starts in a scene a learner trained on; '
        "split by episode start (`starts`: each scene's eligible (view, target) starts 70/30), the test "
        "starts come from the scenes it trained on. The same configuration "
        f"(`{runs[0].config.name}`, dataset seed {runs[0].config.seed}) was run under each rule; their "
        f"wall times: {hours} (each run's own page has its stage table). A baseline learns nothing, so "
        "its change between the readings is the test starts' own (Rand's: how hard they are to improve "
        "by chance; the Oracle's: how much there is to gain); a learner's change beyond Rand's is what "
        "training on the test scenes is worth to it.",
        "",
    ]
    for scenario in ("sp", "mp"):
        results = [run.state.results.get(scenario) for run in runs]
        if any(result is None for result in results):
            missing = [rule for rule, result in zip(rules, results) if result is None]
            lines += [f"### {TITLES[scenario]}", "", f"Not evaluated yet under `{'`, `'.join(missing)}`.", ""]
            continue
        lines += _scenario_lines(scenario, rules, [r for r in results if r is not None])
    return lines


def _scenario_lines(scenario: str, rules: list[str], results: list[EvaluationResults]) -> list[str]:
    """One scenario's tables and sentences (every run evaluated it)."""
    paper = PAPER_TABLE4[scenario]["oer_tau"]
    names = [name for name in ordered(results[0].policies) if all(name in r.policies for r in results)]
    lines = [
        f"### {TITLES[scenario]}",
        "",
        "| Policy | " + " | ".join(f"OER_tau `{rule}`" for rule in rules) + " | OER_tau paper |",
        "|---|" + "---|" * (len(rules) + 1),
    ]
    for name in names:
        ours = [f"{cell(r.policies[name].oer_tau.mean)} ± {cell(r.policies[name].oer_tau.std)}" for r in results]
        lines.append(f"| {name} | " + " | ".join(ours) + f" | {cell(paper.get(name))} |")
    oer_0 = [r.policies["Rand"].oer_0.mean if "Rand" in r.policies else None for r in results]
    lines.append("| start OER_0 | " + " | ".join(cell(v) for v in oer_0) + " | – |")
    learners = [name for name in LEARNER_NAMES if name in names]
    if "Rand" not in names or not learners:
        return [*lines, ""]
    lines += [
        "",
        "| Learner over Rand | " + " | ".join(f"`{rule}`" for rule in rules) + " | paper |",
        "|---|" + "---|" * (len(rules) + 1),
    ]
    rand = [r.policies["Rand"].oer_tau.mean for r in results]
    for name in learners:
        gains = [gain_over_rand(r.policies[name].oer_tau.mean, base) for r, base in zip(results, rand)]
        on_paper = gain_over_rand(paper[name], paper["Rand"]) if name in paper else "–"
        lines.append(f"| {name} | " + " | ".join(gains) + f" | {on_paper} |")
    lines += ["", *_what_it_says(rules, results, paper, learners), ""]
    return lines


def _what_it_says(
    rules: list[str], results: list[EvaluationResults], paper: Mapping[str, float], learners: list[str]
) -> list[str]:
    """The sentences the numbers support: which reading's A2C is nearer the paper's, and how far
    each learner moves between the first two readings beside the moves of Rand and the Oracle."""
    sentences = []
    if "A2C" in learners and "A2C" in paper:
        a2c = [r.policies["A2C"].oer_tau.mean for r in results]
        nearest = min(range(len(rules)), key=lambda i: abs(a2c[i] - paper["A2C"]))
        measured = ", ".join(f"{cell(v)} under `{rule}`" for v, rule in zip(a2c, rules))
        sentences.append(
            f"The paper's A2C scores {cell(paper['A2C'])}; ours {measured}: the `{rules[nearest]}` "
            f"reading comes nearer it, {signed(a2c[nearest] - paper['A2C'])} from it."
        )
    first, second = results[0].policies, results[1].policies

    def move(name: str) -> str:
        return signed(second[name].oer_tau.mean - first[name].oer_tau.mean)

    moves = " and ".join(f"{name} {move(name)}" for name in learners)
    owners = {"Rand": "Rand's", "Oracle": "the Oracle's"}
    fixed = " and ".join(
        f"{owner} by {move(name)}" for name, owner in owners.items() if name in first and name in second
    )
    sentences.append(
        f"From `{rules[0]}` to `{rules[1]}`, OER_tau moves by {moves}; {fixed} (neither learns: their "
        "moves are the test starts' own). A score on this benchmark is comparable only with scores "
        "under the same split rule."
    )
    return sentences

"""The blocks a results page in a project's ``docs/`` writes beside it: the README's short Table 4
and docs/benchmark.md's line on which run the page shows and how long its stages took.

Both are written from the same records as the page (:mod:`davis_ag.workflows.reproduce.pages.results`), so
no number of a run is ever copied into the README or the docs by hand.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any

from davis_ag.benchmark.exact import BEST_FIXED
from davis_ag.benchmark.paired import CONFIDENCE, FEW_SCENES
from davis_ag.benchmark.results import EvaluationResults
from davis_ag.workflows.reproduce.clock import machines
from davis_ag.workflows.reproduce.configs import ReproduceConfig, beside_table4
from davis_ag.workflows.reproduce.groups import GROUPS
from davis_ag.workflows.reproduce.learners import LEARNERS
from davis_ag.workflows.reproduce.pages.gaps import learner_gap, scenes_ahead
from davis_ag.workflows.reproduce.pages.paper_table4 import (
    PAPER_ORDERINGS,
    PAPER_TABLE4,
    PAPER_TABLE4_STD,
    TITLES,
    cell,
    ordering_failures,
    signed,
)
from davis_ag.workflows.reproduce.pages.policies import learners_run, train_split_gap
from davis_ag.workflows.reproduce.pages.provenance import one_whole_hours
from davis_ag.workflows.reproduce.state import RunState, StageRecord

if TYPE_CHECKING:
    from davis_ag.workflows.reproduce.pages.split_rules import RuleRun

#: The README's block that holds the run's OER_tau beside Table 4's (see :func:`readme_block`).
README_MARKER = "results-table4"
#: docs/benchmark.md's block that names the run results.md shows and its hours (:func:`run_block`).
RUN_MARKER = "results-run"


def readme_block(
    config: ReproduceConfig, state: RunState, out: Path | None = None, beside: Sequence[RuleRun] = ()
) -> str:
    """The README's short Table 4: OER_tau, ours beside the paper's, whether the orderings hold,
    and each learner against the best fixed action on test and on train.

    Args:
        config: The run's :class:`~davis_ag.workflows.reproduce.configs.ReproduceConfig`.
        state: The run's records (its ``results``).
        out: The run's folder, for the learners' training records (the train-split gap).
        beside: The same configuration's runs under other split rules: each adds its row under
            ours, named by its rule (the orderings and gaps stay the run's own).

    Returns:
        Markdown: a line on the run, a table, a line per ordering, a line per learner.
    """
    results = state.results
    learners = [n for n in LEARNERS if n == "A2C" or n in learners_run(state)]
    head = (
        f"`{config.name}` run (docs/results.md): {config.sp_scenes} SP strawberry and {config.mp_scenes} "
        f"MP vine scenes at {config.size[0]}x{config.size[1]}, {' and '.join(learners)} "
        f"{config.sp_timesteps:,} (SP) and "
        f"{config.mp_timesteps:,} (MP) steps; OER_tau, mean ± std over {config.sessions} sessions of "
        f"{config.episodes} episodes on the split each row names. Table 4's rows are the paper's."
    )
    for run in beside:
        head += (
            f" Rows under split rule `{run.config.split_rule}` are the same configuration's run under that reading "
            "of the paper's 70/30 split (docs/results.md, \"Both readings of the paper's 70/30 split\")."
        )
    extra = [n for n in learners if n != "A2C"]  # learners the paper did not train: ours only
    columns = ["A2C", *extra, "LRD", "UDD", "Rand", "Oracle", BEST_FIXED]
    lines = [
        head,
        "",
        "| | A2C | "
        + "".join(f"{n} (ours only) | " for n in extra)
        + "LRD | UDD | Rand | Oracle (ours only) | Best fixed action (ours only) |",
        "|---" * (len(columns) + 1) + "|",
    ]
    verdicts = []
    for scenario in ("sp", "mp"):
        result = results.get(scenario)
        if result is not None:
            policies = result.policies
            lines.append(_our_row(scenario, result, columns))
            lines += [_our_row(scenario, r, columns) for run in beside if (r := run.state.results.get(scenario))]
            failures = ordering_failures(PAPER_ORDERINGS[scenario], {n: p.oer_tau for n, p in policies.items()})
            verdict = (
                "not checked"
                if failures is None
                else "**holds**"
                if not failures
                else "**does not hold** (" + "; ".join(failures) + ")"
            )
            verdicts.append(f"{TITLES[scenario]}: {' '.join(PAPER_ORDERINGS[scenario])} {verdict}.")
        else:
            lines.append(f"| {TITLES[scenario]}, ours | not run yet |" + " |" * (len(columns) - 1))
        paper = PAPER_TABLE4[scenario]["oer_tau"]
        lines.append(
            f"| {TITLES[scenario]}, paper (Table 4) | "
            + " | ".join(
                f"{cell(paper[n])} ± {cell(PAPER_TABLE4_STD[scenario]['oer_tau'][n])}" if n in paper else "-"
                for n in columns[:-2]
            )
            + " | - | - |"
        )
    if verdicts:
        lines += [
            "",
            "The paper's orderings in this run (`~`: means within their two standard deviations "
            "added): " + " ".join(verdicts),
        ]
    gaps = {
        learner: found
        for learner in learners
        if (found := [g for s in ("sp", "mp") if (g := _learner_gaps(s, results.get(s), out, learner))])
    }
    if gaps:
        lines += [
            "",
            f"Each learner minus `{BEST_FIXED}` on the same test episodes ({CONFIDENCE:.0%} bootstrap "
            f"interval over episodes), the test scenes it is ahead on, the {CONFIDENCE:.0%} interval when the "
            "test scenes themselves are resampled (over scenes: whether the gap would hold on other scenes "
            f"like them; coarse below {FEW_SCENES}), "
            "and on the train split its kept snapshot minus the best fixed action there (ahead on train "
            "only: it does not carry over to unseen scenes; ahead on neither: it did not learn):",
            "",
        ]
        lines += [f"- {learner}: " + "; ".join(found) + "." for learner, found in gaps.items()]
    return "\n".join(lines)


def _our_row(scenario: str, result: EvaluationResults, columns: list[str]) -> str:
    """``| SP strawberry, ours (26 test scenes, split rule `scenes`) | .457 ± .008 | ... |``."""
    policies = result.policies
    scenes, split = len(result.protocol.scenes), result.protocol.split
    rule = result.protocol.split_rule or "scenes"
    cells = [
        f"{cell(policies[n].oer_tau.mean)} ± {cell(policies[n].oer_tau.std)}" if n in policies else "–" for n in columns
    ]
    return (
        f"| {TITLES[scenario]}, ours ({scenes} {split} scene{'s' if scenes != 1 else ''}, "
        f"split rule `{rule}`) | " + " | ".join(cells) + " |"
    )


def _learner_gaps(scenario: str, result: EvaluationResults | None, out: Path | None, learner: str) -> str | None:
    """``SP strawberry +.030 (+.020 to +.039; over scenes +.016 to +.048), ahead on 18 of the 23
    test scenes played, train +.040``."""
    paired = learner_gap(result, learner) if result is not None else None
    if result is None or paired is None:
        return None
    scenes = paired.per_scene
    intervals = f"{signed(paired.low)} to {signed(paired.high)}"
    if paired.scene_low is not None and paired.scene_high is not None:
        intervals += f"; over scenes {signed(paired.scene_low)} to {signed(paired.scene_high)}"
        if len(scenes) < FEW_SCENES:
            intervals += f", coarse with {len(scenes)}"
    text = f"{TITLES[scenario]} {signed(paired.gap)} ({intervals})"
    if scenes:
        text += ", ahead on {} of the {} test scenes played".format(*scenes_ahead(paired))
    train = train_split_gap(scenario, result, out, learner)
    if train is not None:
        text += f", train {signed(train.kept - train.best)}"
    return text


def run_block(config: ReproduceConfig, state: RunState, stages: list[tuple[str, float, list[dict[str, Any]]]]) -> str:
    """docs/benchmark.md's line on the run results.md shows: its configuration, test splits and the
    wall time of every stage, as the run's clock measured them.

    Args:
        config: The run's :class:`~davis_ag.workflows.reproduce.configs.ReproduceConfig`.
        state: The run's records (its ``results`` and ``stages``).
        stages: ``(stage, seconds, sittings)`` per stage in the run's order, as results.md's
            "Wall time per stage" table has them, with the run's clock's sittings of each.

    Returns:
        One Markdown paragraph.
    """
    splits = []
    for scenario in ("sp", "mp"):
        result = state.results.get(scenario)
        if result is not None:
            protocol = result.protocol
            starts = f", {protocol.starts:,} eligible starts" if protocol.starts is not None else ""
            splits.append(f"{TITLES[scenario]} {len(protocol.scenes)} {protocol.split} scenes{starts}")
        else:
            splits.append(f"{TITLES[scenario]} not evaluated yet")
    per_group = []
    for scenario, key in GROUPS.items():
        times = (
            ", ".join(
                _stage_hours(stage.partition(": ")[2], seconds, state.stages.get(stage), sittings)
                for stage, seconds, sittings in stages
                if stage.startswith(f"{key}: ")
            )
            or "no stage finished yet"
        )
        per_group.append(f"{TITLES[scenario]}: {times}")
    where = machines([sitting for _, _, sittings in stages for sitting in sittings])
    total = sum(seconds for _, seconds, _ in stages)
    return (
        f"[results.md](results.md) shows the `{config.name}` run ({beside_table4(config)}): "
        f"{config.sp_scenes} SP strawberry and {config.mp_scenes} MP vine scenes at "
        f"{config.size[0]}x{config.size[1]}; evaluated on {'; '.join(splits)}. Its stages took "
        f"{total / 3600:.1f} hours of wall time by the run's clock ({'; '.join(per_group)})"
        + (f", on {where}" if where != "-" else "")
        + "; results.md's \"Wall time per stage\" gives each stage's sittings and code."
    )


def _stage_hours(step: str, seconds: float, entry: StageRecord | None, sittings: list[dict[str, Any]]) -> str:
    """``validate 0.43 h``; a stage done whole again by later sittings reads by one whole run of it."""
    one = one_whole_hours(step, entry, sittings)
    if one is None:
        return f"{step} {seconds / 3600:.2f} h"
    return f"{step} {one:.2f} h ({len(sittings)} sittings, each doing it whole: {seconds / 3600:.2f} h in all)"


#: The page whose run the README's Table 4 block and docs/benchmark.md's run block show.
HEADLINE_PAGE = "results.md"


def write_blocks_beside(
    page: Path,
    config: ReproduceConfig,
    state: RunState,
    out: Path | None,
    stages: list[tuple[str, float, list[dict[str, Any]]]],
    beside: Sequence[RuleRun] = (),
) -> None:
    """Rewrite the README's and docs/benchmark.md's blocks of a results page in a project's ``docs/``.

    Only the headline page, ``docs/results.md``, writes them: a page written elsewhere (a work
    folder), another page in ``docs/`` (a smaller run's beside it), a page whose README or
    benchmark.md has no such block and a page of a run under another split rule than ``scenes``
    leave both alone.

    Args:
        page: The results page just written.
        config: The run's configuration.
        state: The run's records.
        out: The run's folder.
        stages: ``(stage, seconds, sittings)`` per stage (:func:`run_block`).
        beside: The same configuration's runs under other split rules (their rows in the README's).
    """
    from davis_ag.atomic_files import write_marked_section

    folder = Path(page).absolute().parent
    # The blocks are the headline run's, under the paper's reading (scenes): a page of another
    # rule's run, or of another run, stands beside docs/results.md and leaves them alone.
    if folder.name != "docs" or Path(page).name != HEADLINE_PAGE or config.split_rule != "scenes":
        return
    for target, marker, text in (
        (folder.parent / "README.md", README_MARKER, lambda: readme_block(config, state, out, beside)),
        (folder / "benchmark.md", RUN_MARKER, lambda: run_block(config, state, stages)),
    ):
        if target.is_file() and f"<!-- {marker}:start -->" in target.read_text():
            write_marked_section(target, marker, text())

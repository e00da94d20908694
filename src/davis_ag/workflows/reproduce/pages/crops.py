"""The ``crops`` run's page: a ladder of how hard each plant-library crop is for active vision.

Written from the run's records (``state.json``) after every benchmark: per crop and scenario, the
test split's scenes and eligible starts, the mean start OER (OER_0), Rand, the Best fixed action,
the exact Oracle and each learner with its paired gap to the Best fixed action (95 % bootstrap
interval over the same test episodes), the same as a ladder chart (PNG), and under it the run's
wall time by kind of stage. Into docs/crops.md it goes between the ``crops-run`` markers; any other
path gets a page of its own.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Mapping
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import write_marked_section, write_text_atomic
from davis_ag.benchmark.exact import BEST_FIXED
from davis_ag.benchmark.paired import CONFIDENCE
from davis_ag.benchmark.results import EvaluationResults, PolicyResult
from davis_ag.benchmark.results_table import replays_few_starts
from davis_ag.workflows.reproduce.configs import ReproduceConfig
from davis_ag.workflows.reproduce.groups import group_key
from davis_ag.workflows.reproduce.pages.gaps import learner_gap
from davis_ag.workflows.reproduce.pages.paper_table4 import cell, signed
from davis_ag.workflows.reproduce.pages.provenance import stage_rows
from davis_ag.workflows.reproduce.state import RunState

#: The marker of docs/crops.md's run table.
CROPS_MARKER = "crops-run"


def _oer(policies: Mapping[str, PolicyResult], name: str) -> float | None:
    """A policy's mean OER_tau, None where it was not played."""
    return policies[name].oer_tau.mean if name in policies else None


def _start_oer(policies: Mapping[str, PolicyResult]) -> float | None:
    """The mean OER at the episodes' starts (OER_0, the same for every policy: LRD's row), None
    where LRD was not played."""
    return policies["LRD"].oer_0.mean if "LRD" in policies else None


def _score(policies: Mapping[str, PolicyResult], name: str) -> str:
    """A policy's OER_tau, mean ± std over sessions (``–`` where it was not played)."""
    if name not in policies:
        return "–"
    score = policies[name].oer_tau
    return f"{cell(score.mean)} ± {cell(score.std)}"


def _learner(result: EvaluationResults, learner: str) -> str:
    """A learner's OER_tau and its paired gap to the Best fixed action with the interval."""
    if learner not in result.policies:
        return "–"
    paired = learner_gap(result, learner)
    gap = f" ({signed(paired.gap)}, {signed(paired.low)} to {signed(paired.high)})" if paired else ""
    return _score(result.policies, learner) + gap


def group_fruit(root: Path | None, folders: list[str]) -> str:
    """What a group's fruit look like in its views: the share of views with at least one fruit
    boxed, the fewest fruit on a plant and the median box's longer side in pixels (how large a
    target is: a few pixels make its OER coarse), read from the scenes' annotations.json and
    scene.json (``–`` where they are not there)."""
    import json

    import numpy as np

    if root is None:
        return "–"
    views = boxed = 0
    fewest: list[int] = []
    sides: list[int] = []
    for folder in folders:
        try:
            annotations = json.loads((root / folder / "annotations.json").read_text())
            plants = json.loads((root / folder / "scene.json").read_text()).get("plants", [])
        except (OSError, ValueError):
            continue
        views += len(annotations)
        for entry in annotations.values():
            boxes = entry.get("bounding_boxes") or []
            boxed += bool(boxes)
            sides += [max(int(box[2]), int(box[3])) for box in boxes]  # x, y, width, height, id, class
        fewest += [int(plant.get("fruit_count", 0)) for plant in plants]
    if not views or not fewest:
        return "–"
    side = f" / {np.median(sides):g}" if sides else " / –"
    return f"{boxed / views:.0%} / {min(fewest)}{side}"


def _evaluated(config: ReproduceConfig, state: RunState) -> tuple[list[tuple[str, str, EvaluationResults]], list[str]]:
    """The groups evaluated, hardest first (the lowest Best fixed action; one without it last), and
    the keys of those not evaluated yet, in the run's order."""
    evaluated, waiting = [], []
    for scenario, crop in config.pairs:
        result = state.results.get(config.result_key(scenario, crop))
        if result is None:
            waiting.append(group_key(scenario, crop))
        else:
            evaluated.append((scenario, crop, result))

    def hardness(group: tuple[str, str, EvaluationResults]) -> float:
        best = _oer(group[2].policies, BEST_FIXED)
        return 1.0 if best is None else best

    return sorted(evaluated, key=hardness), waiting


def crops_table(config: ReproduceConfig, state: RunState, root: Path | None = None) -> str:
    """The run's table, hardest group first (the lowest Best fixed action).

    Args:
        config: The run's configuration.
        state: Its records.
        root: Its dataset (``OUT/dataset``), for how the group's fruit look in its views.

    Returns:
        Markdown: a line on the run, the table, the groups not evaluated yet.
    """
    learners = [algo.upper() for algo in config.learners]
    evaluated, waiting = _evaluated(config, state)
    rows = []
    for scenario, crop, result in evaluated:
        protocol, policies = result.protocol, result.policies
        best = _oer(policies, BEST_FIXED)
        oracle = _oer(policies, "Oracle")
        start = _start_oer(policies)
        rows.append(
            [
                crop,
                scenario,
                group_fruit(root, state.scene_folders.get(group_key(scenario, crop), [])),
                str(len(protocol.scenes)),
                f"{protocol.starts:,}" if protocol.starts is not None else "–",
                cell(start) if start is not None else "–",
                _score(policies, "Rand"),
                _score(policies, BEST_FIXED),
                _score(policies, "Oracle"),
                signed(oracle - best) if oracle is not None and best is not None else "–",
                *[_learner(result, learner) for learner in learners],
            ]
        )
    head = (
        f"`{config.name}` run: {config.sp_scenes} SP and {config.mp_scenes} row scenes per crop at "
        f"{config.size[0]}x{config.size[1]}, {' and '.join(learners)} {config.sp_timesteps:,} steps per "
        f"group; OER_tau, mean ± std over {config.sessions} sessions of {config.episodes} test episodes. "
        f"Each learner's gap to the {BEST_FIXED} on the same episodes follows its score "
        f"({CONFIDENCE:.0%} bootstrap interval over episodes: the one model trained, seed {config.seed}, "
        f"not another training of the learner). Hardest first: the lowest {BEST_FIXED}."
    )
    columns = ["crop", "scenario", "views with a fruit boxed / fewest fruit on a plant / median box side, px"]
    columns += ["test scenes"]
    columns += ["eligible starts", "OER_0", "Rand", BEST_FIXED, "Oracle"]
    columns += ["Oracle − best fixed", *learners]
    lines = [head, "", "| " + " | ".join(columns) + " |", "|---" * len(columns) + "|"]
    lines += ["| " + " | ".join(cells) + " |" for cells in rows]
    if not rows:
        lines.append("| not run yet |" + " |" * (len(columns) - 1))
    few = [(group_key(s, c), r.protocol) for s, c, r in evaluated if replays_few_starts(r.protocol)]
    if few:
        replays = "; ".join(f"{key}: {p.sessions * p.episodes} episodes, {p.starts:,} starts" for key, p in few)
        lines += [
            "",
            f"Few starts ({replays}): their episodes replay each eligible start about twice or more, so "
            "their intervals say how sure the means are over these starts, not over other scenes.",
        ]
    if waiting:
        lines += ["", f"Not evaluated yet: {', '.join(waiting)}."]
    return "\n".join(lines)


def ladder_rows(config: ReproduceConfig, state: RunState) -> list[dict[str, Any]]:
    """The table's groups as :func:`davis_ag.figures.result_charts.plot_ladder` draws them, in
    the table's order; a group whose episodes replay few starts has their number in its label.

    Args:
        config: The run's configuration.
        state: Its records.

    Returns:
        One row per group evaluated, hardest first.
    """
    learners = [algo.upper() for algo in config.learners]
    rows = []
    for scenario, crop, result in _evaluated(config, state)[0]:
        policies = result.policies
        scores: dict[str, dict[str, float | None]] = {}
        for learner in (name for name in learners if name in policies):
            paired = learner_gap(result, learner)
            scores[learner] = {"mean": _oer(policies, learner)}
            if paired is not None:
                scores[learner] |= {"low": paired.low, "high": paired.high}
        few = replays_few_starts(result.protocol)  # said where its dots are, not only under the table
        rows.append(
            {
                "label": f"{crop} {scenario}" + (f" ({result.protocol.starts} starts)" if few else ""),
                "oer_0": _start_oer(policies),
                "rand": _oer(policies, "Rand"),
                "best_fixed": _oer(policies, BEST_FIXED),
                "oracle": _oer(policies, "Oracle"),
                "learners": scores,
            }
        )
    return rows


def ladder_figure(config: ReproduceConfig, state: RunState, page: Path) -> str | None:
    """Draw the table as a ladder (:func:`ladder_rows`) into ``images/crops-ladder.png`` beside
    the page; its Markdown link (None before any group).

    Args:
        config: The run's configuration.
        state: Its records.
        page: The page the link goes in.

    Returns:
        The Markdown image line, or None.
    """
    from davis_ag.figures.result_charts import plot_ladder

    rows = ladder_rows(config, state)
    if not rows:
        return None
    target = page.parent / "images" / "crops-ladder.png"
    title = (
        f"{config.name} run, {len(rows)} of {len(config.pairs)} groups: how hard each crop is, "
        f"hardest (lowest {BEST_FIXED}) at the top"
    )
    plot_ladder(rows, target, title)
    return f"![the crops run as a ladder, hardest at the top](images/{target.name})"


def wall_time_line(config: ReproduceConfig, state: RunState, out: Path | None) -> str:
    """The run's wall time so far by kind of stage (generate, validate, train, evaluate) and the
    machines its clock names, from every sitting on the clock (:func:`stage_rows`); ``""`` before
    any stage.

    The clock counts what each stage took where it ran, other work on the machine included: what
    a researcher running the same command should plan for, not a measurement of the code alone.
    """
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE, read_clock

    hours: dict[str, float] = {}
    for stage, seconds, _, _ in stage_rows(state, out):
        kind = stage.partition(": ")[2].split(" ")[0]
        hours[kind] = hours.get(kind, 0.0) + seconds / 3600
    if not hours:
        return ""
    clock = read_clock(Path(out) / CLOCK_FILE) if out is not None else {}
    machines = Counter(str(s.get("machine") or "a machine unrecorded") for sittings in clock.values() for s in sittings)
    where = f", on {' and '.join(machines)}" if machines else ""
    parts = ", ".join(f"{kind} {value:.1f}" for kind, value in hours.items())
    finished = all(config.result_key(scenario, crop) in state.results for scenario, crop in config.pairs)
    return (
        f"Wall time{'' if finished else ' so far'}: **{sum(hours.values()):.1f} h** on the run's clock, every "
        f"sitting ({parts} h){where}; wall time, so any other work sharing the machine counts too."
    )


def write_crops_md(path: Path, config: ReproduceConfig, state: RunState, out: Path | None) -> Path:
    """Write the crops run's table and its ladder chart (in ``images/`` beside the page): into a
    page's ``crops-run`` block where it has one (docs/crops.md), else as a page of its own with the
    wall time of every stage.

    Args:
        path: The page (docs/crops.md, or a page of the run's own).
        config: The run's configuration.
        state: Its records.
        out: Its folder, for the dataset and the training records (None: not read).

    Returns:
        The path written.
    """
    table = crops_table(config, state, None if out is None else Path(out) / "dataset")
    path = Path(path)
    figure = ladder_figure(config, state, path)
    table += f"\n\n{figure}" if figure else ""
    if path.is_file() and f"<!-- {CROPS_MARKER}:start -->" in path.read_text(errors="replace"):
        spent = wall_time_line(config, state, out)
        write_marked_section(path, CROPS_MARKER, table + (f"\n\n{spent}" if spent else ""))
        return path
    lines = ["# The plant-library crops: the crops run", "", table, "", "## Wall time per stage", ""]
    lines += ["| Stage | Seconds | Hours | Code | Note |", "|---|---|---|---|---|"]
    total = 0.0
    for stage, seconds, code, note in stage_rows(state, out):
        total += seconds
        lines.append(f"| {stage} | {seconds:.0f} | {seconds / 3600:.2f} | {code} | {note} |")
    lines += [f"| total | {total:.0f} | {total / 3600:.2f} | | |", ""]
    return write_text_atomic(path, "\n".join(lines) + "\n")

"""docs/mapping.md's run section, written from the ``mapping`` run's results files: every crop's
table, the ladder from hardest to easiest row to map, each crop's coverage curves, how coverage
moves with the seen fraction, and one episode drawn on its segment.

The page's prose is written by hand; everything between its ``mapping-run`` markers comes from here.
A page without the markers (a run's own ``results.md``) is written whole: a title and the section.
"""

from __future__ import annotations

import os
from pathlib import Path

from davis_ag.atomic_files import write_marked_section, write_text_atomic
from davis_ag.benchmark.results import table_number
from davis_ag.mapping.coverage import SEEN_FRACTION
from davis_ag.mapping.results import MappingResults, mapping_table

#: The markers of docs/mapping.md's section.
MARKER = "mapping-run"


def results_name(key: str, fraction: float) -> str:
    """The results file of one group at one seen fraction (``row-apple-wall-seen50.json``)."""
    return f"{key}-seen{round(fraction * 100)}.json"


def _ladder(runs: dict[str, dict[float, MappingResults]]) -> list[str]:
    """The crops from hardest to easiest to map: by the greedy planner's coverage (perfect
    perception: what is left is the row's own difficulty), with the bound and the ceilings."""
    rows = [
        "| rank | row | fruit on the segment | budget, moves | Greedy | Sweep | Rand | bound | ceiling of the start's alley "
        "| grid ceiling |",
        "|---|---|---|---|---|---|---|---|---|---|",
    ]
    main = {key: by_fraction[SEEN_FRACTION] for key, by_fraction in runs.items() if SEEN_FRACTION in by_fraction}
    ordered = sorted(main.items(), key=lambda item: item[1].policies["Greedy"].coverage.mean)
    for rank, (key, results) in enumerate(ordered, 1):
        policies = results.policies
        first = policies["Greedy"]
        fruit = sum(s.fruit for s in results.segments.values())
        ceiling = sum(s.ceiling for s in results.segments.values()) / fruit
        cells = [table_number(policies[n].coverage.mean) if n in policies else "-" for n in ("Greedy", "Sweep", "Rand")]
        rows.append(
            f"| {rank} | {key} | {fruit} | {results.protocol.budget} | {' | '.join(cells)} | {table_number(first.bound)} | "
            f"{table_number(first.part_ceiling)} | {table_number(ceiling)} |"
        )
    return rows


def _threshold(runs: dict[str, dict[float, MappingResults]]) -> list[str]:
    """Coverage of the greedy planner and the sweep, and the alley's ceiling, at each seen fraction."""
    fractions = sorted({f for by_fraction in runs.values() for f in by_fraction})
    head = " | ".join(f"seen at {f:g}: Greedy / Sweep / ceiling" for f in fractions)
    rows = [f"| row | {head} |", "|---|" + "---|" * len(fractions)]
    for key, by_fraction in runs.items():
        cells = []
        for fraction in fractions:
            results = by_fraction.get(fraction)
            if results is None:
                cells.append("-")
                continue
            p = results.policies
            cells.append(
                f"{table_number(p['Greedy'].coverage.mean)} / {table_number(p['Sweep'].coverage.mean)} / "
                f"{table_number(p['Greedy'].part_ceiling)}"
            )
        rows.append(f"| {key} | {' | '.join(cells)} |")
    return rows


def mapping_section(runs: dict[str, dict[float, MappingResults]], images: Path, page: Path) -> str:
    """The section's Markdown.

    Args:
        runs: Per group key, its results per seen fraction.
        images: The folder of the run's pictures.
        page: The page it goes into (pictures are linked relative to it).
    """
    any_results = next(iter(next(iter(runs.values())).values()))
    p = any_results.protocol
    link = Path(os.path.relpath(images, page.parent)).as_posix()
    lines = [
        f"{len(runs)} rows, {p.sessions} sessions x {p.episodes} episodes each, seed {p.seed}, split {p.split}, "
        f"each row's budget the sweep's length on its {p.scenario} grid; a fruit counts as seen at a visible "
        f"fraction of {SEEN_FRACTION:g}. Written by `davis-ag reproduce --config mapping`.",
        "",
        "### The ladder: which row is hardest to map",
        "",
        *_ladder(runs),
        "",
        "Coverage is the share of the segment's fruit seen by the episode's end; the bound is the most any "
        "episode of the budget could see from its alley (the best budget + 1 views, `mapping/bound.py`); the "
        "alley's ceiling is what every view of it sees; the grid's, every view of both alleys.",
        "",
    ]
    for key, by_fraction in runs.items():
        results = by_fraction.get(SEEN_FRACTION)
        if results is None:
            continue
        lines += [
            f"### {key}",
            "",
            mapping_table(results),
            "",
            f"![Coverage curves, {key}]({link}/{key}-curves.png)",
            "",
        ]
    lines += ["### How coverage moves with the seen fraction", "", *_threshold(runs), ""]
    episodes = sorted(images.glob("*-episode-*.png"))
    if episodes:
        lines += ["### One episode on its segment", ""]
        lines += [f"![{shot.stem}]({link}/{shot.name})" for shot in episodes]
        lines.append("")
    return "\n".join(lines).rstrip()


def write_mapping_md(path: Path, runs: dict[str, dict[float, MappingResults]], images: Path) -> None:
    """Write the section into ``path`` between its markers, or the page whole where it has none."""
    text = mapping_section(runs, images, path)
    start = f"<!-- {MARKER}:start -->"
    if path.is_file() and start in path.read_text():
        write_marked_section(path, MARKER, text)
    else:
        write_text_atomic(path, f"# Row mapping\n\n{start}\n{text}\n<!-- {MARKER}:end -->\n")

"""A leaderboard of row-mapping results files (``davis-ag compare`` on mapping files): one row per
method, ranked by coverage.

Files are ranked together only when they measure the same thing: the same protocol version,
scenario, crop, split and scenes (with the same identity: seed, code, how they were drawn), budget,
seen fraction and robot. Anything else is refused in one line, naming what differs.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from pathlib import Path
from typing import Any

from davis_ag.benchmark.results import table_number
from davis_ag.errors import UserError
from davis_ag.mapping.results import MappingResults, load_mapping_results


def _identity(results: MappingResults) -> dict[str, object]:
    p = results.protocol
    played = set(p.scenes)
    scenes = (
        sorted((s for s in results.dataset.scenes if s.id in played), key=lambda s: s.id) if results.dataset else None
    )
    return {
        "protocol version": p.version,
        "scenario": p.scenario,
        "crop": p.crop,
        "split": p.split,
        "scenes": tuple(p.scenes),
        "dataset": scenes,
        "budget": p.budget,
        "robot seconds budget": p.budget_s,
        "seen fraction": p.seen_fraction,
        "robot": (p.robot["name"], p.robot["digest"]) if p.robot else None,
    }


def mapping_leaderboard(paths: list[str | os.PathLike[str]], checks: Callable[[str, Any], str] | None = None) -> str:
    """Read the files (every summary made again from its episodes), check they measure the same
    thing and rank every method by coverage.

    Args:
        paths: The results files.
        checks: How a maintainer checked each row (``compare --verify``): ``(name, row) -> check``;
            a row whose check is "" is left out of the ranking and named under it.

    Returns:
        A Markdown page: what the numbers rest on, then the table.

    Raises:
        UserError: for a file that is not mapping results, an edited one, or files that differ.
    """
    files = [(Path(p), load_mapping_results(p)) for p in paths]
    first_path, first = files[0]
    reference = _identity(first)
    for path, results in files[1:]:
        other = _identity(results)
        differs = next((key for key in reference if reference[key] != other[key]), None)
        if differs is not None:
            raise UserError(
                f"{path} and {first_path} measure different things ({differs}: {other[differs]} vs "
                f"{reference[differs]}): rank only results of one dataset, split and protocol"
            )
    rows, left_out = [], []
    for path, results in files:
        for name, row in results.policies.items():
            digest = row.digest.short() if row.digest is not None else "-"
            check = checks(name, row) if checks is not None else "-"
            if not check:
                left_out.append(f"{name} ({path.name})")
                continue
            rows.append((row.coverage.mean, name, path.name, row, digest, check))
    if not rows:
        raise UserError("no row is left to rank: give each method's code with --policy NAME=SPEC")
    rows.sort(key=lambda r: -r[0])
    p = first.protocol
    lines = [
        f"Row mapping, {p.scenario}{' ' + p.crop if p.crop else ''} {p.split}: {len(p.scenes)} scene(s), "
        f"budget {p.budget} moves, seen at a visible fraction of {p.seen_fraction:g}"
        f"{', robot ' + p.robot['name'] if p.robot else ''}; {p.sessions} x {p.episodes} episodes per file",
        "",
        "| rank | policy | file | coverage | curve area | 50 % of reachable | 80 % of reachable | code | checked |",
        "|---|---|---|---|---|---|---|---|---|",
    ]
    for rank, (_, name, file, row, digest, check) in enumerate(rows, 1):
        lines.append(
            f"| {rank} | {name} | {file} | {table_number(row.coverage.mean)} ± {table_number(row.coverage.std)} "
            f"| {table_number(row.area.mean)} | {row.reach_50.mean:.1%} | {row.reach_80.mean:.1%} | {digest} | {check} |"
        )
    any_row = rows[0][3]
    lines.append(
        f"| - | Bound: the best {p.budget + 1} views | - | {table_number(any_row.bound)} | - | - | - | - | - |"
    )
    if left_out:
        lines += ["", f"Not ranked (their code was not re-run: give --policy NAME=SPEC): {', '.join(left_out)}."]
    return "\n".join(lines) + "\n"

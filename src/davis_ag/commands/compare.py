"""``davis-ag compare RESULTS.json...``: a leaderboard of evaluations of the same dataset, split and
protocol, with each method's paired gaps to the baselines."""

from __future__ import annotations

import argparse
from typing import Any

from davis_ag.commands import arguments
from davis_ag.errors import UserError

HELP = "rank methods of several results files (a leaderboard with paired gaps)"
DESCRIPTION = (
    "Row-mapping results (davis-ag evaluate --task mapping) are ranked by coverage instead. "
    "Rank every method of the given results files (written by davis-ag evaluate) by OER_tau, with reward, "
    "episode length and the paired gaps to the Best fixed action and Rand (95 % bootstrap intervals "
    "where the episodes are the same), and say what the numbers rest on (scenes, eligible starts, "
    "sessions x episodes). Every summary is made again from the file's episodes first, and a file "
    "whose stored summary differs is refused; with --verify DATA every episode is also played again on "
    "the dataset (davis-ag verify). Refuses results of different datasets, splits, split rules or protocol versions. "
    "Each row shows the first digits of the SHA-256 of the code that played."
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``compare``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument(
        "results", type=arguments.path, nargs="+", metavar="RESULTS.json", help="results files of davis-ag evaluate"
    )
    parser.add_argument(
        "--out",
        type=arguments.path,
        default=None,
        metavar="PAGE.md",
        help="also write the leaderboard as a Markdown page",
    )
    parser.add_argument("--force", action="store_true", help="replace an existing --out")
    parser.add_argument(
        "--verify",
        type=arguments.path,
        default=None,
        metavar="DATA",
        help="replay every file's episodes on this dataset first (davis-ag verify) and rank only sound files",
    )
    parser.add_argument(
        "--policy",
        action="append",
        default=[],
        metavar="NAME=SPEC",
        help="with --verify: play row NAME's episodes again with its code (as verify --policy) and rank only "
        "rows re-run so and davis-ag's own baselines (repeatable)",
    )
    arguments.add_split_rule_flag(parser, recorded=True)


def run(args: argparse.Namespace) -> int:
    """Rank, print and write the page."""
    from contextlib import nullcontext

    from davis_ag.atomic_files import write_text_atomic
    from davis_ag.formats.outputs import claim_output

    reads = [(path, "RESULTS") for path in args.results]
    with claim_output(args.out, force=args.force, reads=reads) if args.out else nullcontext():  # the output rule
        from davis_ag.workflows.stages.rerun import parse_policy_arguments

        policies = parse_policy_arguments(args.policy)
        if policies and args.verify is None:
            raise UserError("--policy re-runs rows on the dataset: give --verify DATA too")
        if args.verify is not None:
            from davis_ag.commands.verify import verify_results

            if verify_results(args.results, args.verify, policies=policies, split_rule=args.split_rule) != 0:
                print("not ranked: a check above is not sound", flush=True)
                return 1
        if args.split_rule is not None and args.verify is None:
            from davis_ag.benchmark.results import load_results
            from davis_ag.commands.verify import check_recorded_rule
            from davis_ag.mapping.results import is_mapping_results

            for path in args.results:
                rule = None if is_mapping_results(path) else load_results(path, check=False).protocol.split_rule
                check_recorded_rule(path, rule, args.split_rule)
        page = _page(args.results, policies if args.verify is not None else None)
        print(page, end="")
        if args.out:
            print(f"wrote {write_text_atomic(args.out, page)}")
    return 0


def _check(name: str, digest: Any, policies: dict[str, str]) -> str:
    """How ``compare --verify`` checked a row: ``re-run`` with its code, ``ours`` (a davis-ag
    baseline), else ``replayed``; "" (left out) for such a row when rows' code was given."""
    from davis_ag.benchmark.code_digest import is_davis_ag_code

    if name in policies:
        return "re-run"
    if is_davis_ag_code(digest):
        return "ours"
    return "" if policies else "replayed"


def _page(paths: list, policies: dict[str, str] | None = None) -> str:
    """The leaderboard of the files: row mapping's when they hold mapping results, else Table 4's;
    with ``policies`` (``--verify``) each row says how it was checked."""
    from davis_ag.benchmark.leaderboard import format_leaderboard, leaderboard
    from davis_ag.mapping.leaderboard import mapping_leaderboard
    from davis_ag.mapping.results import is_mapping_results

    kinds = {is_mapping_results(path) for path in paths}
    if len(kinds) > 1:
        raise UserError("the files mix row-mapping and target-visibility results: compare each task's files apart")
    if kinds == {True}:
        checks = (lambda name, row: _check(name, row.digest, policies)) if policies is not None else None
        return mapping_leaderboard(paths, checks)
    rows = leaderboard(paths)
    if policies is None:
        return format_leaderboard(rows)
    for row in rows:
        row.check = _check(row.base, row.policy.digest, policies)
    ranked = [row for row in rows if row.check]
    if not ranked:
        raise UserError("no row is left to rank: give each method's code with --policy NAME=SPEC")
    page = format_leaderboard(ranked)
    left = [f"{row.name} ({row.file.name})" for row in rows if not row.check]
    if left:
        page += f"\nNot ranked (their code was not re-run: give --policy NAME=SPEC): {', '.join(left)}.\n"
    return page

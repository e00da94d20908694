"""``davis-ag stats DIR``: Table 3 (scenes and images per scenario and crop) and fruit statistics
of any dataset, ours or the original download, printed and written as JSON."""

from __future__ import annotations

import argparse

from davis_ag.commands import arguments

HELP = "Table 3 and fruit statistics of a dataset (table and JSON)"
DESCRIPTION = __doc__


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``stats``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument("dataset", type=arguments.path, metavar="DIR", help="dataset root, group or scene folder")
    parser.add_argument(
        "--out", type=arguments.path, default=None, metavar="STATS.json", help="also write the statistics as JSON here"
    )
    parser.add_argument("--force", action="store_true", help="replace an existing --out")
    parser.add_argument(
        "--no-oer", action="store_true", help="skip the OER distribution (it reads every mask: slow on a large dataset)"
    )


def run(args: argparse.Namespace) -> int:
    """Compute, print and write the statistics."""
    from contextlib import nullcontext

    from davis_ag.atomic_files import write_json_atomic
    from davis_ag.data.reader import open_dataset
    from davis_ag.figures.dataset_stats import dataset_statistics, format_statistics
    from davis_ag.formats.outputs import claim_output

    # The output rule, before the masks are read: nothing inside a dataset, nothing replaced unasked.
    with claim_output(args.out, force=args.force) if args.out else nullcontext():
        stats = dataset_statistics(open_dataset(args.dataset), with_oer=not args.no_oer)
        print(format_statistics(stats))
        if args.out:
            print(f"wrote {write_json_atomic(args.out, stats, indent=2)}")
    return 0

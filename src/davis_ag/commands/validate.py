"""``davis-ag validate DIR``: check a dataset and list every problem, one line each."""

from __future__ import annotations

import argparse
import os
import sys

from davis_ag.commands import arguments

HELP = "check a dataset: schema, files, pointers, boxes against masks"
DESCRIPTION = (
    "Check a DAVIS-Ag dataset (ours or the original download): every annotations.json entry, image "
    "and mask, every pointer and every box against its mask. Prints one 'path: reason' line per "
    "problem and a summary; exits 0 when sound, 1 otherwise."
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``validate``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument(
        "dir",
        type=arguments.path,
        metavar="DIR",
        help="dataset root, group folder (e.g. Single-Strawberry) or scene folder",
    )
    parser.add_argument(
        "--quick", action="store_true", help="skip pixel checks (image and mask sizes, boxes against masks)"
    )
    parser.add_argument(
        "--workers",
        type=arguments.bounded(1, 1024),
        default=os.cpu_count() or 1,
        help=f"processes checking scenes at once on a large dataset (default: one per core, "
        f"{os.cpu_count() or 1} here); the report is the same for any number",
    )
    parser.add_argument(
        "--box-tolerance",
        type=arguments.whole,
        default=None,
        metavar="PX",
        help="pixels a box edge may differ from its mask's extent (default: 0 for scenes "
        "with scene.json, 1 for the original download)",
    )


def run(args: argparse.Namespace) -> int:
    """Validate ``args.dir``; 0 when sound, 1 when a problem was found."""
    from tqdm import tqdm

    from davis_ag.data.validate import validate_dataset

    # tqdm.write keeps the problem lines from tearing the progress bar on stderr.
    report = validate_dataset(
        args.dir,
        quick=args.quick,
        box_tolerance=args.box_tolerance,
        on_problem=lambda p: tqdm.write(str(p), file=sys.stdout),
        progress=True,
        workers=args.workers,
    )
    print(report.summary())
    return 0 if report.ok else 1

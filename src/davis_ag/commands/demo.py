"""``davis-ag demo``: a small dataset, its validation, the baselines and an HTML report.

Generates a few single-plant strawberry scenes, validates them, splits them 70/30 by scene,
benchmarks LRD, UDD, Rand and the Oracle on the test split (Table 4 style) and writes
``OUT/report/index.html``. Re-running skips finished scenes.
"""

from __future__ import annotations

import argparse

from davis_ag.commands import arguments

HELP = "generate a small dataset, validate it, run the baselines, write a report"
DESCRIPTION = __doc__
FORMATTER_CLASS = argparse.RawDescriptionHelpFormatter


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``demo``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument(
        "--out",
        type=arguments.path,
        required=True,
        metavar="DIR",
        help="output folder (DIR/dataset, DIR/report/index.html)",
    )
    parser.add_argument(
        "--scenes",
        type=arguments.bounded(1, 1000),
        default=2,
        help="SP strawberry scenes (default 2: one train, one test scene)",
    )
    parser.add_argument(
        "--size",
        type=arguments.image_size,
        default="1280x720",
        help="image size WIDTHxHEIGHT (default 1280x720, the paper's)",
    )
    parser.add_argument("--seed", type=arguments.seed, default=0, help="dataset and evaluation seed (default 0)")
    parser.add_argument(
        "--episodes", type=arguments.bounded(1, 10**6), default=200, help="episodes per session (default 200)"
    )
    parser.add_argument(
        "--sessions", type=arguments.bounded(1, 1000), default=3, help="evaluation sessions (default 3)"
    )


def run(args: argparse.Namespace) -> int:
    """Run the demo; 0 on success, 1 when the generated dataset failed validation."""
    from davis_ag.workflows.demo import run_demo

    return run_demo(
        args.out, scenes=args.scenes, size=args.size, seed=args.seed, episodes=args.episodes, sessions=args.sessions
    )

"""``davis-ag scene-stats [views|plants|findings|refused]``: measure our scenes against the paper
(Table 3's images per scene, fruit per plant, the Fig. 2-3 and section V-D findings, the moves
TVM-v0 refuses), keep each measurement under DOCS/data/ and rewrite DOCS/scenes.md and the marked
tables of DOCS/dataset-format.md and DOCS/plants.md. Without a measurement it only rewrites them.
Run from a clone: DOCS is its docs/ folder by default."""

from __future__ import annotations

import argparse

from davis_ag.commands import arguments
from davis_ag.scene.specs import CROPS

HELP = "measure our scenes against the paper and rewrite docs/scenes.md"
DESCRIPTION = __doc__
MEASUREMENTS = ("views", "plants", "crops", "findings", "refused")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``scene-stats``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument(
        "measurement",
        nargs="?",
        choices=MEASUREMENTS,
        help="views (instant), plants (grows --count plants of each paper crop), crops (--count plants "
        "of each plant-library crop, beside the literature), findings or refused "
        "(generate --count scenes at --size); none: only rewrite the pages",
    )
    parser.add_argument(
        "--docs", type=arguments.path, default="docs", metavar="DOCS", help="the docs folder (default docs)"
    )
    parser.add_argument("--count", type=arguments.count, default=10, help="plants per crop, or scenes (default 10)")
    parser.add_argument(
        "--size",
        type=arguments.image_size,
        default="1280x720",
        metavar="WxH",
        help="image size of the generated scenes (default 1280x720)",
    )
    parser.add_argument(
        "--crops",
        type=arguments.name_list(tuple(CROPS)),
        default=None,
        help="plants, crops: the crops to grow (default all of the measurement's; the others keep their saved rows)",
    )
    parser.add_argument(
        "--generators",
        type=arguments.name_list(("canopy", "architecture")),
        default=None,
        help="refused: the plant generators compared (default both); plants: the generators grown (default canopy)",
    )
    parser.add_argument(
        "--step",
        type=arguments.positive_float,
        default=0.25,
        help="findings: the grid step in metres (default 0.25, the paper's)",
    )


def run(args: argparse.Namespace) -> int:
    """Measure (if asked) and rewrite the pages."""
    from davis_ag.errors import UserError
    from davis_ag.workflows.scene_stats.page import write_measurement

    if not (args.docs / "architecture.md").is_file():
        raise UserError(
            f"{args.docs}: not the docs folder of a davis-ag clone (no architecture.md); "
            "run from the clone's root or give --docs"
        )
    write_measurement(args.docs, args.measurement, args.count, tuple(args.size), args.crops, args.generators, args.step)
    print(f"written {args.docs / 'scenes.md'}")
    return 0

"""``davis-ag plot KIND``: the paper's figures from a dataset and/or evaluation results.

Each figure is written as PNG and SVG, with a JSON file of the numbers it shows beside it.
"""

from __future__ import annotations

import argparse

from davis_ag.commands import arguments
from davis_ag.figures.plots import KINDS, PlotRequest, make_plot

HELP = "draw one of the paper's figures (PNG, SVG and the numbers as JSON)"
DESCRIPTION = __doc__ + "\nkinds:\n" + "\n".join(f"  {k:<11} {v}" for k, v in KINDS.items())
FORMATTER_CLASS = argparse.RawDescriptionHelpFormatter


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``plot``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument("kind", choices=list(KINDS), help="which figure")
    parser.add_argument(
        "dataset",
        type=arguments.path,
        nargs="?",
        default=None,
        metavar="DIR",
        help="dataset root, group or scene folder (all kinds but actions)",
    )
    parser.add_argument(
        "--scene", default=None, metavar="ID", help="scene id, e.g. Single-Strawberry/000 (default: the first scene)"
    )
    parser.add_argument(
        "--results",
        type=arguments.path,
        default=None,
        metavar="RESULTS.json",
        help="`davis-ag evaluate` results (actions, episode)",
    )
    parser.add_argument("--policy", default=None, help="policy of the per-episode panel or episode")
    parser.add_argument(
        "--episode", type=arguments.whole, default=0, metavar="N", help="recorded episode to draw (default 0)"
    )
    parser.add_argument(
        "--start", default=None, metavar="VIEW", help="episode: start view to walk from instead of a recorded episode"
    )
    parser.add_argument("--actions", default="", metavar="A,B,...", help="episode: action names to walk from --start")
    parser.add_argument(
        "--target",
        type=arguments.whole,
        default=None,
        metavar="FRUIT",
        help="episode: target fruit id (a move losing its box is refused)",
    )
    parser.add_argument(
        "--out",
        type=arguments.path,
        required=True,
        metavar="PATH",
        help="output path without suffix: PATH.png, PATH.svg, PATH.json",
    )
    parser.add_argument("--formats", default="png,svg", help="figure formats (default png,svg)")
    parser.add_argument("--force", action="store_true", help="replace existing figure and numbers files")


def run(args: argparse.Namespace) -> int:
    """Draw the figure and print where it went."""
    from davis_ag.errors import UserError

    formats = tuple(f.strip().lower() for f in args.formats.split(",") if f.strip())
    bad = [f for f in formats if f not in ("png", "svg", "pdf")]
    if bad or not formats:
        raise UserError(f"--formats {args.formats!r}: choose from png, svg, pdf (comma-separated)")
    from davis_ag.formats.outputs import claim_output

    actions = [a.strip() for a in args.actions.split(",") if a.strip()]
    base = args.out.with_suffix("") if args.out.suffix.lower().lstrip(".") in ("png", "svg", "pdf") else args.out
    files = [base.with_name(f"{base.name}.{suffix}") for suffix in (*formats, "json")]
    with claim_output(  # the output rule
        files[0],
        force=args.force,
        also=[(f, "--out") for f in files[1:]],
        reads=[(args.results, "--results")] if args.results else [],
    ):
        plotted = _draw(args, formats, actions)
    for path in plotted.paths:
        print(f"wrote {path}")
    return 0


def _draw(args: argparse.Namespace, formats: tuple[str, ...], actions: list[str]):
    """The figure the arguments ask for."""
    return make_plot(
        PlotRequest(
            args.kind,
            args.out,
            dataset=args.dataset,
            scene=args.scene,
            results=args.results,
            policy=args.policy,
            episode=args.episode,
            start=args.start,
            actions=actions,
            target=args.target,
            formats=formats,
        )
    )

"""``davis-ag generate``: render scenes into a dataset folder in the published layout.

Either one group from the flags (``--crop tomato --scenario sp --scenes 5``) or a whole dataset
from a config file or preset (``--config paper``). A run killed at any point finishes the dataset
when started again with the same command; finished scenes are skipped.
"""

from __future__ import annotations

import argparse
import dataclasses

from davis_ag.commands import arguments
from davis_ag.errors import UserError
from davis_ag.generate.run_config import load_dataset_config, single_group_config, use_strawberry_altitudes
from davis_ag.generate.run_progress import DEFAULT_MAX_RETRIES, RunOptions, default_workers
from davis_ag.generate.runner import run_dataset
from davis_ag.render.backends import DEFAULT_ANTIALIASING, DEFAULT_RENDERER, resolve_look
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import DEFAULT_PLANTS
from davis_ag.scene.structures import DEFAULT_STRUCTURES

HELP = "render DAVIS-Ag scenes (Helios plants, our OpenGL renderer)"
DESCRIPTION = __doc__
FORMATTER_CLASS = argparse.RawDescriptionHelpFormatter

#: Flags that describe the one group of a config-less run.
GROUP_FLAGS = ("crop", "scenario", "scenes", "first")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``generate``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument("--config", help="dataset config: a preset (paper, mini) or a YAML file")
    parser.add_argument(
        "--crop",
        help="strawberry, tomato or vine (the paper's), or a plant-library crop: apple, apple-wall, almond, "
        "olive, pistachio, walnut, capsicum, cherry-tomato, vsp-vine, wye-vine (default strawberry; not with --config)",
    )
    parser.add_argument(
        "--scenario", help="sp (single plant), mp (multi plant) or row (an orchard row and its alleys) (default sp)"
    )
    parser.add_argument("--scenes", type=arguments.bounded(1, 100_000), help="how many scenes (default 1)")
    parser.add_argument("--first", type=arguments.whole, help="index of the first scene (default 0)")
    parser.add_argument("--seed", type=arguments.seed, help="dataset seed (default 0, or the config's)")
    parser.add_argument("--size", type=arguments.image_size, help="image size (default 1280x720, or the config's)")
    arguments.add_renderer_flags(parser)
    parser.add_argument(
        "--no-depth",
        action="store_true",
        help="do not write images/NNNN_depth.png (uint16 millimetres along the optical axis)",
    )
    parser.add_argument("--out", type=arguments.path, required=True, help="dataset folder")
    parser.add_argument(
        "--only",
        action="append",
        metavar="SCENE",
        help="make only this scene or group, e.g. Single-Strawberry/003 (repeatable, or comma-separated)",
    )
    parser.add_argument(
        "--workers",
        type=arguments.bounded(1, 1024),
        help=f"scene processes on this machine, each drawing with its share of the cores as "
        f"Mesa threads (default: one per core as memory allows, {default_workers()} here, never "
        "more than the scenes; 1, or a single scene, draws in this process with every core)",
    )
    parser.add_argument(
        "--executor",
        choices=("local", "ray"),
        default="local",
        help="local processes (default) or one Ray task per scene on a cluster",
    )
    parser.add_argument("--address", help="Ray cluster address: auto (on a cluster machine) or ray://HEAD:10001")
    parser.add_argument(
        "--cpus-per-scene",
        type=arguments.bounded(1, 1024),
        default=1,
        help="Ray: CPUs (and Mesa threads) each scene task reserves (default 1)",
    )
    parser.add_argument(
        "--max-retries",
        type=arguments.bounded(0, 100),
        default=DEFAULT_MAX_RETRIES,
        help=f"tries again for a scene whose worker died (default {DEFAULT_MAX_RETRIES})",
    )
    parser.add_argument("--quiet", action="store_true", help="no progress bars")


def run(args: argparse.Namespace) -> int:
    given = [f"--{flag}" for flag in GROUP_FLAGS if getattr(args, flag) is not None]
    if args.config:
        if given:
            raise UserError(
                f"{', '.join(given)} cannot be combined with --config: the config lists the "
                "groups; use --only to pick scenes of it"
            )
        config = load_dataset_config(args.config)
        if args.seed is not None or args.size is not None:
            config = dataclasses.replace(
                config,
                seed=config.seed if args.seed is None else args.seed,
                camera=config.camera if args.size is None else Camera(*args.size),
            )
        if args.antialiasing is not None:
            config = dataclasses.replace(config, antialiasing=args.antialiasing)
        if args.appearance is not None:
            config = dataclasses.replace(config, appearance=args.appearance)
        if args.plants is not None:
            config = dataclasses.replace(config, plants=args.plants)
        if args.structures is not None:
            config = dataclasses.replace(config, structures=args.structures)
        if args.renderer is not None or args.look is not None or args.no_depth:
            renderer = args.renderer or config.renderer
            look = args.look if args.look is not None else (config.look if args.renderer is None else None)
            resolve_look(renderer, look)
            config = dataclasses.replace(config, renderer=renderer, look=look, depth=config.depth and not args.no_depth)
    else:
        config = single_group_config(
            args.scenario or "sp",
            args.crop or "strawberry",
            args.scenes or 1,
            0 if args.first is None else args.first,
            args.seed or 0,
            args.size or (1280, 720),
            args.renderer or DEFAULT_RENDERER,
            args.look,
            not args.no_depth,
            args.antialiasing or DEFAULT_ANTIALIASING,
            args.plants or DEFAULT_PLANTS,
            args.appearance or "paper",
            args.structures or DEFAULT_STRUCTURES,
        )
    if args.strawberry_altitudes:
        config = use_strawberry_altitudes(config, args.strawberry_altitudes)
    for group in config.groups:
        arguments.check_crop_flags(args, group.crop, group.scenario, local=args.executor == "local")
    if args.executor != "ray" and args.address:
        raise UserError("--address is for --executor ray")
    if args.executor == "ray" and args.workers is not None:
        raise UserError(
            "--workers is for the local executor: Ray runs one task per scene on the cluster (see --cpus-per-scene)"
        )
    arguments.prove_writable_folder(args.out)
    only = [item for value in args.only or [] for item in value.split(",") if item.strip()]
    requests = config.requests(only)
    options = RunOptions(
        workers=args.workers or default_workers(requests),
        executor=args.executor,
        address=args.address,
        cpus_per_scene=args.cpus_per_scene,
        max_retries=args.max_retries,
        progress=not args.quiet,
    )
    report = run_dataset(requests, args.out, options)
    splits = f"; {report.splits.name} written" if report.splits else ""
    print(f"{report.root}: {len(report.made)} scenes made, {len(report.skipped)} already complete{splits}")
    return 0

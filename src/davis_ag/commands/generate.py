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
from davis_ag.scene.camera import Camera

#: Flags that describe the one group of a config-less run.
GROUP_FLAGS = ("crop", "scenario", "scenes", "first")



def register(subparsers) -> None:
    parser = subparsers.add_parser("generate", help="render DAVIS-Ag scenes with Helios",
                                   description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--config", help="dataset config: a preset (paper, mini) or a YAML file")
    parser.add_argument("--crop", help="strawberry, tomato or vine (default strawberry; not with --config)")
    parser.add_argument("--scenario", help="sp (single plant) or mp (multi plant) (default sp)")
    parser.add_argument("--scenes", type=arguments.count, help="how many scenes (default 1)")
    parser.add_argument("--first", type=int, help="index of the first scene (default 0)")
    parser.add_argument("--seed", type=int, help="dataset seed (default 0, or the config's)")
    parser.add_argument("--size", type=arguments.image_size, help="image size (default 1280x720, or the config's)")
    parser.add_argument("--out", type=arguments.path, required=True, help="dataset folder")
    parser.add_argument("--strawberry-altitudes", choices=("table1", "readme"),
                        help="strawberry camera altitudes: table1 = Table 1's 25/40/55 cm (default), "
                             "readme = the dataset README's and Fig. 2's 0.50/0.75/1.00 m")
    parser.add_argument("--only", action="append", metavar="SCENE",
                        help="make only this scene or group, e.g. Single-Strawberry/003 (repeatable, or "
                             "comma-separated)")
    parser.add_argument("--workers", type=arguments.count,
                        help=f"scene processes on this machine, each drawing with one Mesa thread (default: "
                             f"one per core as memory allows, {default_workers()} here; 1 draws in this process "
                             "with every core)")
    parser.add_argument("--executor", choices=("local", "ray"), default="local",
                        help="local processes (default) or one Ray task per scene on a cluster")
    parser.add_argument("--address", help="Ray cluster address: auto (on a cluster machine) or ray://HEAD:10001")
    parser.add_argument("--cpus-per-scene", type=arguments.count, default=1,
                        help="Ray: CPUs (and Mesa threads) each scene task reserves (default 1)")
    parser.add_argument("--max-retries", type=arguments.whole, default=DEFAULT_MAX_RETRIES,
                        help=f"tries again for a scene whose worker died (default {DEFAULT_MAX_RETRIES})")
    parser.add_argument("--quiet", action="store_true", help="no progress bars")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    given = [f"--{flag}" for flag in GROUP_FLAGS if getattr(args, flag) is not None]
    if args.config:
        if given:
            raise UserError(f"{', '.join(given)} cannot be combined with --config: the config lists the "
                            "groups; use --only to pick scenes of it")
        config = load_dataset_config(args.config)
        if args.seed is not None or args.size is not None:
            if args.seed is not None and args.seed < 0:
                raise UserError(f"--seed {args.seed} is negative: use a whole number from 0")
            config = dataclasses.replace(config, seed=config.seed if args.seed is None else args.seed,
                             camera=config.camera if args.size is None else Camera(*args.size))
    else:
        config = single_group_config(args.scenario or "sp", args.crop or "strawberry", args.scenes or 1,
                                     0 if args.first is None else args.first, args.seed or 0,
                                     args.size or (1280, 720))
    if args.strawberry_altitudes:
        config = use_strawberry_altitudes(config, args.strawberry_altitudes)
    if args.executor != "ray" and args.address:
        raise UserError("--address is for --executor ray")
    if args.executor == "ray" and args.workers is not None:
        raise UserError("--workers is for the local executor: Ray runs one task per scene on the cluster "
                        "(see --cpus-per-scene)")
    only = [item for value in args.only or [] for item in value.split(",") if item.strip()]
    requests = config.requests(only)
    options = RunOptions(workers=args.workers or default_workers(), executor=args.executor, address=args.address,
                         cpus_per_scene=args.cpus_per_scene, max_retries=args.max_retries,
                         progress=not args.quiet)
    report = run_dataset(requests, args.out, options)
    splits = f"; {report.splits.name} written" if report.splits else ""
    print(f"{report.root}: {len(report.made)} scenes made, {len(report.skipped)} already complete{splits}")
    return 0

"""``davis-ag evaluate``: the section V-C benchmark (Table 4) on a dataset's test split."""

from __future__ import annotations

import argparse
from pathlib import Path

from davis_ag.commands import arguments
from davis_ag.errors import UserError


def register(subparsers: argparse._SubParsersAction) -> None:
    """Add the ``evaluate`` sub-command."""
    parser = subparsers.add_parser(
        "evaluate",
        help="benchmark LRD, UDD, Rand, Oracle (and a trained A2C) as in Table 4",
        description="Run every policy on the same episodes of the test split (sessions x "
                    "episodes, fixed seeds), print a Table 4 style summary, write it as JSON and "
                    "a PNG bar chart.",
    )
    parser.add_argument("--dataset", type=arguments.path, required=True, metavar="DIR", help="dataset root")
    parser.add_argument("--scenario", required=True, choices=["sp", "mp"],
                        help="single plant (tau=3) or multi plant (tau=5)")
    parser.add_argument("--crop", default=None, help="evaluate on one crop only (default: all)")
    parser.add_argument("--split", default="test", choices=["train", "test", "all"],
                        help="scenes to evaluate on (default: test)")
    parser.add_argument("--model", type=arguments.path, default=None, metavar="MODEL.zip",
                        help="trained A2C model; adds the A2C column")
    parser.add_argument("--policies", default="LRD,UDD,Rand,Oracle",
                        help="comma-separated baselines (default: LRD,UDD,Rand,Oracle)")
    parser.add_argument("--stochastic", action="store_true",
                        help="let A2C sample its actions instead of taking the most likely one")
    parser.add_argument("--episodes", type=int, default=200, help="episodes per session (200)")
    parser.add_argument("--sessions", type=int, default=3, help="sessions (3)")
    parser.add_argument("--seed", type=int, default=0, help="base seed of the episodes (0)")
    parser.add_argument("--cache-dir", type=arguments.path, default=None, metavar="DIR",
                        help="observation cache folder (default: DIR/.davis_ag_cache)")
    parser.add_argument("--out", type=arguments.path, required=True, metavar="RESULTS.json", help="results file")
    parser.add_argument("--plot", type=arguments.path, default=None, metavar="PNG",
                        help="bar chart (default: the --out path with .png)")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    """Evaluate, print the table, write JSON and PNG."""
    from davis_ag.benchmark import TVMEnv
    from davis_ag.benchmark.agents import build_agents
    from davis_ag.benchmark.evaluation import evaluate_agents, format_table, plot_results, write_json

    if args.episodes < 1 or args.sessions < 1:
        raise UserError("--episodes and --sessions must be at least 1")
    names = [n for n in args.policies.split(",") if n.strip()]
    if args.model and not any(n.strip().lower() == "a2c" for n in names):
        names.append("A2C")
    agents = build_agents(names, model=args.model, deterministic=not args.stochastic)
    env = TVMEnv(args.dataset, scenario=args.scenario, split=args.split, crop=args.crop,
                 cache_dir=args.cache_dir)
    results = evaluate_agents(env, agents, episodes=args.episodes, sessions=args.sessions,
                              seed=args.seed, keep_episodes=True)
    print(format_table(results))
    out = write_json(results, args.out)
    plot = plot_results(results, args.plot or Path(args.out).with_suffix(".png"))
    print(f"wrote {out} and {plot}")
    return 0

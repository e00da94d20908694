"""``davis-ag evaluate``: the section V-C benchmark (Table 4) on a dataset's test split, on the grid
(TVM-v0) or with continuous camera poses (``--env continuous``, TVMContinuous-v0)."""

from __future__ import annotations

import argparse
from pathlib import Path

from davis_ag.atomic_files import write_or_rescue
from davis_ag.commands import arguments
from davis_ag.errors import MachineError, UserError
from davis_ag.formats.outputs import claim_output

HELP = "benchmark LRD, UDD, Rand, Oracle (and a trained A2C) as in Table 4"
DESCRIPTION = ("Run every policy on the same episodes of the test split (sessions x episodes, fixed seeds), "
               "print a Table 4 style summary, write it as JSON and a PNG bar chart. On the grid the row "
               "'Best fixed action' (the best policy that always plays one action) is added, and the "
               "image-blind policies get their exact expectations beside the sampled means.")

#: What --policies accepts on the grid (A2C needs --model too).
POLICIES = ("LRD", "UDD", "Rand", "Oracle", "A2C")
#: What --policies accepts with --env continuous (Model needs --model: a PPO or SAC .zip).
CONTINUOUS_POLICIES = ("LR", "UD", "Rand", "Greedy", "Model")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``evaluate``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    arguments.add_dataset_flags(parser, "evaluate")
    parser.add_argument("--split", default="test", choices=["train", "test", "all"],
                        help="scenes to evaluate on (default: test)")
    parser.add_argument("--model", type=arguments.path, default=None, metavar="MODEL.zip",
                        help="trained A2C model; adds the A2C column")
    parser.add_argument("--env", default="grid", choices=["grid", "continuous"],
                        help="grid: the dataset's views (TVM-v0, default); continuous: any pose, drawn live "
                             "from regrown scenes (TVMContinuous-v0; scenes made by davis-ag generate)")
    parser.add_argument("--policies", type=arguments.name_list(tuple(dict.fromkeys(POLICIES + CONTINUOUS_POLICIES))),
                        default=None, help="comma-separated baselines (grid default: LRD,UDD,Rand,Oracle; "
                                           "continuous: LR,UD,Rand,Greedy)")
    parser.add_argument("--stochastic", action="store_true",
                        help="let A2C (or the continuous Model) sample its actions instead of taking the most likely one "
                             "(grid A2C samples by default, as davis-ag reproduce plays it)")
    parser.add_argument("--deterministic", action="store_true",
                        help="grid A2C takes its most likely action instead of sampling")
    parser.add_argument("--episodes", type=arguments.bounded(1, 10**6), default=200,
                        help="episodes per session (200)")
    parser.add_argument("--sessions", type=arguments.bounded(1, 1000), default=3, help="sessions (3)")
    parser.add_argument("--seed", type=arguments.seed, default=0, help="base seed of the episodes (0)")
    parser.add_argument("--cache-dir", type=arguments.path, default=None, metavar="DIR",
                        help="observation cache folder (default: DIR/.davis_ag_cache)")
    parser.add_argument("--out", type=arguments.path, required=True, metavar="RESULTS.json", help="results file")
    parser.add_argument("--plot", type=arguments.path, default=None, metavar="PNG",
                        help="bar chart (default: the --out path with .png)")
    parser.add_argument("--force", action="store_true", help="replace an existing --out and --plot")


def run(args: argparse.Namespace) -> int:
    """Evaluate, print the table, write JSON and PNG."""
    continuous = args.env == "continuous"
    allowed = CONTINUOUS_POLICIES if continuous else POLICIES
    names = list(args.policies or (("LR", "UD", "Rand", "Greedy") if continuous else ("LRD", "UDD", "Rand", "Oracle")))
    wrong = [n for n in names if n not in allowed]
    if wrong:
        raise UserError(f"--policies {wrong[0]} is not a policy of --env {args.env}: choose from {', '.join(allowed)}")
    model_name = "Model" if continuous else "A2C"
    if args.model and model_name not in names:
        names.append(model_name)
    out = arguments.prove_writable_file(args.out)
    plot = arguments.prove_writable_file(args.plot or out.with_suffix(".png"), "--plot")
    if plot == out:
        raise UserError(f"--plot and --out are both {out}: give the chart another name")
    if args.cache_dir is not None:
        arguments.prove_writable_folder(args.cache_dir, "--cache-dir")
    with claim_output(out, force=args.force, also=[(plot, "--plot")]):  # the output rule
        return _evaluate(args, names, out, plot)


def _evaluate(args: argparse.Namespace, names: list[str], out: Path, plot: Path) -> int:
    """Evaluate ``names`` on the claimed outputs ``out`` and ``plot``."""
    from davis_ag.benchmark.evaluation import format_table, write_json
    from davis_ag.figures.result_charts import plot_results

    continuous = args.env == "continuous"
    if continuous:
        from davis_ag.live.evaluation import evaluate_continuous
        from davis_ag.live.policies import build_policies
        from davis_ag.live.tvm_continuous import TVMContinuousEnv

        agents = build_policies(names, model=args.model, deterministic=not args.stochastic)
        env = TVMContinuousEnv(args.dataset, scenario=args.scenario, split=args.split, crop=args.crop)
        try:
            results = evaluate_continuous(env, agents, episodes=args.episodes, sessions=args.sessions,
                                          seed=args.seed, keep_episodes=True)
        finally:
            env.close()
    else:
        from davis_ag.benchmark import TVMEnv
        from davis_ag.benchmark.agents import A2C_DETERMINISTIC, build_agents
        from davis_ag.benchmark.evaluation import evaluate_agents

        if args.stochastic and args.deterministic:
            raise UserError("--stochastic and --deterministic contradict each other: give one")
        deterministic = args.deterministic or (A2C_DETERMINISTIC and not args.stochastic)
        agents = build_agents(names, model=args.model, deterministic=deterministic)
        env = TVMEnv(args.dataset, scenario=args.scenario, split=args.split, crop=args.crop,
                     cache_dir=args.cache_dir)
        results = evaluate_agents(env, agents, episodes=args.episodes, sessions=args.sessions,
                                  seed=args.seed, keep_episodes=True, best_fixed_action=True)
    print(format_table(results))
    # The JSON is the result: keep it somewhere even when --out fails at the end.
    write_or_rescue(out, lambda path: write_json(results, path), "the results")
    try:
        plot_results(results, plot)
    except OSError as error:
        raise MachineError(f"the results are in {out}, but the chart could not be written to {plot} "
                        f"({error.strerror or error}): run again with another --plot") from None
    print(f"wrote {out} and {plot}")
    return 0

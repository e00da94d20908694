"""``davis-ag evaluate``: the section V-D benchmark (Table 4) on a dataset's test split, on the grid
(TVM-v0) or with continuous camera poses (``--env continuous``, TVMContinuous-v0)."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import write_or_rescue
from davis_ag.commands import arguments
from davis_ag.errors import MachineError, UserError
from davis_ag.figures.canvas import check_figure_path
from davis_ag.formats.outputs import claim_output

HELP = "score policies (yours, trained models, the baselines) as in Table 4"
DESCRIPTION = (
    "Run every policy on the same episodes of the test split (sessions x episodes, fixed seeds), "
    "print a Table 4 style summary with each policy's paired gap to the Best fixed action (grid) and "
    "to Rand, write it as JSON (docs/benchmark-your-method.md documents the file) and a PNG bar chart. "
    "--policy adds a method beside the baselines: a saved Stable-Baselines3 model of any algorithm, "
    "or module:attr / path/to/file.py:attr naming a function (observation, info) -> action or a "
    "class with reset(seed) and act(observation, info). On the grid the row 'Best fixed action' "
    "(the best policy that always plays one action) is added, and the image-blind policies get their "
    "exact expectations beside the sampled means. "
    "--task mapping scores row mapping instead (RowMapping-v0, docs/mapping.md): every fruit of the row "
    "segment to see within a budget of moves, beside the Sweep, Rand and Greedy baselines and the "
    "budget's coverage bound; the chart is then the coverage curves."
)

#: Baselines --policies accepts on the grid.
POLICIES = ("LRD", "UDD", "Rand", "Oracle")
#: Baselines --policies accepts with --env continuous.
CONTINUOUS_POLICIES = ("LR", "UD", "Rand", "Greedy")
#: Baselines --policies accepts with --task mapping.
MAPPING_POLICIES = ("Sweep", "Rand", "Greedy")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``evaluate``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    arguments.add_dataset_flags(parser, "evaluate")
    parser.add_argument(
        "--split",
        default="test",
        choices=["train", "test", "all"],
        help="the split's side to evaluate on (default: test; --split-rule says how it splits)",
    )
    parser.add_argument(
        "--policy",
        action=_AddPolicy,
        default=[],
        metavar="SPEC",
        help="a method to score beside the baselines (repeatable): MODEL.zip (any Stable-Baselines3 "
        "algorithm, the row named after it), module:attr or path/to/file.py:attr (a function "
        "(observation, info) -> action, or a class with reset and act)",
    )
    parser.add_argument(
        "--model",
        action=_AddPolicy,
        dest="policy",
        metavar="MODEL.zip",
        help="the same as --policy (kept for earlier scripts)",
    )
    parser.add_argument(
        "--name",
        action=_NamePolicy,
        default=None,
        metavar="NAME",
        help="row name of the --policy given just before it (repeatable)",
    )
    parser.add_argument(
        "--env",
        default="grid",
        choices=["grid", "continuous"],
        help="grid: the dataset's views (TVM-v0, default); continuous: any pose, drawn live "
        "from regrown scenes (TVMContinuous-v0; scenes made by davis-ag generate)",
    )
    arguments.add_task_flags(parser, "score")
    parser.add_argument(
        "--budget-s",
        type=float,
        default=None,
        metavar="SECONDS",
        help="--task mapping with --robot: also end an episode when the robot's seconds are spent",
    )
    parser.add_argument(
        "--policies",
        type=arguments.name_list(tuple(dict.fromkeys(POLICIES + CONTINUOUS_POLICIES + MAPPING_POLICIES))),
        default=None,
        help="comma-separated baselines (grid default: LRD,UDD,Rand,Oracle; continuous: LR,UD,Rand,Greedy; "
        "--task mapping: Sweep,Rand,Greedy)",
    )
    parser.add_argument(
        "--deterministic",
        action="store_true",
        help="trained models take their most likely action instead of sampling it (the default, "
        "as davis-ag reproduce plays A2C)",
    )
    parser.add_argument("--episodes", type=arguments.bounded(1, 10**6), default=200, help="episodes per session (200)")
    parser.add_argument("--sessions", type=arguments.bounded(1, 1000), default=3, help="sessions (3)")
    parser.add_argument("--seed", type=arguments.seed, default=0, help="base seed of the episodes (0)")
    parser.add_argument("--out", type=arguments.path, required=True, metavar="RESULTS.json", help="results file")
    parser.add_argument(
        "--plot", type=arguments.path, default=None, metavar="PNG", help="bar chart (default: the --out path with .png)"
    )
    parser.add_argument("--force", action="store_true", help="replace an existing --out and --plot")
    parser.add_argument(
        "--robot",
        default=None,
        metavar="ROBOT",
        help="the camera rides on this robot (davis-ag robots lists them, or a YAML file): only the views it "
        "reaches, each move costing its seconds (docs/robot.md)",
    )


class _AddPolicy(argparse.Action):
    """``--policy SPEC``: one more method, not yet named (``policy_names`` keeps step with it)."""

    def __call__(
        self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, value: Any, _: Any = None
    ) -> None:
        setattr(namespace, self.dest, [*(getattr(namespace, self.dest) or []), value])
        namespace.policy_names = [*(getattr(namespace, "policy_names", None) or []), None]


class _NamePolicy(argparse.Action):
    """``--name NAME``: the row name of the ``--policy`` just before it, as the docs say; a name
    with no policy before it, or a second name for one, is refused rather than put on another row."""

    def __call__(
        self, parser: argparse.ArgumentParser, namespace: argparse.Namespace, value: Any, _: Any = None
    ) -> None:
        names = list(getattr(namespace, "policy_names", None) or [])
        if not names:
            parser.error(f"--name {value}: give it after the --policy it names")
        if names[-1] is not None:
            parser.error(f"--name {value}: the --policy before it is already named {names[-1]!r}")
        names[-1] = value
        namespace.policy_names = names


def run(args: argparse.Namespace) -> int:
    """Evaluate, print the table, write JSON and PNG."""
    mapping = args.task == "mapping"
    if mapping and args.env != "grid":
        raise UserError("--task mapping plays the grid (RowMapping-v0): leave out --env continuous")
    if not mapping and (args.budget, args.seen_fraction, args.budget_s) != (None, None, None):
        raise UserError("--budget, --seen-fraction and --budget-s are for --task mapping: add it or leave them out")
    arguments.check_task_split_rule(args)
    allowed = MAPPING_POLICIES if mapping else CONTINUOUS_POLICIES if args.env == "continuous" else POLICIES
    names = list(args.policies or allowed)
    wrong = [n for n in names if n not in allowed]
    if wrong:
        where = "--task mapping" if mapping else f"--env {args.env}"
        raise UserError(f"--policies {wrong[0]} is not a baseline of {where}: choose from {', '.join(allowed)}")
    specs = args.policy or []
    out = arguments.prove_writable_file(args.out)
    plot = arguments.prove_writable_file(args.plot or out.with_suffix(".png"), "--plot")
    check_figure_path(plot, "--plot")  # before the episodes, not after
    if args.cache_dir is not None:
        arguments.prove_writable_folder(args.cache_dir, "--cache-dir")
    # A policy's file (a model, a module) is an input: never replaced by the results or the chart.
    reads = [(path, "--policy") for spec in specs for path in _spec_files(spec)]
    with claim_output(out, force=args.force, also=[(plot, "--plot")], reads=reads):  # the output rule
        if mapping:
            return _evaluate_mapping(args, names, specs, out, plot)
        return _evaluate(args, names, specs, out, plot)


def _spec_files(spec: str) -> list[Path]:
    """The file a ``--policy`` SPEC reads, where it names one (``model.zip``, ``mine.py:act``)."""
    candidates = [spec, spec.rsplit(":", 1)[0]] if ":" in spec else [spec]
    return [Path(c) for c in candidates if Path(c).expanduser().is_file()][:1]


def _policies(args: argparse.Namespace, specs: list[str]) -> list[Any]:
    """The ``--policy`` specs as policies, each with the ``--name`` given after it."""
    from davis_ag.benchmark.policies import policy_from_spec

    return [
        policy_from_spec(spec, name, deterministic=args.deterministic)
        for spec, name in zip(specs, getattr(args, "policy_names", None) or [None] * len(specs), strict=True)
    ]


def _finish(table: str, out: Path, plot: Path, write: Any, draw: Any) -> int:
    """Print the table, write the results (kept somewhere even when ``out`` fails at the end: the
    JSON is the result) and draw the chart."""
    print(table)
    write_or_rescue(out, write, "the results")
    try:
        draw(plot)
    except OSError as error:
        raise MachineError(
            f"the results are in {out}, but the chart could not be written to {plot} "
            f"({error.strerror or error}): run again with another --plot"
        ) from None
    print(f"wrote {out} and {plot}")
    return 0


def _evaluate(args: argparse.Namespace, names: list[str], specs: list[str], out: Path, plot: Path) -> int:
    """Evaluate the baselines ``names`` and the ``--policy`` specs on the claimed ``out`` and ``plot``."""
    from davis_ag.benchmark.evaluation import evaluate, write_json
    from davis_ag.benchmark.results_table import format_table
    from davis_ag.figures.result_charts import plot_results

    results = evaluate(
        _policies(args, specs),
        args.dataset,
        scenario=args.scenario,
        split=args.split,
        sessions=args.sessions,
        episodes=args.episodes,
        seed=args.seed,
        env=args.env,
        crop=args.crop,
        baselines=names,
        cache_dir=args.cache_dir,
        robot=args.robot,
        split_rule=args.split_rule,
    )
    return _finish(
        format_table(results),
        out,
        plot,
        lambda path: write_json(results, path),
        lambda path: plot_results(results, path),
    )


def _evaluate_mapping(args: argparse.Namespace, names: list[str], specs: list[str], out: Path, plot: Path) -> int:
    """``--task mapping``: score the baselines ``names`` and the specs on row mapping."""
    from davis_ag.figures.mapping_plots import plot_coverage_curves
    from davis_ag.mapping.coverage import SEEN_FRACTION
    from davis_ag.mapping.evaluation import evaluate_mapping
    from davis_ag.mapping.results import mapping_table

    results = evaluate_mapping(
        _policies(args, specs),
        args.dataset,
        scenario=args.scenario,
        split=args.split,
        sessions=args.sessions,
        episodes=args.episodes,
        seed=args.seed,
        crop=args.crop,
        baselines=names,
        cache_dir=args.cache_dir,
        budget=args.budget,
        seen_fraction=SEEN_FRACTION if args.seen_fraction is None else args.seen_fraction,
        robot=args.robot,
        budget_s=args.budget_s,
    )
    return _finish(mapping_table(results), out, plot, results.write, lambda path: plot_coverage_curves(results, path))

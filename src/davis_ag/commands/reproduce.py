"""``davis-ag reproduce``: the paper's Table 4 (section VI) end to end, at a size that fits.

Stages (each resumable: finished scenes are skipped, a trained model's zip and an evaluation's
JSON are reused, a killed training resumes from its checkpoint): SP strawberry data, its
validation and split, A2C and PPO beside it (the same budget) on SP, the SP benchmark, then the
same for MP vine; ``--results`` (Markdown) is rewritten after every benchmark, so a
run cut short still leaves what it measured.
"""

from __future__ import annotations

import argparse
from dataclasses import replace
from pathlib import Path
from typing import TYPE_CHECKING, Any

from davis_ag.commands import arguments
from davis_ag.errors import UserError
from davis_ag.formats.splits import SPLIT_RULES
from davis_ag.workflows.reproduce.configs import CONFIGS, TABLE4_LEARNERS, ReproduceConfig
from davis_ag.workflows.reproduce.run import reproduce, write_page
from davis_ag.workflows.reproduce.state import RunState, run_config
from davis_ag.workflows.reproduce.status import format_status

if TYPE_CHECKING:
    from davis_ag.workflows.reproduce.pages.split_rules import RuleRun

HELP = (
    "reproduce Table 4, the crops ladder, row mapping, the robot or the structures run: generate, train A2C and PPO, "
    "benchmark, write the page"
)
DESCRIPTION = __doc__
FORMATTER_CLASS = argparse.RawDescriptionHelpFormatter


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``reproduce``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument("--out", type=arguments.path, required=True, metavar="DIR", help="work folder")
    parser.add_argument(
        "--results",
        type=arguments.path,
        default=None,
        metavar="MD",
        help="Markdown results file (default: DIR/results.md; docs/results.md also rewrites the "
        "README's Table 4 block and docs/benchmark.md's run block)",
    )
    parser.add_argument(
        "--config",
        choices=list(CONFIGS),
        default="small",
        help="small (default: a smoke test of every stage, under an hour on 2 CPU cores; not comparable "
        "with Table 4), "
        "medium (the paper's grids and 300K A2C steps, hours), paper-scale (Table 3's 130 scenes "
        "at 1280x720, over many sittings: --status says where a run stands), crops (every "
        "plant-library crop's SP and row scenes, its page docs/crops.md), mapping (row mapping on "
        "five crops' rows with every baseline, its page docs/mapping.md), robot (three rows without "
        "a robot and with each robot, A2C and PPO trained under each, its page docs/robot.md), "
        "structures (four rows bare and with their trellises, stakes and strings, its section in "
        "docs/crops.md), "
        "a2c-search (A2C settings searched on SP strawberry's train split beside PPO, never its test "
        "split; its page docs/a2c-search.md) or a2c-search-paper-scale (the same on the paper-scale "
        "SP strawberry dataset under the starts rule, the longer budget first; its page "
        "docs/a2c-search-paper-scale.md)",
    )
    parser.add_argument(
        "--sp-scenes", type=arguments.bounded(1, 1000), default=None, help="override the SP scene count"
    )
    parser.add_argument(
        "--mp-scenes", type=arguments.bounded(1, 1000), default=None, help="override the MP scene count"
    )
    parser.add_argument("--sp-timesteps", type=arguments.bounded(1, 10**9), default=None, help="override SP A2C steps")
    parser.add_argument("--mp-timesteps", type=arguments.bounded(1, 10**9), default=None, help="override MP A2C steps")
    parser.add_argument("--only", choices=["sp", "mp", "row"], default=None, help="run one scenario only")
    parser.add_argument(
        "--learners",
        type=arguments.name_list(TABLE4_LEARNERS),
        default=None,
        help="the learners a Table 4 run trains and scores, comma-separated (default: the configuration's, "
        "a2c,ppo): a2c alone leaves out PPO's hours; the page names the learners the run had",
    )
    parser.add_argument(
        "--split-rule",
        choices=SPLIT_RULES,
        default=None,
        help="how train and test split (default: the configuration's, scenes): starts or fruits train the "
        "learners and score everything under that rule (issue 59: Table 4 read both ways); its Table 4 "
        "page is its own, never a page of another rule's run (docs/benchmark.md#split-rules)",
    )
    parser.add_argument(
        "--rewrite-results", action="store_true", help="only rewrite --results from DIR/state.json; run nothing"
    )
    parser.add_argument(
        "--beside",
        type=arguments.path,
        action="append",
        default=[],
        metavar="DIR",
        help="with --rewrite-results of a Table 4 run: the folder of the same configuration's run under "
        "another split rule; the page gains a section on both readings of the paper's 70/30 split "
        "(docs/benchmark.md#split-rules)",
    )
    parser.add_argument(
        "--status",
        action="store_true",
        help="only print where the run in DIR stands, stage by stage (safe while it runs); run nothing",
    )
    arguments.add_torch_threads_flag(parser, "train and score")


def check_results_path(results: Path, out: Path) -> None:
    """Refuse a ``--results`` page that would replace a run's records or a dataset's files.

    The page is rewritten at every sitting, so an existing one is replaced without ``--force``;
    but never over the run's ``state.json`` or clock, into its models or results folders, or into
    a dataset.

    Raises:
        UserError: naming what the page would replace.
    """
    from davis_ag.formats.outputs import check_outside_datasets, resolved
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE

    # Resolved, as the file system will take them: `run/x/../state.json` or a link to the run
    # folder name its records too.
    page, work = resolved(check_outside_datasets(results, "--results")), resolved(out)
    records = [work / "state.json", work / CLOCK_FILE, work / "models", work / "results", work / "dataset"]
    if any(page == record or record in page.parents for record in records):
        raise UserError(
            f"--results {page} would replace the run's own records in {work}: "
            "choose another path (e.g. docs/results.md)"
        )


def beside_runs(own: ReproduceConfig, folders: list[Path]) -> list[RuleRun]:
    """The runs ``--beside`` names, each checked to be ``own``'s configuration under another rule.

    Args:
        own: The configuration of the run whose page is written.
        folders: The other runs' folders.

    Returns:
        One :class:`~davis_ag.workflows.reproduce.pages.split_rules.RuleRun` per folder.

    Raises:
        UserError: for a folder with no finished run, a run of another page or configuration, or a
            rule already on the page.
    """
    from davis_ag.workflows.reproduce.pages.split_rules import RuleRun

    if own.page != "table4":
        raise UserError(f"--beside: the {own.name} run has no Table 4 page to set another split rule's run beside")
    runs, rules = [], {own.split_rule}
    for folder in folders:
        state = RunState.load(folder / "state.json")
        if not state.config:
            raise UserError(f"--beside {folder}: no reproduce run there (no state.json with a configuration)")
        other = run_config(state, folder / "state.json")
        if replace(other, split_rule=own.split_rule) != own:
            raise UserError(
                f"--beside {folder}: its run is the {other.name} configuration with other settings than this "
                f"{own.name} run; both readings must be the same run but for --split-rule"
            )
        if other.split_rule in rules:
            raise UserError(f"--beside {folder}: its split rule {other.split_rule} is already on the page")
        rules.add(other.split_rule)
        runs.append(RuleRun(other, state, folder))
    return runs


def check_page_rule(results: Path, rule: str) -> None:
    """Refuse a Table 4 page of another split rule's run: each rule's run has its own page, so a
    ``starts`` run never replaces the ``scenes`` run's docs/results.md (or the other way round).

    Raises:
        UserError: naming the page's rule and where to write instead.
    """
    from davis_ag.workflows.reproduce.pages.results import page_split_rule

    if not results.is_file():
        return
    written = page_split_rule(results.read_text(errors="replace"))
    if written is not None and written != rule:
        raise UserError(
            f"--results {results} is the Table 4 page of a split rule {written} run; this run splits by "
            f"{rule}: write its page elsewhere (e.g. --results {results.with_name(f'results-{rule}.md')})"
        )


def configured(args: argparse.Namespace) -> ReproduceConfig:
    """The configuration ``--config`` names, with the size, split-rule and learner flags over it.

    Raises:
        UserError: for ``--learners`` on a run that is not a Table 4 run.
    """
    config = CONFIGS[args.config]
    overrides: dict[str, Any] = {
        k: getattr(args, k)
        for k in ("sp_scenes", "mp_scenes", "sp_timesteps", "mp_timesteps")
        if getattr(args, k) is not None
    }
    if args.split_rule is not None:
        overrides["split_rule"] = args.split_rule
    if args.learners is not None:
        if config.page != "table4":
            table4 = ", ".join(name for name, c in CONFIGS.items() if c.page == "table4")
            raise UserError(
                f"--learners: the {config.name} run chooses its own learners; it goes with a Table 4 run ({table4})"
            )
        overrides["learners"] = tuple(args.learners)
    return replace(config, **overrides)


def run(args: argparse.Namespace) -> int:
    """Run every stage of the chosen configuration and write the results file."""
    config = configured(args)
    if args.status:
        print(format_status(args.out))
        return 0
    # The page lives with its run unless asked elsewhere: a bare run never replaces the committed
    # docs/results.md (the paper-scale run's) with a smoke test's numbers.
    args.results = args.results if args.results is not None else args.out / "results.md"
    check_results_path(args.results, args.out)
    arguments.prove_writable_file(args.results, "--results")
    if args.rewrite_results:
        state = RunState.load(args.out / "state.json")
        if not state.config:
            raise UserError(f"{args.out / 'state.json'}: no finished run to write results from")
        recorded = run_config(state, args.out / "state.json")
        if args.beside:
            from davis_ag.workflows.reproduce.pages.results import write_results_md

            beside = beside_runs(recorded, args.beside)
            check_page_rule(args.results, recorded.split_rule)
            write_results_md(args.results, recorded, state, args.out, beside)
        elif recorded.page == "mapping":
            from davis_ag.workflows.reproduce.mapping_run import write_run_page

            write_run_page(args.results, recorded, args.out, recorded.pairs)
        elif recorded.page == "robot":
            from davis_ag.workflows.reproduce.pages.robot import write_robot_page

            write_robot_page(args.results, recorded, state, args.out, recorded.pairs)
        elif recorded.page == "structures":
            from davis_ag.workflows.reproduce.pages.structures import write_structures_page

            write_structures_page(args.results, recorded, state, args.out, recorded.pairs)
        elif recorded.page == "a2c-search":
            from davis_ag.workflows.reproduce.a2c_search import check_page
            from davis_ag.workflows.reproduce.pages.a2c_search import write_search_page

            check_page(args.results)
            write_search_page(args.results, recorded, state, args.out)
        else:
            if recorded.page == "table4":
                check_page_rule(args.results, recorded.split_rule)
            write_page(args.results, recorded, state, args.out)
        print(f"wrote {args.results}")
        return 0
    if args.beside:
        raise UserError("--beside goes with --rewrite-results, once both runs have their records")
    arguments.prove_writable_folder(args.out)
    arguments.use_torch_threads(args)
    if config.page == "table4":
        check_page_rule(args.results, config.split_rule)
    pairs = [p for p in config.pairs if args.only in (None, p[0])]
    if not pairs:
        raise UserError(f"--only {args.only}: the {config.name} run has no {args.only} groups")
    if config.page == "mapping":
        from davis_ag.workflows.reproduce.mapping_run import reproduce_mapping

        return reproduce_mapping(config, args.out, args.results, pairs)
    if config.page == "robot":
        from davis_ag.workflows.reproduce.robot_run import reproduce_robot

        return reproduce_robot(config, args.out, args.results, pairs)
    if config.page == "structures":
        from davis_ag.workflows.reproduce.structures_run import reproduce_structures

        return reproduce_structures(config, args.out, args.results, pairs)
    if config.page == "a2c-search":
        from davis_ag.workflows.reproduce.a2c_search import reproduce_a2c_search

        return reproduce_a2c_search(config, args.out, args.results)
    return reproduce(config, args.out, args.results, pairs)

"""``davis-ag verify SCENE...``: make scenes again from their records and compare them byte for byte;
``davis-ag verify RESULTS.json... --dataset DATA``: replay every episode of results files on their dataset."""

from __future__ import annotations

import argparse
from pathlib import Path
from typing import Any

from davis_ag.commands import arguments

HELP = "make scenes again and compare them byte for byte, or replay results files on their dataset"
DESCRIPTION = (
    "Prove that a dataset of ours regenerates bit for bit: each SCENE folder is grown and drawn "
    "again from its scene.json (seed, grid, camera, renderer, plants, appearance) in a folder of "
    "its own, and every file is compared with the one on disk (scene.json as JSON, without the "
    "generator's versions and the timings). Nothing is written inside the dataset. Prints one line "
    "per scene; exits 0 when every scene came out identical, 1 otherwise. A scene takes as long as "
    "generate takes to make it. "
    "With --dataset, the arguments are results files of davis-ag evaluate instead: each is checked "
    "against the dataset it names (its fingerprint, the environment its protocol builds), every "
    "summary is made again from the episodes, and every episode of every policy is played again "
    "(its seeded start, then its recorded actions); prints sound, or the first episode that "
    "differs (policy, session, episode, field, stored and replayed value) and exits 1."
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``verify``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument(
        "scenes",
        type=arguments.path,
        nargs="+",
        metavar="SCENE|RESULTS.json",
        help="scene folders of a dataset made by davis-ag generate (e.g. data/Single-Strawberry/000), "
        "or with --dataset results files of davis-ag evaluate",
    )
    parser.add_argument(
        "--keep",
        type=arguments.path,
        default=None,
        metavar="DIR",
        help="keep the scenes made again in DIR, as a dataset (default: a temporary folder, removed after)",
    )
    parser.add_argument(
        "--dataset",
        type=arguments.path,
        default=None,
        metavar="DATA",
        help="replay the RESULTS.json files given on this dataset (the one they evaluated)",
    )
    parser.add_argument(
        "--cache-dir",
        type=arguments.path,
        default=None,
        metavar="DIR",
        help="with --dataset: the observation cache folder, as evaluate took it (default: in the dataset)",
    )
    parser.add_argument(
        "--robot",
        default=None,
        metavar="ROBOT.yaml",
        help="with --dataset: the YAML of the robot a results file was evaluated with, where it is not built in",
    )
    parser.add_argument(
        "--policy",
        action="append",
        default=[],
        metavar="NAME=SPEC",
        help="with --dataset: also play row NAME's episodes again with its code (SPEC as evaluate --policy "
        "takes it: file.py:function, file.py:Class, module:attr, MODEL.zip), which must have the digest the "
        "file records and give every recorded action (repeatable)",
    )
    arguments.add_split_rule_flag(parser, recorded=True)


def run(args: argparse.Namespace) -> int:
    """Verify each scene (or results file) in turn; 0 when all are sound, 1 otherwise."""
    from davis_ag.errors import UserError

    if args.dataset is not None:
        if args.keep is not None:
            raise UserError("--keep is for scenes made again; with --dataset nothing is made: leave it out")
        from davis_ag.workflows.stages.rerun import parse_policy_arguments

        return verify_results(
            args.scenes, args.dataset, args.cache_dir, args.robot, parse_policy_arguments(args.policy), args.split_rule
        )
    if args.split_rule is not None:
        raise UserError("--split-rule checks results files: give them with --dataset DATA, or leave it out")
    if args.policy:
        raise UserError("--policy re-runs a results file's row: give the results files and --dataset DATA")
    if files := [p for p in args.scenes if p.suffix == ".json"]:
        raise UserError(f"{files[0]}: to verify results, give the dataset they evaluated: --dataset DATA")
    from davis_ag.generate.regenerate import verify_scene

    check_before_making(args.scenes, args.keep)
    verdicts = []
    for scene in args.scenes:
        verdict = verify_scene(scene, args.keep)
        print(verdict.text(), flush=True)
        verdicts.append(verdict)
    same = sum(v.identical for v in verdicts)
    if len(verdicts) > 1:
        print(f"{same} of {len(verdicts)} scenes identical")
    return 0 if same == len(verdicts) else 1


def verify_results(
    paths: list[Path],
    dataset: Path,
    cache_dir: Path | None = None,
    robot: str | None = None,
    policies: dict[str, str] | None = None,
    split_rule: str | None = None,
) -> int:
    """Replay each results file on ``dataset`` (:mod:`davis_ag.benchmark.replay`) under the split
    rule it records, and play each row named in ``policies`` again with its code
    (:mod:`davis_ag.workflows.stages.rerun`); 0 when all are sound.

    Raises:
        UserError: for a file that is not results, holds a summary its episodes do not give, or
            cannot be replayed, a dataset that is not one, or a file of another rule than
            ``split_rule`` (None: any).
    """
    from davis_ag.benchmark.replay import replay_grid
    from davis_ag.benchmark.results import load_results
    from davis_ag.errors import UserError
    from davis_ag.mapping.results import is_mapping_results
    from davis_ag.workflows.stages.rerun import rerun_row

    policies = policies or {}
    reports: list[Any] = []
    for path in paths:
        results: Any
        if is_mapping_results(path):
            from davis_ag.mapping.evaluation import replay_mapping
            from davis_ag.mapping.results import load_mapping_results

            results = load_mapping_results(path)
            check_recorded_rule(path, None, split_rule)
            report: Any = replay_mapping(results, dataset, str(path), cache_dir, robot)
        else:
            results = load_results(path)  # every summary made again from the episodes first
            check_recorded_rule(path, results.protocol.split_rule, split_rule)
            if results.protocol.environment == "davis_ag/TVMContinuous-v0":
                from davis_ag.live.replay import replay_continuous

                report = replay_continuous(results, dataset, str(path), robot)
            else:
                report = replay_grid(results, dataset, str(path), cache_dir, robot)
        print(report.text(), flush=True)
        reports.append(report)
        missing = [name for name in policies if name not in results.policies]
        if len(paths) == 1 and missing:
            raise UserError(f"{path}: has no row {missing[0]!r} (its rows: {', '.join(results.policies)})")
        for name, spec in policies.items():
            if report.sound and name in results.policies:
                rerun = rerun_row(path, results, dataset, name, spec, cache_dir, robot)
                print(rerun.text(), flush=True)
                reports.append(rerun)
    sound = sum(r.sound for r in reports)
    if len(reports) > 1:
        print(f"{sound} of {len(reports)} {'checks' if policies else 'results files'} sound")
    return 0 if sound == len(reports) else 1


def check_recorded_rule(path: Path, recorded: str | None, wanted: str | None) -> None:
    """Refuse a results file evaluated under another split rule than ``--split-rule`` asks for.

    Args:
        path: The file, for the message.
        recorded: The rule its protocol records (None: a file from before the rules, or of an
            environment without them: ``scenes``).
        wanted: ``--split-rule`` (None: any rule).

    Raises:
        UserError: one line.
    """
    from davis_ag.errors import UserError

    if wanted is not None and (recorded or "scenes") != wanted:
        raise UserError(
            f"{path}: evaluated under --split-rule {recorded or 'scenes'}, not {wanted}: give files of one rule, "
            "or leave --split-rule out to replay each under its own"
        )


def check_before_making(scenes: list[Path], keep: Path | None) -> None:
    """Refuse, before the first scene is made again (minutes to hours each), what would fail later:
    records that cannot rebuild a scene, a scene given twice, and a ``--keep`` folder that lies in
    a dataset (:mod:`the output rule <davis_ag.formats.outputs>`), is not empty, or would hold
    scenes of datasets made with other settings.

    Raises:
        UserError: naming the scene or folder and what to do.
    """
    import os

    from davis_ag.errors import UserError
    from davis_ag.formats.outputs import check_outside_datasets
    from davis_ag.generate.regenerate import request_for, scene_folder_of
    from davis_ag.generate.run_config import grid_settings

    requests = [request_for(scene) for scene in scenes]
    folders = [os.path.realpath(scene_folder_of(scene)) for scene in scenes]
    if len(set(folders)) < len(folders):
        twice = next(f for f in folders if folders.count(f) > 1)
        raise UserError(f"{twice} is given twice: give each scene once")
    if keep is None:
        return
    check_outside_datasets(keep, "--keep")  # the output rule's owner: only generate writes in a dataset
    kept = arguments.prove_writable_folder(keep, "--keep")
    if kept.is_dir() and any(kept.iterdir()):
        raise UserError(f"--keep {keep} is not empty: choose a new or empty folder")
    # One --keep folder is one dataset: its scenes share every setting, and a scene id is made once.
    ids = [request.folder for request in requests]
    if len(set(ids)) < len(ids):
        twice = next(i for i in ids if ids.count(i) > 1)
        raise UserError(f"two scenes given are {twice}: verify them with one --keep folder each")

    def made_as(request: Any) -> tuple:
        """What one dataset's scenes share (its seed, camera and settings); a group shares its grid."""
        return request.dataset_seed, request.camera, request.scene_settings(), request.classes

    grids: dict[str, dict[str, Any]] = {}
    for request in requests:
        grid = grid_settings(request.scenario, request.crop)
        if made_as(request) != made_as(requests[0]) or grids.setdefault(request.folder.split("/")[0], grid) != grid:
            raise UserError(
                f"--keep {keep} would hold {requests[0].folder} and {request.folder}, made with other seeds, "
                "sizes, grids or settings: verify them with one --keep folder each"
            )

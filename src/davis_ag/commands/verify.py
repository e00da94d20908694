"""``davis-ag verify SCENE...``: make scenes again from their records and compare them byte for byte."""

from __future__ import annotations

import argparse

from davis_ag.commands import arguments

HELP = "make scenes again from their scene.json and compare every file byte for byte"
DESCRIPTION = (
    "Prove that a dataset of ours regenerates bit for bit: each SCENE folder is grown and drawn again "
    "from its scene.json and the dataset's dataset.json (seed, grid, camera, renderer, plants, "
    "appearance) in a folder of its own, and every file is compared with the one on disk "
    "(scene.json as JSON, without the generator's versions and the timings). Nothing is written "
    "inside the dataset. Prints one line per scene; exits 0 when every scene came out identical, "
    "1 otherwise. A scene takes as long as generate takes to make it."
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``verify``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument(
        "scenes",
        type=arguments.path,
        nargs="+",
        metavar="SCENE",
        help="scene folders of a dataset made by davis-ag generate (e.g. data/Single-Strawberry/000)",
    )
    parser.add_argument(
        "--keep",
        type=arguments.path,
        default=None,
        metavar="DIR",
        help="keep the scenes made again in DIR, as a dataset (default: a temporary folder, removed after)",
    )


def run(args: argparse.Namespace) -> int:
    """Verify each scene in turn; 0 when all are identical, 1 otherwise."""
    from davis_ag.errors import UserError
    from davis_ag.workflows.regenerate import request_for, scene_folder_of, verify_scene

    for scene in args.scenes:  # every scene's records, before the first long regeneration
        request_for(scene)
    if args.keep is not None:
        keep = arguments.prove_writable_folder(args.keep, "--keep")
        for scene in args.scenes:
            root = scene_folder_of(scene).parent.parent
            if keep == root or root in keep.parents:
                raise UserError(f"--keep {args.keep} lies in the dataset of {scene}: choose a folder outside it")
    verdicts = []
    for scene in args.scenes:
        verdict = verify_scene(scene, args.keep)
        print(verdict.text(), flush=True)
        verdicts.append(verdict)
    same = sum(v.identical for v in verdicts)
    if len(verdicts) > 1:
        print(f"{same} of {len(verdicts)} scenes identical")
    return 0 if same == len(verdicts) else 1

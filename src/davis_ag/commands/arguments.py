"""Argument types shared by the sub-commands: sizes, counts, seeds, lists and paths, each checked
as parsed, so a bad value is one argparse line (exit 2) before any work starts.

Output paths are checked again by the commands, before their long work, with
:func:`davis_ag.atomic_files.prove_writable_folder` / ``prove_writable_file`` (re-exported here):
those create a temporary file where the output will go, the only test that holds for root.
"""

from __future__ import annotations

import argparse
import os
from collections.abc import Callable
from pathlib import Path

from davis_ag.atomic_files import prove_writable_file, prove_writable_folder  # noqa: F401 - shared
from davis_ag.errors import UserError
from davis_ag.formats.models import MAX_SEED, check_image_size, check_seed


def image_size(text: str) -> tuple[int, int]:
    """Parse ``WIDTHxHEIGHT`` by the one image-size rule (:func:`davis_ag.formats.models.check_image_size`)."""
    try:
        return check_image_size(text.strip(), "")
    except UserError as error:
        raise argparse.ArgumentTypeError(f"not an image size: {error}") from None


def _digits(text: str) -> int | None:
    text = text.strip()
    # isascii: str.isdigit also accepts digits int() refuses, such as superscripts.
    return int(text) if text.isascii() and text.isdigit() else None


def count(text: str) -> int:
    """Parse a positive count."""
    value = _digits(text)
    if value is None or value < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not a positive whole number")
    return value


def whole(text: str) -> int:
    """Parse a whole number from 0."""
    value = _digits(text)
    if value is None:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number from 0")
    return value


def _finite(text: str) -> float | None:
    try:
        value = float(text.strip())
    except ValueError:
        return None
    return value if value == value and abs(value) != float("inf") else None


def positive_float(text: str) -> float:
    """Parse a finite number above 0 (a length in metres)."""
    value = _finite(text)
    if value is None or value <= 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number above 0")
    return value


def non_negative_float(text: str) -> float:
    """Parse a finite number from 0 (a length in metres)."""
    value = _finite(text)
    if value is None or value < 0:
        raise argparse.ArgumentTypeError(f"{text!r} is not a number from 0")
    return value


def bounded(low: int, high: int) -> Callable[[str], int]:
    """A parser of whole numbers from ``low`` to ``high`` (a sanity bound that keeps a typo such as
    an extra zero from starting days of work or exhausting memory)."""

    def parse(text: str) -> int:
        value = _digits(text)
        if value is None or not low <= value <= high:
            raise argparse.ArgumentTypeError(f"{text!r} is not a whole number from {low} to {high}")
        return value

    parse.__name__ = f"whole number from {low} to {high}"  # argparse names the type in errors
    return parse


def torch_threads(text: str) -> int:
    """Parse a torch thread count: from 1 to this machine's CPUs (more only queue for the cores)."""
    value, cpus = _digits(text), os.cpu_count() or 1
    if value is None or not 1 <= value <= cpus:
        raise argparse.ArgumentTypeError(f"{text!r}: give torch from 1 to {cpus} threads (this machine's CPUs)")
    return value


def add_torch_threads_flag(parser: argparse.ArgumentParser, verb: str) -> None:
    """Add ``--torch-threads`` (:func:`use_torch_threads`), shared by train and reproduce."""
    parser.add_argument(
        "--torch-threads",
        type=torch_threads,
        default=None,
        metavar="N",
        help=f"torch's threads to {verb} with (default: torch's own, one per core); two runs sharing a "
        'machine each train faster on their share of its cores (docs/performance.md, "Two trainings on '
        "one machine\"); each sitting's training record keeps the count",
    )


def use_torch_threads(args: argparse.Namespace) -> None:
    """Give torch the ``--torch-threads`` asked for (none asked: torch's own count stays)."""
    if args.torch_threads is not None:
        import torch

        torch.set_num_threads(args.torch_threads)


def seed(text: str) -> int:
    """Parse a seed by the one seed rule (:func:`davis_ag.formats.models.check_seed`)."""
    value = _digits(text)
    try:
        return check_seed(value if value is not None else text)
    except UserError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a seed: use a whole number from 0 to {MAX_SEED}") from None


def name_list(choices: tuple[str, ...]) -> Callable[[str], list[str]]:
    """A parser of a comma-separated, non-empty list of names from ``choices`` (any case),
    returned in the spelling of ``choices``, without repeats."""
    canonical = {c.lower(): c for c in choices}

    def parse(text: str) -> list[str]:
        names = [n.strip() for n in text.split(",") if n.strip()]
        if not names:
            raise argparse.ArgumentTypeError(
                f"{text!r} names nothing: give a comma-separated list of {', '.join(choices)}"
            )
        unknown = [n for n in names if n.lower() not in canonical]
        if unknown:
            raise argparse.ArgumentTypeError(f"unknown name {unknown[0]!r}: choose from {', '.join(choices)}")
        return list(dict.fromkeys(canonical[n.lower()] for n in names))

    return parse


def number_list(text: str) -> list[int]:
    """Parse a comma-separated, non-empty list of numbers from 1, e.g. ``1,40,200``."""
    parts = [p.strip() for p in text.split(",")]
    values = [_digits(p) for p in parts]
    if not parts or any(v is None or v < 1 for v in values):
        raise argparse.ArgumentTypeError(f"{text!r} is not a list of numbers from 1 like 1,40,200")
    return list(dict.fromkeys(v for v in values if v is not None))


def path(text: str) -> Path:
    """Parse a path and make it absolute at once.

    pyhelios changes the process's working directory while it builds and closes a Visualizer, so
    a relative path resolved later could point into pyhelios's folders.
    """
    if not text.strip():
        raise argparse.ArgumentTypeError("an empty path")
    if "\0" in text:
        raise argparse.ArgumentTypeError(f"{text!r} holds a NUL character, which no path may")
    try:
        return Path(text).expanduser().absolute()
    except RuntimeError:  # expanduser of ~name for a user that does not exist
        raise argparse.ArgumentTypeError(f"{text!r}: no such user's home folder") from None


def antialiasing_mode(text: str) -> str:
    """Parse ``--antialiasing``: fxaa, msaa or none (4 and 1, the samples per pixel earlier versions
    took, still mean msaa and none)."""
    from davis_ag.errors import UserError
    from davis_ag.render.backends import resolve_antialiasing

    try:
        return resolve_antialiasing(text)
    except UserError as error:
        raise argparse.ArgumentTypeError(str(error)) from None


def add_renderer_flags(parser: argparse.ArgumentParser) -> None:
    """How a scene is grown and drawn, shared by generate and preview: ``--renderer``, ``--look``,
    ``--antialiasing``, ``--plants``, ``--appearance``, ``--structures`` and ``--strawberry-altitudes``."""
    from davis_ag.render.backends import LOOKS, RENDERERS
    from davis_ag.scene.specs import PLANT_GENERATORS

    parser.add_argument(
        "--renderer",
        choices=RENDERERS,
        help="opengl: ours (default); helios: pyhelios's Visualizer, the slower reference",
    )
    parser.add_argument(
        "--look",
        choices=LOOKS,
        help="default: full-resolution, filtered textures (default); helios: Helios's frames, "
        "reduced unfiltered textures included (the helios renderer draws only this)",
    )
    parser.add_argument(
        "--antialiasing",
        type=antialiasing_mode,
        metavar="{fxaa,msaa,none}",
        help="our renderer's: fxaa along silhouettes (default), msaa (4x samples: closest to "
        "Helios's frames, several times slower without a GPU) or none; ids exact in every mode",
    )
    parser.add_argument(
        "--plants",
        choices=PLANT_GENERATORS,
        help="canopy: Helios's Canopy Generator plants, as the paper's (default); architecture: "
        "pyhelios3d's PlantArchitecture plants bent towards them",
    )
    parser.add_argument(
        "--appearance",
        choices=("paper", "random"),
        help="paper: the paper's sky, soil and exposure (default); random: per scene, from its "
        "seed, the sun, sky, soil, exposure, white balance and sensor noise (labels unchanged)",
    )
    parser.add_argument(
        "--structures",
        choices=("none", "default"),
        help="default: a row scene gets its crop's trellis posts and wires, stakes and twine, or "
        "greenhouse strings and heating pipes (organ class structure); none: the bare rows of before",
    )
    parser.add_argument(
        "--strawberry-altitudes",
        choices=("table1", "readme"),
        help="strawberry camera altitudes: table1 = Table 1's 25/40/55 cm (default), "
        "readme = the dataset README's and Fig. 2's 0.50/0.75/1.00 m",
    )


def check_crop_flags(args: argparse.Namespace, crop, scenario, local: bool = True) -> None:
    """Refuse, before anything grows, what a crop does not offer: ``--plants`` for a plant-library
    crop (its plants come from the library only), and a scene too large for this machine.

    Args:
        args: The parsed flags (``plants``).
        crop, scenario: The scene's kind.
        local: Whether the scene is made on this machine (the size check).

    Raises:
        UserError: one line.
    """
    from davis_ag.errors import UserError
    from davis_ag.scene.scene_size import check_scene_size

    if getattr(args, "plants", None) is not None and crop.source == "library":
        raise UserError(
            f"--plants {args.plants}: {crop.name} grows from Helios's plant library only; "
            "--plants chooses the paper's crops' plants: drop it"
        )
    if local:
        check_scene_size(scenario, crop)


def add_dataset_flags(parser: argparse.ArgumentParser, verb: str) -> None:
    """Add ``--dataset``, ``--scenario``, ``--crop`` and ``--cache-dir``, shared by train and evaluate.

    Args:
        parser: the sub-command's parser.
        verb: what the command does, as ``--crop``'s help says it: "train" gives "train on one crop only".
    """
    parser.add_argument("--dataset", type=path, required=True, metavar="DIR", help="dataset root")
    parser.add_argument(
        "--scenario",
        required=True,
        choices=["sp", "mp", "row"],
        help="single plant (tau=3), multi plant (tau=5) or an orchard row (tau=5)",
    )
    parser.add_argument("--crop", default=None, help=f"{verb} on one crop only (default: all)")
    parser.add_argument(
        "--cache-dir",
        type=path,
        default=None,
        metavar="DIR",
        help="observation cache folder (default: DIR/.davis_ag_cache)",
    )


def add_split_rule_flag(parser: argparse.ArgumentParser, recorded: bool = False) -> None:
    """Add ``--split-rule`` (:data:`davis_ag.formats.splits.SPLIT_RULES`): train's and evaluate's
    rule (default ``scenes``), or, with ``recorded``, verify's and compare's check of the rule the
    results files record (default: none, each file replayed under its own).

    Args:
        parser: the sub-command's parser.
        recorded: Whether the rule is read from results files rather than chosen.
    """
    from davis_ag.formats.splits import SPLIT_RULES

    rules = (
        "scenes: 70 %% of each group's scenes train, 30 %% test (splits.json); starts: train and test play "
        "the same scenes, 70 %% of each group's (view, target) starts train, 30 %% test; fruits: 70 %% of "
        "each group's target fruits train, their starts with them (TVM-v0 only; docs/benchmark.md)"
    )
    if recorded:
        parser.add_argument(
            "--split-rule",
            choices=SPLIT_RULES,
            default=None,
            help="refuse results files evaluated under another split rule (default: each under the rule it "
            "records; a file from before the rules records scenes). " + rules,
        )
        return
    parser.add_argument("--split-rule", choices=SPLIT_RULES, default="scenes", help="(default: scenes) " + rules)


def add_task_flags(parser: argparse.ArgumentParser, verb: str) -> None:
    """Add ``--task``, ``--budget``, ``--seen-fraction`` and ``--split-rule``, shared by train and evaluate.

    Args:
        parser: the sub-command's parser.
        verb: what the command does with the task (``train``: "train on"; evaluate: "score").
    """
    parser.add_argument(
        "--task",
        default="tvm",
        choices=["tvm", "mapping"],
        help=f"tvm: {verb} target visibility maximisation (default); mapping: {verb} row mapping "
        "(RowMapping-v0, docs/mapping.md; the grid only)",
    )
    parser.add_argument(
        "--budget",
        type=bounded(1, 10**5),
        default=None,
        metavar="MOVES",
        help="--task mapping: moves per episode (default: the fixed sweep's, driving the row once at each height)",
    )
    parser.add_argument(
        "--seen-fraction",
        type=float,
        default=None,
        metavar="F",
        help="--task mapping: the visible fraction at which a fruit counts as seen (default 0.5)",
    )
    add_split_rule_flag(parser)


def check_task_split_rule(args: argparse.Namespace) -> None:
    """Refuse ``--split-rule`` other than scenes where it does not apply: ``--task mapping`` and
    ``--env continuous`` split by scenes only.

    Raises:
        UserError: one line.
    """
    rule = getattr(args, "split_rule", "scenes")
    other = (
        "--task mapping"
        if args.task == "mapping"
        else "--env continuous"
        if getattr(args, "env", "") == "continuous"
        else None
    )
    if rule != "scenes" and other is not None:
        raise UserError(f"--split-rule {rule} splits TVM-v0's starts; {other} splits by scenes: leave it out")

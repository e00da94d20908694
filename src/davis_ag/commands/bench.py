"""``davis-ag bench``: what a labelled view costs with our renderer against pyhelios's documented
path, the environments' steps per second, and what the paper-scale dataset would take
(:mod:`davis_ag.workflows.bench.run`). ``make bench`` runs it and writes docs/performance.md."""

from __future__ import annotations

import argparse
import json
from pathlib import Path

from davis_ag.commands import arguments
from davis_ag.scene.specs import CROPS

HELP = "time our renderer against Helios's documented path and project the paper-scale run"
DESCRIPTION = __doc__
CROP_NAMES = ("strawberry", "tomato", "vine")
#: The plant-library crops ``--only crops`` measures.
LIBRARY_NAMES = tuple(name for name, crop in CROPS.items() if crop.source == "library")
#: The measurements ``--only`` runs alone, each written between its ``bench-NAME`` markers.
MEASUREMENTS = ("continuous", "training", "crops", "verify", "play", "robot", "mapping", "sharing")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``bench``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument(
        "--out",
        type=arguments.path,
        default="out/bench.json",
        metavar="BENCH.json",
        help="the JSON report (default out/bench.json)",
    )
    parser.add_argument(
        "--crops",
        type=arguments.name_list(tuple(CROPS)),
        default=None,
        help="crops to time, comma-separated: the paper's (default all three; the documented path "
        "only where a target is set), or with --only crops plant-library crops (default all; the "
        "others keep the rows of an earlier --out report)",
    )
    parser.add_argument("--repeats", type=arguments.count, default=3, help="interleaved repetitions (default 3)")
    parser.add_argument(
        "--antialiasing",
        choices=("fxaa", "msaa", "none"),
        default="fxaa",
        help="our renderer's antialiasing (default fxaa)",
    )
    parser.add_argument(
        "--doc",
        type=arguments.path,
        metavar="PAGE.md",
        help="write the tables into this Markdown file's bench sections (its -gpu ones on a GPU machine)",
    )
    parser.add_argument(
        "--only",
        choices=("all", *MEASUREMENTS),
        default="all",
        help="continuous: only TVMContinuous-v0's steps/s (about a minute); training: only the "
        "learners' training steps/s (about 8 minutes); crops: only the plant-library crops' single "
        "plants and rows (grow, s/view, memory; about half an hour); verify: only how fast a results "
        "file's summaries and episodes are checked (about a minute); play: only a trained model's "
        "episodes one at a time against in step (about a minute); robot: the robots' reach of a row "
        "scene and a grid step with a robot (about five minutes); mapping: a row-mapping step beside "
        "TVM-v0's, the segment's ceiling and the budget's bound (about five minutes); sharing: two "
        "trainings at once with torch's threads each and with half the cores each, beside one alone "
        "(about five minutes)",
    )
    parser.add_argument(
        "--device",
        choices=("cpu", "cuda"),
        default="cpu",
        help="with --only training: cuda times every learner on the CPU and then on the GPU, in one "
        "process, for what the GPU gains (default cpu)",
    )


def _is_report(path: Path) -> bool:
    """Whether a file is a report an earlier ``davis-ag bench`` wrote."""
    try:
        data = json.loads(path.read_text())
    except (OSError, ValueError):
        return False
    return isinstance(data, dict) and bool({"machine", "continuous_env", *MEASUREMENTS} & set(data))


def run(args: argparse.Namespace) -> int:
    """Measure, print and write the report (and the doc's sections)."""
    from davis_ag.atomic_files import prove_writable_folder, read_page, write_marked_section
    from davis_ag.errors import UserError
    from davis_ag.workflows.bench.report import doc_section, is_gpu_machine, table, write_continuous
    from davis_ag.workflows.bench.run import run as run_bench
    from davis_ag.workflows.bench.run import run_only, training_devices
    from davis_ag.workflows.bench.training import write_training

    # Minutes of measuring come before anything is written: refuse a bad output first, and never
    # replace a file that is not an earlier report.
    prove_writable_folder(args.out.parent)
    if args.out.exists() and not _is_report(args.out):
        raise UserError(f"--out {args.out}: holds something other than an earlier bench report; give a new .json path")
    allowed = LIBRARY_NAMES if args.only == "crops" else CROP_NAMES
    if wrong := [name for name in args.crops or [] if name not in allowed]:
        which = "the plant-library crops" if args.only == "crops" else "the paper's crops (the others: --only crops)"
        raise UserError(
            f"--crops {','.join(wrong)}: {'--only crops' if args.only == 'crops' else 'this bench'} times {which}"
        )
    args.crops = args.crops or list(allowed)
    if args.device != "cpu" and args.only != "training":
        raise UserError(f"--device {args.device} is for --only training: add --only training, or leave --device out")
    # A GPU machine's numbers go to the page's GPU sections, beside the 2-core machine's.
    gpu = args.doc is not None and is_gpu_machine()
    sections = [f"bench-{args.only}"] if args.only in MEASUREMENTS else None
    if sections is None:  # the whole bench: the view costs, and with strawberry the rates too
        sections = ["bench", "bench-continuous", "bench-training"] if "strawberry" in args.crops else ["bench"]
    markers = [doc_section(name, gpu) for name in sections]
    page = read_page(args.doc, "--doc") if args.doc is not None and args.doc.is_file() else ""
    missing = [m for m in markers if f"<!-- {m}:start -->" not in page or f"<!-- {m}:end -->" not in page]
    if args.doc is not None and missing:
        raise UserError(
            f"--doc {args.doc}: not a Markdown page with <!-- {missing[0]}:start --> and <!-- {missing[0]}:end --> "
            "markers; give docs/performance.md or leave --doc out"
        )
    if args.only in MEASUREMENTS:
        # A GPU machine's training table is always the CPU's beside the GPU's (where torch has CUDA).
        devices = ("cpu", args.device) if args.device != "cpu" else (training_devices() if gpu else ("cpu",))
        run_only(args.only, args.out, args.doc, devices, gpu, crops=args.crops)
        print(f"written {args.out}" + (f" and {args.doc}" if args.doc else ""))
        return 0
    report = run_bench(args.out, args.crops, args.repeats, args.antialiasing)
    text = table(report)
    print(text)
    if args.doc:
        write_marked_section(args.doc, markers[0], text)
        load = report["machine"]["load_average"]
        if "continuous_env" in report:
            write_continuous(report["continuous_env"], (load["start"][0], load["end"][0]), args.doc, gpu)
        if "training" in report:
            write_training(report["training"], (load["start"][0], load["end"][0]), args.doc, gpu)
        print(f"written {args.doc}")
    print(f"written {args.out}")
    return 0

"""``davis-ag transfer``: Table 5's experiment: pre-train on DAVIS-Ag, fine-tune on a real set."""

from __future__ import annotations

import argparse

from davis_ag.commands import arguments
from davis_ag.errors import UserError

HELP = "Table 5: YOLOv5n real-only vs pre-trained on DAVIS-Ag, over random splits"
DESCRIPTION = (
    "Pre-train YOLOv5n (ultralytics, built from its YAML, nothing downloaded) on a DAVIS-Ag dataset, "
    "then, on N random train/test splits of a real set, train it from scratch (Real-Only) and from "
    "the pre-trained weights (DAVIS-Ag -> Real) with the same budget, and report mAP@50 and "
    "mAP@50:95 per split like Table 5. Needs pip install 'davis-ag[detect]'."
)


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``transfer``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument(
        "--pretrain",
        type=arguments.path,
        required=True,
        metavar="DIR",
        help="DAVIS-Ag dataset to pre-train on (e.g. Single-Strawberry scenes)",
    )
    parser.add_argument(
        "--real",
        type=arguments.path,
        required=True,
        metavar="PATH",
        help="the real set: ultralytics data YAML, folder with images/ and labels/, or COCO JSON",
    )
    parser.add_argument(
        "--real-images",
        type=arguments.path,
        default=None,
        metavar="DIR",
        help="image folder of a COCO --real (default: as its file names say)",
    )
    parser.add_argument(
        "--real-label",
        default="real set",
        metavar="TEXT",
        help="how the results name the real set; include 'stand-in' for a synthetic one",
    )
    parser.add_argument("--out", type=arguments.path, required=True, metavar="DIR", help="work folder")
    parser.add_argument("--splits", type=arguments.count, default=3, help="random splits (default 3)")
    parser.add_argument("--train-size", type=arguments.count, default=654, help="train images per split (654)")
    parser.add_argument("--test-size", type=arguments.count, default=159, help="test images per split (159)")
    parser.add_argument("--seed", type=arguments.whole, default=0, help="split k draws with seed + k (default 0)")
    parser.add_argument("--epochs", type=arguments.count, default=100, help="epochs of every real-set run (100)")
    parser.add_argument("--pretrain-epochs", type=arguments.count, default=100, help="pre-training epochs (100)")
    parser.add_argument("--imgsz", type=arguments.count, default=640, help="input size in pixels (640)")
    parser.add_argument("--batch", type=arguments.count, default=16, help="batch size (16)")
    parser.add_argument("--device", default="cpu", help="cpu (default), 0 for the first GPU, ...")
    parser.add_argument("--workers", type=arguments.whole, default=0, help="data-loading processes (0)")
    parser.add_argument(
        "--results",
        type=arguments.path,
        default=None,
        metavar="MD",
        help="also write a Markdown report (e.g. docs/transfer/results.md)",
    )
    parser.add_argument("--force", action="store_true", help="replace an existing --results report")


def run(args: argparse.Namespace) -> int:
    """Run the experiment and print the Table-5-style table."""
    from contextlib import nullcontext

    from davis_ag.detection.yolo_training import Budget
    from davis_ag.formats.outputs import check_outside_datasets, claim_output
    from davis_ag.workflows.transfer import (
        WORK_RECORD,
        TransferConfig,
        run_transfer,
        table5_markdown,
        write_results_md,
    )

    # Before any export or training: the work folder and the report never land in a dataset.
    check_outside_datasets(args.out)
    arguments.prove_writable_folder(args.out)
    if args.imgsz < 32 or args.imgsz % 32:
        raise UserError(f"--imgsz must be a multiple of 32 (YOLO's stride), at least 32; got {args.imgsz}")
    budget = Budget(args.epochs, args.imgsz, args.batch, args.device, args.workers)
    config = TransferConfig(
        pretrain=args.pretrain,
        real=args.real,
        out=args.out,
        real_images=args.real_images,
        real_label=args.real_label,
        splits=args.splits,
        train_size=args.train_size,
        test_size=args.test_size,
        seed=args.seed,
        pretrain_budget=Budget(args.pretrain_epochs, args.imgsz, args.batch, args.device, args.workers),
        budget=budget,
    )
    report = (
        claim_output(  # never over the real set, nor the work folder's own records
            args.results,
            force=args.force,
            flag="--results",
            reads=[(args.real, "--real"), (args.out / "transfer.json", "OUT's"), (args.out / WORK_RECORD, "OUT's")],
        )
        if args.results
        else nullcontext()
    )
    with report:  # the output rule, before hours of training
        results = run_transfer(config)
        print(table5_markdown(results))
        print(f"wrote {args.out / 'transfer.json'} ({results['wall_s']['total']:.0f} s)")
        if args.results:
            from davis_ag.provenance import machine_description

            print(f"wrote {write_results_md(results, args.results, machine_description())}")
    return 0

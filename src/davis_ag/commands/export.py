"""``davis-ag export coco|yolo|pointcloud|usd|mesh|nerfstudio DIR OUT``: a DAVIS-Ag dataset in a detection
format, by split, as point clouds (PLY) from its depth images, or in 3-D (:mod:`davis_ag.commands.world_export`)."""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

from davis_ag.atomic_files import write_json_atomic
from davis_ag.commands import arguments
from davis_ag.commands.world_export import WORLD_FORMATS, add_formats, check_scenes, run_world
from davis_ag.errors import UserError
from davis_ag.formats.outputs import LOCK_FILE, claim_output

HELP = "write a dataset as COCO or YOLO detection data, point clouds, USD stages, labelled meshes or nerfstudio sets"
DESCRIPTION = (
    "Export a DAVIS-Ag dataset for detectors, one set per split (splits.json, else the benchmark's "
    "seeded 70/30 split by scene). coco: OUT/annotations/instances_<split>.json with RLE masks, "
    "boxes, fruit ids and visible fractions, images referenced in place. yolo: the ultralytics "
    "layout (images/, labels/, data.yaml). pointcloud: PLY point clouds in the world frame from "
    "the depth images, with colour, organ class and fruit id. usd, mesh, nerfstudio: each scene in 3-D "
    "(docs/worlds.md): a USD stage with plants, fruit and cameras; its triangles labelled per face "
    "(PLY or GLB); nerfstudio's transforms.json with the views' poses."
)

#: What an export folder may already hold (a previous export: carried on when unfinished, replaced with --force).
_OURS = {"coco": {"annotations"}, "yolo": {"images", "labels", "data.yaml"}, "pointcloud": set()}
_OURS.update({name: set() for name in WORLD_FORMATS})  # group folders only, as pointcloud
#: Marks an export that has not finished: the same command carries on without --force.
UNFINISHED = ".davis_ag-export-unfinished"
#: What a killed export leaves (hidden working folders, temporary files), removed by the next run.
LEFT_BY_A_KILL = ("annotations/.coco-*", "**/.*.tmp")


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``export``'s formats, each a sub-parser with its own arguments (see :mod:`davis_ag.commands`)."""
    formats = parser.add_subparsers(dest="format", required=True, metavar="{coco,yolo,pointcloud,usd,mesh,nerfstudio}")
    for name, help_text in (
        ("coco", "COCO instances JSON, masks as pycocotools RLE"),
        ("yolo", "ultralytics layout: images/, labels/, data.yaml"),
    ):
        sub = formats.add_parser(name, help=help_text, description=help_text)
        sub.add_argument("dir", type=arguments.path, metavar="DIR", help="dataset root, group folder or scene folder")
        sub.add_argument("out", type=arguments.path, metavar="OUT", help="export folder (new, or a previous export)")
        sub.add_argument(
            "--split", choices=("train", "test", "both"), default="both", help="which split to write (default both)"
        )
        sub.add_argument("--force", action="store_true", help="replace a finished export in OUT")
        sub.add_argument(
            "--organs",
            action="store_true",
            help="also the organ classes (soil, fruit, leaf, stem, trunk) as semantic masks, from "
            "the views' NNNN_class.png"
            + (" (with --task segment)" if name == "yolo" else " (RLE, category ids 101-105)"),
        )
        if name == "yolo":
            sub.add_argument(
                "--task",
                choices=("detect", "segment"),
                default="detect",
                help="label lines: boxes (detect, default) or polygons (segment)",
            )
            sub.add_argument(
                "--appearance-shift",
                type=arguments.whole,
                default=None,
                metavar="SEED",
                help="re-colour, light from one side, blur, add noise and re-compress every "
                "exported image (copies; the dataset is untouched): a stand-in for real "
                "photographs when none are at hand",
            )
    cloud = formats.add_parser(
        "pointcloud",
        help="PLY point clouds from the depth images (world frame, colour, organ, fruit id)",
        description="One PLY per view (OUT/<group>/<scene>/NNNN.ply), or per scene with --fuse "
        "(OUT/<group>/<scene>.ply): points in the world frame from each depth image, the "
        "recorded intrinsics and the pose, with colour, organ class and fruit id.",
    )
    cloud.add_argument("dir", type=arguments.path, metavar="DIR", help="dataset root, group folder or scene folder")
    cloud.add_argument("out", type=arguments.path, metavar="OUT", help="export folder (new, or a previous export)")
    cloud.add_argument("--force", action="store_true", help="replace a finished export in OUT")
    cloud.add_argument("--fuse", action="store_true", help="one cloud per scene, all its views joined")
    cloud.add_argument(
        "--max-depth",
        type=arguments.positive_float,
        default=5.0,
        metavar="M",
        help="drop points farther than this from the camera, m (default 5; the far soil reaches 30 m)",
    )
    cloud.add_argument(
        "--voxel",
        type=arguments.non_negative_float,
        default=None,
        metavar="M",
        help="keep one point per cube of this side, m (default 0.005 with --fuse, else 0: all)",
    )
    add_formats(formats)


def check_out(out: Path, fmt: str) -> None:
    """Refuse an output folder that holds anything but a previous export of the same format."""
    if out.exists() and not out.is_dir():
        raise UserError(f"{out}: is a file; give a folder for the export")
    if out.is_dir():
        from davis_ag.scene.specs import parse_group_name

        foreign = sorted(
            p.name
            for p in out.iterdir()
            if p.name not in _OURS[fmt] | {UNFINISHED, LOCK_FILE}
            and not (fmt in ("pointcloud", *WORLD_FORMATS) and p.is_dir() and parse_group_name(p.name))
        )
        if foreign:
            raise UserError(
                f"{out}: holds {', '.join(foreign[:3])}{' ...' if len(foreign) > 3 else ''}, "
                f"which is not a {fmt} export; give a new or empty folder"
            )


def run(args: argparse.Namespace) -> int:
    """Export ``args.dir`` to ``args.out``; prints the counts per split."""
    from davis_ag.data.reader import open_dataset
    from davis_ag.detection.instances import check_export_splits

    dataset = open_dataset(args.dir)  # a bad DIR, or a split that lost a scene, before anything is created
    scenes = check_scenes(args) if args.format in WORLD_FORMATS else []  # scene.json, before OUT is made
    if args.format not in ("pointcloud", *WORLD_FORMATS):
        check_export_splits(dataset)
    if args.format == "yolo" and args.task == "segment":  # polygons need masks: refused before anything is made
        lacking = next((v for s in dataset.scenes for v in s if not v.mask_path.is_file()), None)
        if lacking is not None:
            raise UserError(
                f"{lacking.mask_path}: missing, and --task segment needs every view's instance mask; "
                "export with --task detect, or regenerate the scene"
            )
    check_out(args.out, args.format)
    marker, wanted = args.out / UNFINISHED, export_settings(args)
    unfinished = marker.exists()  # a stopped export: the same command carries on
    if unfinished and not args.force:
        check_same_export(marker, wanted)
    with claim_output(args.out, force=args.force or unfinished, folder=True, temporaries=LEFT_BY_A_KILL):
        if args.force:  # replaced, not refreshed: nothing of the old export stays beside the new one
            clear_export(args.out)
        write_json_atomic(marker, wanted)
        if args.format in WORLD_FORMATS:
            code = run_world(args, scenes)
        else:
            code = run_point_clouds(args) if args.format == "pointcloud" else _export(args)
        marker.unlink()
    return code


def export_settings(args: argparse.Namespace) -> dict[str, object]:
    """What an export is of: the dataset (as the file system takes its path) and every option."""
    from davis_ag.formats.outputs import resolved

    chosen = {
        key: value if isinstance(value, (bool, int, float, type(None))) else str(value)
        for key, value in sorted(vars(args).items())
        if key not in ("out", "force", "dir") and not callable(value)
    }
    return {"dir": str(resolved(args.dir)), **chosen}


def check_same_export(marker: Path, wanted: dict[str, object]) -> None:
    """Refuse to carry on a stopped export with another dataset or options: the two would mix.

    Raises:
        UserError: naming what differs and both ways on.
    """
    import json

    try:
        recorded = json.loads(marker.read_text())
    except (OSError, ValueError):
        recorded = None
    if not isinstance(recorded, dict):  # an older run's empty marker: taken as this export's
        return
    differ = [k for k in ("dir", *sorted(set(recorded) | set(wanted))) if recorded.get(k) != wanted.get(k)]
    if differ:
        key = differ[0]
        raise UserError(
            f"{marker.parent} holds an unfinished export of another {'dataset' if key == 'dir' else key} "
            f"({recorded.get(key)} against {wanted.get(key)}): run that export again to finish it, "
            "or give --force to start this one over"
        )


def clear_export(out: Path) -> None:
    """Remove a previous export's files (:func:`check_out` found nothing else there)."""
    import shutil

    for entry in out.iterdir():
        if entry.name == LOCK_FILE:
            continue
        if entry.is_dir() and not entry.is_symlink():
            shutil.rmtree(entry)
        else:
            entry.unlink()


def _export(args: argparse.Namespace) -> int:
    """Write the COCO or YOLO export of ``args.dir`` into the claimed ``args.out``."""
    splits = ("train", "test") if args.split == "both" else (args.split,)
    if args.format == "coco":
        from davis_ag.detection.coco_export import export_coco

        counts = export_coco(args.dir, args.out, splits, organs=args.organs)
        unit = "annotations"
    else:
        from davis_ag.detection.yolo_export import export_yolo

        counts = export_yolo(args.dir, args.out, args.task, splits, organs=args.organs)
        unit = "instances"
        if args.appearance_shift is not None:
            from davis_ag.detection.appearance_shift import shift_folder

            shift_folder(args.out / "images", args.appearance_shift)
    for split, c in counts.items():
        print(f"{split}: {c['images']} images, {c[unit]} {unit}")
    clipped, dropped = (sum(c.get(key, 0) for c in counts.values()) for key in ("clipped", "dropped"))
    if clipped or dropped:
        print(
            f"note: {clipped} box(es) reaching outside their image were cut to it and {dropped} with no pixel "
            "inside were left out; `davis-ag validate` lists them",
            file=sys.stderr,
        )
    where = args.out / "annotations" if args.format == "coco" else args.out / "data.yaml"
    print(f"wrote {where}")
    return 0


def run_point_clouds(args: argparse.Namespace) -> int:
    """Write the PLY point clouds of ``args.dir`` under the claimed ``args.out``; prints the counts."""
    from davis_ag.data.point_cloud import export_point_clouds

    voxel = args.voxel if args.voxel is not None else (0.005 if args.fuse else 0.0)
    counts = export_point_clouds(args.dir, args.out, args.fuse, args.max_depth, voxel)
    print(f"{counts['scenes']} scenes: {counts['files']} PLY files, {counts['points']:,} points; wrote {args.out}")
    return 0

"""``davis-ag generate``: render scenes into a dataset folder in the published layout."""

from __future__ import annotations

import argparse
import re
from pathlib import Path

from tqdm import tqdm

from davis_ag.config import crop_spec, scenario_spec
from davis_ag.errors import UserError
from davis_ag.generate import SceneRequest, check_output_root, check_scene_slot, generate_scene
from davis_ag.render import Camera


def image_size(text: str) -> tuple[int, int]:
    """Parse ``WIDTHxHEIGHT``."""
    match = re.fullmatch(r"(\d+)x(\d+)", text.strip())
    if not match or min(int(match[1]), int(match[2])) < 16:
        raise argparse.ArgumentTypeError(f"{text!r} is not an image size like 1280x720 (16 pixels at least)")
    return int(match[1]), int(match[2])


def count(text: str) -> int:
    """Parse a positive count."""
    if not text.isdigit() or int(text) < 1:
        raise argparse.ArgumentTypeError(f"{text!r} is not a positive whole number")
    return int(text)


def register(subparsers) -> None:
    parser = subparsers.add_parser("generate", help="render DAVIS-Ag scenes with Helios",
                                   description=__doc__)
    parser.add_argument("--crop", default="strawberry", help="strawberry, tomato or vine")
    parser.add_argument("--scenario", default="sp", help="sp (single plant) or mp (multi plant)")
    parser.add_argument("--scenes", type=count, default=1, help="how many scenes (default 1)")
    parser.add_argument("--first", type=int, default=0, help="index of the first scene (default 0)")
    parser.add_argument("--seed", type=int, default=0, help="dataset seed (default 0)")
    parser.add_argument("--size", type=image_size, default=(1280, 720), help="image size (default 1280x720)")
    parser.add_argument("--out", type=Path, required=True, help="dataset folder")
    parser.set_defaults(func=run)


def run(args: argparse.Namespace) -> int:
    crop, scenario = crop_spec(args.crop), scenario_spec(args.scenario)
    if args.first < 0 or args.first + args.scenes > 1000:
        raise UserError(f"scene indices {args.first}..{args.first + args.scenes - 1} do not fit 000..999")
    if args.seed < 0:
        raise UserError(f"--seed {args.seed} is negative: use a whole number from 0")
    check_output_root(args.out)
    camera = Camera(*args.size)
    requests = [SceneRequest(scenario, crop, args.first + i, args.seed, camera) for i in range(args.scenes)]
    todo = [r for r in requests if not check_scene_slot(args.out, r)]
    if len(todo) < len(requests):
        print(f"{len(requests) - len(todo)} of {len(requests)} scenes already complete in {args.out}: skipped")
    with tqdm(total=len(todo), desc="scenes", unit="scene", position=0) as scenes_bar, \
         tqdm(desc="views", unit="view", position=1, leave=False) as views_bar:
        for request in todo:
            views_bar.reset()
            views_bar.set_description(f"views {request.folder}")

            def on_view(done: int, total: int) -> None:
                views_bar.total = total
                views_bar.update(1)

            scene_dir, stats = generate_scene(request, args.out, on_view)
            scenes_bar.update(1)
            tqdm.write(f"{scene_dir}: {stats['views']} views, grown in {stats['grow_s']:.1f} s, "
                       f"{stats['views_s'] / stats['views']:.3f} s per view")
    return 0

"""``davis-ag reach DATASET --robot NAME``: which views of each scene a robot reaches.

Prints, per group and camera height, the share of views the robot reaches (an IK solution within
joint limits, clear of itself, its platform, the ground and the scene's trunks: docs/robot.md), and
draws each scene's grid coloured by reach into ``--out``. The reach is computed once per scene and
robot and cached beside the observation caches (``--cache-dir``), never inside the scenes."""

from __future__ import annotations

import argparse
import sys

import numpy as np

from davis_ag.commands import arguments

HELP = "which views of a dataset's scenes a robot reaches (table and a picture per scene)"
DESCRIPTION = __doc__


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``reach``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument("dataset", type=arguments.path, metavar="DATASET", help="a generated dataset's root")
    parser.add_argument(
        "--robot", required=True, metavar="ROBOT", help="a robot (davis-ag robots lists them) or a YAML file"
    )
    parser.add_argument("--out", type=arguments.path, required=True, metavar="DIR", help="folder for the pictures")
    parser.add_argument("--scenario", default=None, help="only this scenario's scenes (sp, mp or row)")
    parser.add_argument("--crop", default=None, help="only this crop's scenes (e.g. vsp-vine)")
    parser.add_argument(
        "--cache-dir",
        type=arguments.path,
        default=None,
        metavar="DIR",
        help="the caches' folder (default: in the dataset)",
    )
    parser.add_argument("--force", action="store_true", help="replace pictures already in --out")
    parser.add_argument(
        "--episode",
        type=arguments.whole,
        default=None,
        metavar="SEED",
        help="also draw the Oracle's TVM-v0 episode of this seed under the robot as a strip: the arm at each "
        "step, seen from the alley, above what its camera saw (reopens the scene: minutes the first time)",
    )
    parser.add_argument(
        "--doc",
        type=arguments.path,
        default=None,
        metavar="PAGE.md",
        help="also write the table between <!-- reach-ROBOT:start/end --> markers in this page (docs/robot.md)",
    )


def _episode_strip(dataset, scenario: str, robot: str, args: argparse.Namespace, out) -> object:
    """Play the Oracle's episode ``--episode`` under the robot and draw it (figures/robot_strip.py)."""
    from davis_ag.benchmark import TVMEnv
    from davis_ag.benchmark.agents import build_agents
    from davis_ag.benchmark.evaluation import run_episode
    from davis_ag.figures.robot_strip import plot_robot_strip
    from davis_ag.live.robot_pictures import robot_frames

    env = TVMEnv(dataset, scenario, split="all", crop=args.crop, robot=robot, cache_dir=args.cache_dir)
    played = run_episode(env, build_agents(["Oracle"])[0], args.episode)
    _, info = env.reset(seed=args.episode)
    steps = [(info["path"][-1], 0.0, info["oer_t"])]
    for action in played["actions"]:
        info = env.step(action)[4]
        if action != env.done_action and info["path"][-1] != steps[-1][0]:
            steps.append((info["path"][-1], info["robot"]["seconds"], info["oer_t"]))
    scene = dataset.scene(played["scene"])
    frames = robot_frames(scene.path, robot, [view for view, _, _ in steps], cache_dir=args.cache_dir)
    captions = [
        f"{'start' if k == 0 else f'step {k}, {seconds:.1f} s'}: {view}, OER {oer:.2f}"
        for k, (view, seconds, oer) in enumerate(steps)
    ]
    title = (
        f"{scene.id}: the Oracle's episode {args.episode} under {robot}, fruit {played['target_fruit']}, "
        f"OER {played['oer_0']:.2f} -> {played['oer_tau']:.2f} in {played['seconds']:.1f} robot seconds"
    )
    return plot_robot_strip(
        frames, captions, title, out / f"{scene.id.replace('/', '-')}-{robot}-episode-{args.episode}.png"
    )


def run(args: argparse.Namespace) -> int:
    """Compute (or load) every scene's reach, print the table, draw the pictures."""
    from davis_ag.benchmark.splits import scene_crop
    from davis_ag.data.reader import open_dataset
    from davis_ag.errors import UserError
    from davis_ag.figures.reach_plots import plot_scene_reach
    from davis_ag.formats.outputs import claim_output
    from davis_ag.robot.definitions import load_robot
    from davis_ag.robot.obstacles import trunk_points
    from davis_ag.robot.reach import load_reach, scene_lines, view_poses
    from davis_ag.robot.summary import reach_table

    definition = load_robot(args.robot)
    dataset = open_dataset(args.dataset)
    scenes = [
        s
        for s in dataset
        if (args.scenario is None or s.scenario == args.scenario) and (args.crop is None or scene_crop(s) == args.crop)
    ]
    if not scenes:
        which = " ".join(w for w in (args.scenario, args.crop) if w)
        raise UserError(
            f"{args.dataset} has no {which + ' ' if which else ''}scene; generate one or choose another --scenario or --crop"
        )
    with claim_output(args.out, force=args.force, flag="--out", folder=True) as out:
        reaches = []
        for number, scene in enumerate(scenes, 1):

            def progress(done: int, total: int, scene_id: str = scene.id, number: int = number) -> None:
                if done == total or done % max(1, total // 10) == 0:
                    print(
                        f"\r{scene_id} ({number} of {len(scenes)}): {done} of {total} views solved",
                        end="",
                        file=sys.stderr,
                    )
                    if done == total:
                        print(file=sys.stderr)

            reach = load_reach(scene, dataset.root, definition, args.cache_dir, progress)
            reaches.append(reach)
            lines, _ = scene_lines(scene, view_poses(scene))
            picture = out / f"{scene.id.replace('/', '-')}-{definition.name}.png"
            plot_scene_reach(scene, reach, tuple(line.y for line in lines.values()), picture, trunk_points(scene))
        print(f"{definition.name} ({definition.urdf_source}) on {args.dataset}")
        print(f"{'group':<22} {'camera m':>8} {'views':>6} {'reached':>8}")
        rows = reach_table(scenes, reaches)
        for row in rows:
            print(f"{row.group:<22} {row.height:>8.2f} {row.views:>6} {row.share * 100:>7.1f}%")
        total = sum(len(r.reachable) for r in reaches)
        reached = sum(int(r.reachable.sum()) for r in reaches)
        print(f"all: {reached} of {total} views ({reached / total * 100:.1f} %); pictures in {out}")
        if args.episode is not None:
            print(f"wrote {_episode_strip(dataset, scenes[0].scenario or 'sp', definition.name, args, out)}")
    if args.doc is not None:
        from davis_ag.atomic_files import write_marked_section
        from davis_ag.robot.reach import BLOCKED

        codes = np.concatenate([r.blocked for r in reaches])
        refusals = {why: int((codes == code).sum()) for code, why in enumerate(BLOCKED) if code}
        page = [
            f"`davis-ag reach {args.dataset.name} --robot {definition.name}` ({definition.urdf_source}, definition "
            f"{definition.digest}): {reached} of {total} views reached ({reached / total * 100:.1f} %), "
            f"{sum(r.obstacle_points for r in reaches):,} trunk points as obstacles; views refused: "
            + ", ".join(f"{why} {count}" for why, count in refusals.items())
            + ".",
            "",
            "| group | camera height, m | views | reached |",
            "|---|---|---|---|",
            *(f"| {r.group} | {r.height:g} | {r.views} | {r.share * 100:.1f} % |" for r in rows),
        ]
        write_marked_section(args.doc, f"reach-{definition.name}", "\n".join(page))
        print(f"wrote the table into {args.doc}")
    return 0

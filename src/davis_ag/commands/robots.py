"""``davis-ag robots``: the robots a camera can ride on, their arm, base and lift, and the camera
heights each reaches (the share of test poses solved at each height beside an empty alley:
:func:`davis_ag.robot.summary.reach_by_height`)."""

from __future__ import annotations

import argparse

HELP = "list the robots (arm, mount, lift, speeds) and the camera heights each reaches"
DESCRIPTION = __doc__


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``robots``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument(
        "robots",
        nargs="*",
        metavar="ROBOT",
        help="robots to list: built-in names or YAML files (default: every built-in)",
    )
    parser.add_argument(
        "--doc",
        default=None,
        metavar="PAGE.md",
        help="also write the table between <!-- robots:start/end --> markers in this page (docs/robot.md)",
    )


def run(args: argparse.Namespace) -> int:
    """Print one block per robot."""
    from davis_ag.robot.definitions import builtin_robots, load_robot
    from davis_ag.robot.summary import HEIGHTS, reach_by_height

    definitions = [load_robot(name) for name in (args.robots or builtin_robots())]
    print("camera heights, m:      " + " ".join(f"{h:>4g}" for h in HEIGHTS))
    table = ["| robot | arm | mount, m | lift, m | " + " | ".join(f"{h:g} m" for h in HEIGHTS) + " |"]
    table.append("|---" * (4 + len(HEIGHTS)) + "|")
    for definition in definitions:
        shares = reach_by_height(definition)
        table.append(
            f"| {definition.name} | {definition.urdf_source} | {definition.mount_height_m:g} | "
            f"{definition.lift_m[0]:g}-{definition.lift_m[1]:g} | "
            + " | ".join(f"{shares[h] * 100:.0f} %" for h in HEIGHTS)
            + " |"
        )
        low, high = definition.lift_m
        lift = f"lift {low:g}-{high:g} m at {definition.lift_speed_m_s:g} m/s" if high > low else "no lift"
        print(
            f"{definition.name}: {definition.urdf_source}, tool {definition.tool_frame}, mount "
            f"{definition.mount_height_m:g} m, {lift}, base {definition.base_speed_m_s:g} m/s, joints at "
            f"{definition.joint_speed_scale:g} of the URDF's speeds"
        )
        print(f"  {'reached, %':<22}" + " ".join(f"{shares[h] * 100:>4.0f}" for h in HEIGHTS))
    if args.doc:
        from davis_ag.atomic_files import write_marked_section

        write_marked_section(args.doc, "robots", "\n".join(table))
        print(f"wrote the table into {args.doc}")
    return 0

"""The tables of each row crop's structure and floor in docs/crops.md, written from what the code builds.

``python -m davis_ag.figures.structure_table docs/crops.md`` fills its ``structures`` section.
"""

from __future__ import annotations

import sys
from collections import Counter
from itertools import pairwise

import numpy as np

from davis_ag.atomic_files import write_marked_section
from davis_ag.scene.cover import FLOOR_SYSTEMS, GRASS, WEED_SHARE, WEEDS, cover_spots, covered_strips
from davis_ag.scene.specs import CROPS
from davis_ag.scene.structures import ALLEY_SYSTEMS, SYSTEMS, Part, greenhouse_floor, structure_parts

#: The section's marker in docs/crops.md.
MARKER = "structures"
#: Parts that run along the row (their height is one number) and parts that stand.
RUNNING = ("wire", "string", "pipe")
STANDING = ("post", "stake")


def _heights(parts: list[Part], kinds: tuple[str, ...]) -> str:
    """The heights of the horizontal parts of these kinds on the centre row and its alleys, m."""
    heights = sorted({round(p.nodes[0][2], 2) for p in parts if p.kind in kinds and p.nodes[0][2] == p.nodes[-1][2]})
    return ", ".join(f"{h:.2f}" for h in heights) or "-"


def structure_rows() -> list[str]:
    """One Markdown table row per crop with a structure: what is built in its ``row`` scene."""
    lines = [
        "| crop | system | parts in a row scene (three rows) | supports: height, where along x | heights above the ground (m) |",
        "|---|---|---|---|---|",
    ]
    for name in SYSTEMS:
        crop = CROPS[name]
        assert crop.row is not None  # every system belongs to a row crop
        parts = structure_parts("row", crop, "default")
        counts = Counter(p.kind for p in parts)
        standing = [p for p in parts if p.kind in STANDING and p.nodes[0][1] == 0.0]
        xs = sorted({p.nodes[0][0] for p in standing})
        gaps = [b - a for a, b in pairwise(xs[1:-1])]
        every = f"every {gaps[0]:.2f} m" if gaps else f"at {', '.join(f'{x:g}' for x in xs)} m"
        support = f"{max(p.nodes[-1][2] for p in standing):.2f} m, {every}" if standing else "none (hung from the roof)"
        lines.append(
            f"| {name} | {crop.row.system} | {', '.join(f'{n} {k}s' for k, n in sorted(counts.items()))} | "
            f"{support} | wires {_heights(parts, ('wire',))}; strings {_heights(parts, ('string',))}; "
            f"pipes {_heights(parts, ('pipe',))} |"
        )
    return lines


def floor_rows() -> list[str]:
    """One Markdown table row per crop whose floor is built: the cover in an orchard's or a
    vineyard's alleys (tufts counted at seed 0: the count is the grid's, the seed moves them), the
    floor cover of a greenhouse."""
    grass = sorted({model for model, _ in GRASS})
    models = f"{' or '.join(grass)} at {', '.join(f'{age:g}' for _, age in GRASS)} days"
    weeds = ", ".join(f"{model} ({age:g} d)" for model, age in WEEDS)
    lines = [
        "| crop | floor | bare strip along each row, m | cover across each alley, m | in a row scene (four alleys) |",
        "|---|---|---|---|---|",
    ]
    for name, system in FLOOR_SYSTEMS.items():
        row = CROPS[name].row
        assert row is not None  # every floor belongs to a row crop
        low, high = covered_strips(row, system)[0]
        tufts = len(cover_spots(row, system, np.random.default_rng(0)))
        lines.append(f"| {name} | {system.name} | {system.bare_strip:.2f} | {high - low:.2f} | {tufts} tufts |")
    for name in ALLEY_SYSTEMS:
        sides = greenhouse_floor(CROPS[name])
        assert sides is not None
        lines.append(
            f"| {name} | white woven ground cover over the house's floor | - | - | "
            f"{2 * sides[0]:.1f} x {2 * sides[1]:.1f} m |"
        )
    lines += [
        "",
        f"A tuft is Helios's {models}, or one time in {round(1 / WEED_SHARE)} a weed: {weeds}.",
    ]
    return lines


def main(argv: list[str]) -> int:
    """Write the table into the page given (docs/crops.md)."""
    if len(argv) != 1:
        print("usage: python -m davis_ag.figures.structure_table docs/crops.md", file=sys.stderr)
        return 2
    write_marked_section(argv[0], MARKER, "\n".join([*structure_rows(), "", *floor_rows()]))
    return 0


if __name__ == "__main__":
    sys.exit(main(sys.argv[1:]))

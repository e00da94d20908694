"""Search for the grid convention that gives Table 3's images per scene (a tool, not shipped).

Table 3 of the paper gives scenes and images per crop and scenario; their ratio is the images
per scene, exact: SP strawberry 285, tomato 348, vine 348; MP strawberry 1,128, tomato 1,800,
vine 1,800. Table 2 gives the rules (25 / 50 cm steps, 3 / 2 altitudes, 1 / 12 headings, 3 x 3 m
and 7 x 3 m grids) and section III-C the exclusion radii (75 cm strawberry, 100 cm others).
This script counts the views each candidate convention gives and prints them beside the paper's:

- lattice: ``cells`` (cell centres), ``points`` (lattice points, both edges included) or
  ``staggered`` (points, odd rows shifted half a step along +x, as the original's Fig. 2 shows);
- exclusion: horizontal (``2d``) or 3-D to the plant's centre at ``centre_height`` (``3d``),
  inclusive (``<=``: a position at exactly r is out) or strict (``<``);
- extents: Table 2's (3 x 3 / 7 x 3 m for every crop) or per crop (``davis_ag.scene.specs``);
- MP plant spacing: ours (``specs``), or the spacings of a sweep for MP strawberry.

Run: ``python tools/grid_conventions.py`` (about a second).
"""

from __future__ import annotations

import itertools
import math

import numpy as np

from davis_ag.scene.specs import CROPS, SCENARIOS, CropSpec

#: Table 3: images / scenes, per (scenario, crop).
PAPER = {("sp", "strawberry"): 24_510 / 86, ("sp", "tomato"): 45_240 / 130, ("sp", "vine"): 63_336 / 182,
         ("mp", "strawberry"): 86_856 / 77, ("mp", "tomato"): 203_400 / 113, ("mp", "vine"): 79_200 / 44}


def positions(lattice: str, extent: tuple[float, float], step: float) -> list[tuple[float, float]]:
    """Candidate camera positions (x, y) of one lattice convention."""
    if lattice == "cells":
        nx, ny = (int(round(e / step)) for e in extent)
        offsets = (0.0, 0.0)
    else:
        nx, ny = (int(math.floor(e / step + 1e-9)) + 1 for e in extent)
        offsets = (step / 2, 0.0) if lattice == "staggered" else (0.0, 0.0)
    out = []
    for iy in range(ny):
        shift = offsets[0] if iy % 2 else 0.0
        for ix in range(nx):
            out.append(((ix - (nx - 1) / 2) * step + shift, (iy - (ny - 1) / 2) * step))
    return out


def views(scenario: str, crop: CropSpec, lattice: str, distance: str, inclusive: bool,
          extent: tuple[float, float], spacing: float) -> int:
    """Views per scene under one convention."""
    spec = SCENARIOS[scenario]
    count = 1 if scenario == "sp" else crop.mp_plants
    stems = [((i - (count - 1) / 2) * spacing, 0.0) for i in range(count)]
    total = 0
    for level in spec.altitude_levels:
        z = crop.altitudes[level]
        for x, y in positions(lattice, extent, spec.step):
            gaps = [math.hypot(x - sx, y - sy) if distance == "2d"
                    else math.dist((x, y, z), (sx, sy, crop.centre_height)) for sx, sy in stems]
            near = min(gaps)
            out = near <= crop.exclusion_radius + 1e-9 if inclusive else near < crop.exclusion_radius - 1e-9
            total += 0 if out else spec.headings
    return total


def conventions_table() -> None:
    """Every lattice x exclusion x extent convention, six counts each, against the paper's."""
    pairs = sorted(PAPER)
    print("paper:", " ".join(f"{s}-{c}={PAPER[s, c]:.0f}" for s, c in pairs))
    for lattice, distance, inclusive, extents in itertools.product(
            ("cells", "points", "staggered"), ("2d", "3d"), (True, False), ("table2", "per-crop")):
        counts = []
        for scenario, crop_name in pairs:
            crop = CROPS[crop_name]
            if extents == "table2":
                extent = SCENARIOS[scenario].extent
            else:
                extent = crop.sp_extent if scenario == "sp" else crop.mp_extent
            counts.append(views(scenario, crop, lattice, distance, inclusive, extent, crop.mp_spacing))
        hits = sum(c == round(PAPER[p]) for c, p in zip(counts, pairs))
        label = f"{lattice:9s} {distance} {'<=' if inclusive else '< '} {extents:8s}"
        print(f"{label}  {' '.join(f'{c:5d}' for c in counts)}   {hits}/6 equal the paper's")


def mp_strawberry_sweep() -> None:
    """Which staggered MP grids leave 47 positions (1,128 / 24) around five strawberry plants."""
    crop = CROPS["strawberry"]
    print("\nMP strawberry on a staggered lattice, 2-D exclusion <= 0.75 m: grids giving 1,128 views")
    found = []
    for width, depth in itertools.product(np.arange(2.0, 7.01, 0.5), np.arange(2.0, 3.01, 0.5)):
        for spacing in np.arange(0.10, 1.001, 0.05):
            if views("mp", crop, "staggered", "2d", True, (width, depth), spacing) == 1128:
                found.append((float(width), float(depth), round(float(spacing), 2)))
    by_grid: dict[tuple[float, float], list[float]] = {}
    for width, depth, spacing in found:
        by_grid.setdefault((width, depth), []).append(spacing)
    for (width, depth), spacings in sorted(by_grid.items()):
        print(f"  {width:.1f} x {depth:.1f} m: plant spacing {', '.join(f'{s:.2f}' for s in spacings)} m")
    seven = [g for g in by_grid if g[0] == 7.0]
    print(f"  7 m wide grids among them: {len(seven)}")


if __name__ == "__main__":
    conventions_table()
    mp_strawberry_sweep()

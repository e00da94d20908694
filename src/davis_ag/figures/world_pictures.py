"""A picture of an exported labelled mesh (``davis-ag export mesh``): its triangles in their own colour,
by organ class and by fruit, drawn with matplotlib from the PLY alone.

``python -m davis_ag.figures.world_pictures MESH.ply OUT.png [--margin M]`` (docs/worlds.md shows one).
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np

from davis_ag.figures.canvas import new_figure, save_figure
from davis_ag.figures.label_pictures import ORGAN_COLOURS, class_colours


def read_mesh(path: Path) -> dict[str, np.ndarray]:
    """A labelled PLY mesh: ``corners`` (n, 3, 3) and per face ``rgb``, ``organ``, ``fruit_id``, ``plant``."""
    from plyfile import PlyData

    ply = PlyData.read(str(path))
    vertex, face = ply["vertex"].data, ply["face"].data
    points = np.stack([vertex["x"], vertex["y"], vertex["z"]], axis=1)
    return {
        "corners": points[np.stack(face["vertex_indices"])],
        "rgb": np.stack([face["red"], face["green"], face["blue"]], axis=1),
        "organ": np.asarray(face["organ"]),
        "fruit_id": np.asarray(face["fruit_id"]),
        "plant": np.asarray(face["plant"]),
        "names": np.array([c.split()[2] for c in ply.comments if c.startswith("class ")]),
    }


def draw_mesh(path: Path, out_path: Path, margin: float = 0.3, elevation: float = 25.0, azimuth: float = -60.0) -> Path:
    """Three views of one mesh: its colours, its organ classes and its fruit (each fruit its own colour).

    Args:
        path: A PLY written by ``davis-ag export mesh``.
        out_path: The PNG.
        margin: Soil kept around the plants, m (the soil runs out to 30 m).
        elevation: Viewing elevation, degrees.
        azimuth: Viewing azimuth, degrees.
    """
    from matplotlib.patches import Patch
    from mpl_toolkits.mplot3d import Axes3D
    from mpl_toolkits.mplot3d.art3d import Poly3DCollection

    mesh = read_mesh(path)
    corners, organ = mesh["corners"], mesh["organ"]
    plants = mesh["plant"] >= 0
    lo, hi = corners[plants].reshape(-1, 3).min(axis=0) - margin, corners[plants].reshape(-1, 3).max(axis=0) + margin
    centroid = corners.mean(axis=1)
    keep = plants | np.all((centroid[:, :2] >= lo[:2]) & (centroid[:, :2] <= hi[:2]), axis=1)
    no_fruit = np.iinfo(mesh["fruit_id"].dtype).max
    fruit = mesh["fruit_id"][keep]
    fruit_colours = np.where(
        (fruit != no_fruit)[:, None],
        np.stack([(fruit * 97) % 200 + 55, (fruit * 57) % 200 + 55, (fruit * 31) % 200 + 55], axis=1),
        200,
    )
    panels = (
        ("own colour", mesh["rgb"][keep]),
        ("organ class", class_colours(organ[keep])),
        ("fruit id (others grey)", fruit_colours),
    )
    figure = new_figure(12.0, 4.6)
    for k, (title, colours) in enumerate(panels):
        ax = figure.add_axes((k / 3, 0.1, 1 / 3, 0.84), projection="3d")
        assert isinstance(ax, Axes3D)  # matplotlib's stubs know only 2-D axes
        ax.add_collection3d(Poly3DCollection(corners[keep], facecolors=colours / 255.0, linewidths=0))
        ax.set_xlim(lo[0], hi[0])
        ax.set_ylim(lo[1], hi[1])
        ax.set_zlim(0, max(hi[2], 0.1))
        ax.set_box_aspect((hi[0] - lo[0], hi[1] - lo[1], max(hi[2], 0.1)), zoom=1.5)
        ax.view_init(elev=elevation, azim=azimuth)
        ax.set_axis_off()
        ax.set_title(title, fontsize=10)
    present = np.unique(organ[keep])
    names = mesh["names"]
    handles = [
        Patch(
            color=ORGAN_COLOURS[v] / 255 if v < len(ORGAN_COLOURS) else "k",
            label=names[v] if v < len(names) else str(v),
        )
        for v in present
    ]
    figure.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=9, frameon=False)
    return save_figure(figure, out_path)


def main(argv: list[str] | None = None) -> int:
    """``python -m davis_ag.figures.world_pictures MESH.ply OUT.png``."""
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("mesh", type=Path)
    parser.add_argument("out", type=Path)
    parser.add_argument("--margin", type=float, default=0.3, help="soil kept around the plants, m")
    parser.add_argument("--elevation", type=float, default=25.0)
    parser.add_argument("--azimuth", type=float, default=-60.0)
    args = parser.parse_args(argv)
    print(draw_mesh(args.mesh, args.out, args.margin, args.elevation, args.azimuth))
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""Pictures of the labels beyond fruit: a view beside its organ classes, and a fused point cloud.

``python -m davis_ag.figures.label_pictures SCENE_DIR CLOUD.ply OUT_DIR [VIEW]`` writes
``OUT_DIR/organ-classes.png`` and ``OUT_DIR/point-cloud.png`` (docs/labels.md shows them).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from davis_ag.data.reader import View, open_dataset
from davis_ag.figures.canvas import new_figure, save_figure
from davis_ag.scene.organs import ORGAN_NAMES

#: One colour per organ class (sky, soil, fruit, leaf, stem, trunk, petiole, peduncle, flower,
#: structure, cover), for class images and clouds.
ORGAN_COLOURS = np.array(
    [
        [135, 190, 235],
        [120, 90, 60],
        [220, 30, 40],
        [60, 170, 60],
        [240, 200, 40],
        [110, 60, 150],
        [40, 200, 190],
        [250, 130, 30],
        [250, 250, 250],
        [235, 70, 200],
        [175, 205, 105],
    ],
    dtype=np.uint8,
)


def class_colours(classes: np.ndarray) -> np.ndarray:
    """An RGB picture of a class image (values past the table black)."""
    table = np.vstack([ORGAN_COLOURS, np.zeros((256 - len(ORGAN_COLOURS), 3), np.uint8)])
    return table[classes]


def draw_organ_classes(view: View, out_path: Path) -> Path:
    """The view's colour image beside its organ classes, with the class legend."""
    from matplotlib.patches import Patch

    image, classes = view.image(), view.classes()
    if classes is None:
        raise SystemExit(f"{view.class_path}: missing; generate the scene with this version")
    height, width = classes.shape
    figure = new_figure(2 * 5.0, 5.0 * height / width + 0.7)
    for k, (picture, title) in enumerate(
        ((image, f"{view.scene.id} {view.name}"), (class_colours(classes), "organ classes"))
    ):
        ax = figure.add_axes((k * 0.5 + 0.005, 0.12, 0.49, 0.82))
        ax.imshow(picture, interpolation="nearest")
        ax.set_title(title, fontsize=9)
        ax.set_axis_off()
    counts = np.bincount(classes.ravel(), minlength=len(ORGAN_NAMES))
    handles = [
        Patch(color=ORGAN_COLOURS[v] / 255, label=f"{v} {name} ({counts[v] / classes.size:.1%})")
        for v, name in enumerate(ORGAN_NAMES)
    ]
    figure.legend(handles=handles, loc="lower center", ncol=len(handles), fontsize=8, frameon=False)
    return save_figure(figure, out_path)


def draw_point_cloud(points: np.ndarray, out_path: Path, radius: float = 0.4, title: str = "") -> Path:
    """A fused cloud seen from two sides: true colour and organ class, within ``radius`` m of the
    plant (the soil thinned so the plant shows).

    Args:
        points: :data:`davis_ag.data.point_cloud.POINT_DTYPE` points.
        out_path: The PNG.
        radius: Horizontal distance from the plants' centre kept, m.
        title: Shown above.
    """
    from mpl_toolkits.mplot3d.axes3d import Axes3D

    xyz = np.stack([points["x"], points["y"], points["z"]], axis=1).astype(np.float64)
    plant = points["organ"] > 1
    centre = np.median(xyz[plant, :2], axis=0) if plant.any() else np.zeros(2)
    near = np.linalg.norm(xyz[:, :2] - centre, axis=1) <= radius
    soil_every = np.zeros(len(points), bool)
    soil_every[::3] = True
    keep = near & (plant | soil_every)
    xyz, kept = xyz[keep], points[keep]
    rgb = np.stack([kept["red"], kept["green"], kept["blue"]], axis=1) / 255.0
    organ = class_colours(kept["organ"]) / 255.0
    figure = new_figure(12.0, 5.6)
    top = float(xyz[:, 2].max()) if len(xyz) else 1.0
    for k, (colours, label) in enumerate(((rgb, "colour"), (organ, "organ class"))):
        ax = figure.add_axes((k * 0.5, 0.0, 0.5, 0.9), projection="3d")
        assert isinstance(ax, Axes3D)  # matplotlib's stubs know only 2-D axes
        ax.scatter(xyz[:, 0], xyz[:, 1], xyz[:, 2], c=colours, s=1.0, linewidths=0, depthshade=False)
        ax.view_init(elev=20, azim=-60)
        ax.set_xlim(centre[0] - radius, centre[0] + radius)
        ax.set_ylim(centre[1] - radius, centre[1] + radius)
        ax.set_zlim(0.0, top)
        ax.set_box_aspect((2 * radius, 2 * radius, top), zoom=1.0)
        ax.set_xlabel("x (m)", fontsize=8)
        ax.set_ylabel("y (m)", fontsize=8)
        ax.set_zlabel("z (m)", fontsize=8)
        ax.tick_params(labelsize=7)
        ax.set_title(label, fontsize=10, y=0.98)
    figure.suptitle(title or f"{len(points):,} points fused; {int(keep.sum()):,} shown", fontsize=10)
    return save_figure(figure, out_path)


def main(argv: list[str] | None = None) -> int:
    """Write the two pictures (see the module docstring)."""
    from davis_ag.data.point_cloud import read_ply

    args = sys.argv[1:] if argv is None else argv
    scene_dir, cloud, out = Path(args[0]), Path(args[1]), Path(args[2])
    scene = open_dataset(scene_dir).scenes[0]
    view = scene.view(args[3]) if len(args) > 3 else next(v for v in scene if v.boxes)
    draw_organ_classes(view, out / "organ-classes.png")
    points = read_ply(cloud)
    draw_point_cloud(
        points,
        out / "point-cloud.png",
        title=f"{scene.id}: {len(points):,} points fused from {len(scene)} views (plyfile)",
    )
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

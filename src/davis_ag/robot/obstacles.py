"""What a robot must not touch in a generated scene: its woody organs and the growers' structures,
seen by its own views.

The obstacles are the scene's points of organ class ``trunk`` (trunks, scaffolds, cordons and
canes; docs/labels.md) and ``structure`` (trellis posts and wires, stakes, twine, strings and
heating pipes: :mod:`davis_ag.scene.structures`), unprojected from the views' depth and class images and thinned to one
point per 3 cm voxel: the surfaces the grid's cameras saw, which are the surfaces an arm coming
from the same alleys meets. Leaves, flowers, fruit and green stems are left out on purpose: the
arm may brush them, as foliage is treated as permeable in the lime-picking work (arXiv
2108.13889). The ground is the robot model's own half-space.

To bound the time on a 1,536-view row, at most :data:`MAX_VIEWS` views are read, spread evenly
over the scene's views (every altitude and heading appears, as the views are numbered altitude
first, heading last).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from davis_ag.data.point_cloud import DEPTH_SATURATED_M, Pinhole, unproject
from davis_ag.errors import UserError
from davis_ag.scene.organs import STRUCTURE, TRUNK

#: The organ classes a robot must not touch.
OBSTACLE_CLASSES = (TRUNK, STRUCTURE)

if TYPE_CHECKING:
    from davis_ag.data.reader import Scene

#: Views read for the obstacles, at most; voxel side of the thinned cloud, m; farthest depth used, m.
MAX_VIEWS = 240
VOXEL = 0.03
MAX_DEPTH = 6.0


def trunk_points(scene: Scene) -> np.ndarray:
    """The scene's woody surfaces and structures (:data:`OBSTACLE_CLASSES`) as ``(n, 3)`` world
    points, one per 3 cm voxel.

    Args:
        scene: A generated scene with depth and class images.

    Returns:
        The points (possibly none: a strawberry has no trunk).

    Raises:
        UserError: when the scene has no depth or class images to find its trunks in.
    """
    pinhole = Pinhole.of_scene(scene)
    views = list(scene)
    chosen = (
        views if len(views) <= MAX_VIEWS else [views[i] for i in np.linspace(0, len(views) - 1, MAX_VIEWS).astype(int)]
    )
    parts = []
    for view in chosen:
        depth, classes = view.depth(), view.classes()
        if depth is None or classes is None or view.pose is None:
            raise UserError(
                f"{scene.path}: {view.name} has no depth or class image, so its trunks cannot be found; "
                "the robot needs a scene generated with depth (without --no-depth)"
            )
        keep = np.isin(classes, OBSTACLE_CLASSES) & (depth > 0) & (depth < min(DEPTH_SATURATED_M, MAX_DEPTH))
        if keep.any():
            parts.append(unproject(depth, pinhole, view.pose)[keep])
    if not parts:
        return np.empty((0, 3))
    points = np.concatenate(parts)
    cells = np.unique(np.floor(points / VOXEL).astype(np.int64), axis=0)
    return (cells + 0.5) * VOXEL

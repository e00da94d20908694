"""How ``davis-ag bench`` times a view: the generate path's seconds per view, and any loop's.

Shared by the renderer bench (:mod:`davis_ag.workflows.bench.run`) and the crops bench
(:mod:`davis_ag.workflows.bench.crops`).
"""

from __future__ import annotations

import time
from collections.abc import Callable, Sequence
from pathlib import Path

from davis_ag.generate.one_scene import SceneRequest, draw_scene
from davis_ag.scene.view_grid import Viewpoint


def time_loop(views: Sequence[Viewpoint], step: Callable[[Viewpoint], object]) -> float:
    """Run ``step`` on every view; seconds per view of all but the first."""
    step(views[0])
    start = time.perf_counter()
    for view in views[1:]:
        step(view)
    return (time.perf_counter() - start) / (len(views) - 1)


def time_ours(request: SceneRequest, model, grid, views: list, root: Path) -> tuple[float, float]:
    """The generate path on the chosen views: seconds per view (views 2..n, publishing included)
    and the seconds before the first view was done (renderer set-up and the first view)."""
    marks: dict[str, float] = {}

    def on_view(done: int, total: int) -> None:
        if done == 1:
            marks["first"] = time.perf_counter()

    start = time.perf_counter()
    draw_scene(request, model, grid, root, on_view, views=views)
    end = time.perf_counter()
    return (end - marks["first"]) / (len(views) - 1), marks["first"] - start

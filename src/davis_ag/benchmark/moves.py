"""How often the environment refuses a move from an episode's start (section V-D's rule).

A move is refused, and the agent stays where it is, when it leads off the grid or too close to a
plant (no pointer), or to a view where the target fruit has no box. Measured over every eligible
start (each view and target with OER below 0.4 and enough visible pixels) and every move of the
scenario, this share says how much room the plants leave a policy to act in.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np

from davis_ag.benchmark.cache import SceneCache
from davis_ag.benchmark.starts import min_pixels as start_pixels
from davis_ag.benchmark.tvm import MAX_START_OER
from davis_ag.scene.specs import ALL_ACTIONS, scenario_spec

if TYPE_CHECKING:
    from davis_ag.data.reader import Scene


@dataclass(frozen=True)
class RefusedMoves:
    """Moves tried from every eligible start, and how many the environment refuses.

    Attributes:
        starts: Eligible (view, target) starts.
        moves: Moves tried: starts x the scenario's moves (``done`` excluded).
        no_view: Moves refused because no view lies there (off the grid or too close to a plant).
        target_lost: Moves refused because the target has no box in the view they reach.
    """

    starts: int
    moves: int
    no_view: int
    target_lost: int

    @property
    def share(self) -> float:
        """Share of moves refused, either way (NaN without starts)."""
        return (self.no_view + self.target_lost) / self.moves if self.moves else float("nan")


def refused_moves(
    cache: SceneCache, actions: tuple[str, ...], min_pixels: float, max_start_oer: float = MAX_START_OER
) -> RefusedMoves:
    """Count the refused moves from one scene's eligible starts.

    Args:
        cache: The scene's tables.
        actions: The scenario's moves (pointer keys).
        min_pixels: Visible pixels a start target needs.
        max_start_oer: A start target's OER must be below this.

    Returns:
        The counts.
    """
    rows = np.flatnonzero((cache.box_oer < max_start_oer) & (cache.box_pixels >= min_pixels))
    columns = [ALL_ACTIONS.index(a) for a in actions]
    nxt = cache.pointers[cache.box_view[rows]][:, columns]  # (starts, moves)
    fruit = cache.box_fruit[rows][:, None]
    kept = cache.box_index[np.maximum(nxt, 0), np.broadcast_to(fruit, nxt.shape)] >= 0
    no_view = int((nxt < 0).sum())
    target_lost = int(((nxt >= 0) & ~kept).sum())
    return RefusedMoves(len(rows), int(nxt.size), no_view, target_lost)


def refused_moves_of_scenes(scenes: Sequence[Scene], caches: list[SceneCache], scenario: str) -> RefusedMoves:
    """:func:`refused_moves` summed over scenes of one scenario (the environment's own threshold)."""
    actions = tuple(scenario_spec(scenario).actions)
    parts = [refused_moves(cache, actions, start_pixels(scene, cache)) for scene, cache in zip(scenes, caches)]
    return RefusedMoves(
        *(sum(getattr(p, name) for p in parts) for name in ("starts", "moves", "no_view", "target_lost"))
    )

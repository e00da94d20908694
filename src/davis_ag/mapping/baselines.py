"""Row mapping's baselines: the fixed sweep, Rand and the greedy planner that knows the labels.

- **Sweep**: the classic coverage path, knowing the grid but no label. From the start it heads for
  the alley line nearest the row, turned to face the row, drives that line to the far end at the
  start's camera height, changes height and drives back, and so on through every height; each leg
  begins at the end nearest the start. Each step is the first move of a shortest path (fewest
  moves) to the next view of the path not yet visited.
- **Rand**: a uniformly random move each step.
- **Greedy**: each step the move whose view sees the most fruit not yet seen, read from the labels:
  the next-best-view planners' information gain with perfect perception. Where no move sees
  anything new, it heads along a shortest path for the nearest view that does (most new fruit
  breaking ties), so it never stalls while something is left to see.

None looks at the image; each reads the environment's tables in ``prepare``, as the grid's Oracle does.
"""

from __future__ import annotations

from typing import Any

import numpy as np
from scipy.sparse import csr_matrix
from scipy.sparse.csgraph import shortest_path

from davis_ag.benchmark.policies import Policy, SeededPolicy, baselines_by_name, unwrapped
from davis_ag.environments import MAPPING_ID
from davis_ag.mapping.env import RowMappingEnv, grid_places


def mapping_env(env: Any) -> RowMappingEnv:
    """The :class:`RowMappingEnv` under any wrappers.

    Raises:
        UserError: when ``env`` is another environment.
    """
    return unwrapped(env, RowMappingEnv, MAPPING_ID)


class _Paths:
    """Shortest paths (in moves) over one scene's move graph, computed on demand and kept."""

    def __init__(self, next_views: np.ndarray) -> None:
        self.next_views = next_views
        n, moves = next_views.shape
        rows = np.repeat(np.arange(n), moves)
        graph = csr_matrix((np.ones(n * moves), (rows, next_views.ravel())), shape=(n, n))
        graph.setdiag(0)
        graph.eliminate_zeros()
        self.graph, self.reverse = graph, graph.T.tocsr()
        self._from: dict[int, np.ndarray] = {}
        self._to: dict[int, np.ndarray] = {}

    def distances(self, view: int) -> np.ndarray:
        """Moves from ``view`` to every view (inf where none leads)."""
        if view not in self._from:
            self._from[view] = shortest_path(self.graph, directed=True, unweighted=True, indices=view)
        return self._from[view]

    def distances_to(self, target: int) -> np.ndarray:
        """Moves from every view to ``target`` (inf where none leads)."""
        if target not in self._to:
            self._to[target] = shortest_path(self.reverse, directed=True, unweighted=True, indices=target)
        return self._to[target]

    def step_towards(self, view: int, target: int) -> int | None:
        """The first move (lowest index) of a shortest path from ``view`` to ``target``; None when
        the target cannot be reached or is here."""
        to_target = self.distances_to(target)
        here = to_target[view]
        if not np.isfinite(here) or here == 0:
            return None
        closer = np.flatnonzero(to_target[self.next_views[view]] == here - 1)
        return int(closer[0]) if len(closer) else None


class _TablePolicy:
    """A baseline that reads the environment's tables: it keeps the environment and one
    :class:`_Paths` per scene."""

    name = ""

    def prepare(self, env: Any) -> None:
        """Keep the environment (under its wrappers) and its move graphs."""
        self.env = mapping_env(env)
        self.paths = [_Paths(table) for table in self.env.next_views]

    def reset(self, seed: int | None = None) -> None:
        """Nothing random."""

    def first_free_move(self, scene: int, view: int) -> int:
        """The first move that is not refused (0 where every move is)."""
        free = np.flatnonzero(self.env.next_views[scene][view] != view)
        return int(free[0]) if len(free) else 0


class Sweep(_TablePolicy):
    """The fixed sweep (see the module docstring)."""

    name = "Sweep"

    def prepare(self, env: Any) -> None:
        """Read each scene's grid: nominal positions, heights and how much each view faces the row."""
        super().prepare(env)
        self._grid = []
        for scene, cache in zip(self.env.scenes, self.env.caches):
            xy, grid = grid_places(scene, cache.view_names)
            yaw = np.radians([(scene.views[name].pose or (0, 0, 0, 0))[3] for name in cache.view_names])
            # Facing the row's centre line (y = 0): the heading's share along -y for a camera at y.
            facing = -np.sin(yaw) * np.sign(np.where(xy[:, 1] == 0, 1.0, xy[:, 1]))
            self._grid.append((grid, xy, facing))
        self._plan: list[int] = []

    def reset(self, seed: int | None = None) -> None:
        """Forget the last episode's path."""
        self._plan = []

    def _path(self, scene: int, start: int) -> list[int]:
        """The sweep's views from ``start`` (see the module docstring)."""
        grid, xy, facing = self._grid[scene]
        part = self.env.coverage[scene].part
        mine = np.flatnonzero(part == part[start])
        nearest = np.min(np.abs(np.round(xy[mine, 1], 3)))
        line = mine[np.abs(np.round(xy[mine, 1], 3)) == nearest]
        # One view per (column, height) of the line: the heading that faces the row most.
        best: dict[tuple[float, int], int] = {}
        for v in line[np.argsort(-facing[line], kind="stable")]:
            best.setdefault((round(float(xy[v, 0]), 3), int(grid[v, 2])), int(v))
        levels = sorted({level for _, level in best}, key=lambda level: (abs(level - grid[start, 2]), level))
        xs = sorted({x for x, _ in best})
        ascending = abs(xs[0] - xy[start, 0]) <= abs(xs[-1] - xy[start, 0])
        path = []
        for level in levels:
            row = [best[(x, level)] for x in (xs if ascending else xs[::-1]) if (x, level) in best]
            path += row
            ascending = not ascending
        return path

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> int:
        """The first move towards the next view of the sweep not yet visited."""
        scene, view = self.env.scene_index, self.env.current_view
        if not self._plan and info.get("steps", 0) == 0:
            self._plan = self._path(scene, view)
        while self._plan:
            move = self.paths[scene].step_towards(view, self._plan[0])
            if move is not None:
                return move
            self._plan.pop(0)  # here already, or out of reach
        return self.first_free_move(scene, view)


class Greedy(_TablePolicy):
    """The greedy planner with the labels (see the module docstring)."""

    name = "Greedy"

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> int:
        """The move that sees the most new fruit, else the way to the nearest view that sees some."""
        scene, view = self.env.scene_index, self.env.current_view
        seen = self.env.coverage[scene].seen
        unseen = ~self.env.seen_mask
        following = self.env.next_views[scene][view]
        gains = seen[following][:, unseen].sum(axis=1)
        if gains.max() > 0:
            return int(np.argmax(gains))
        worth = seen[:, unseen].sum(axis=1)
        distance = self.paths[scene].distances(view)
        candidates = np.flatnonzero((worth > 0) & np.isfinite(distance))
        if len(candidates):
            # Nearest first, then most new fruit, then the lowest view index.
            target = int(candidates[np.lexsort((candidates, -worth[candidates], distance[candidates]))[0]])
            move = self.paths[scene].step_towards(view, target)
            if move is not None:
                return move
        return self.first_free_move(scene, view)


class FixedMove:
    """The same move every step: a trivial policy, what a learner that collapsed to one move plays."""

    def __init__(self, move: str, name: str | None = None) -> None:
        """Args:
        move: The move's name (``forward`` ...).
        name: The row's name (default ``always <move>``).
        """
        self.move, self.name = move, name or f"always {move}"
        self.source = f"always {move}"

    def reset(self, seed: int | None = None) -> None:
        """Nothing random."""

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> str:
        """The move, by name."""
        return self.move


class RandMapping(SeededPolicy):
    """A uniformly random move each step."""

    name = "Rand"

    def prepare(self, env: Any) -> None:
        """Read how many moves the environment has."""
        self._moves = len(mapping_env(env).action_names)

    def act(self, observation: np.ndarray, info: dict[str, Any]) -> int:
        """One move, drawn uniformly."""
        return int(self._rng.integers(self._moves))


#: Row mapping's baselines by name, in the order tables list them.
BASELINES = {"Sweep": Sweep, "Rand": RandMapping, "Greedy": Greedy}


def build_baselines(names: list[str]) -> list[Policy]:
    """The baselines named (any case).

    Raises:
        UserError: for an unknown name.
    """
    return baselines_by_name(names, BASELINES, "mapping ")

"""Row mapping (``davis_ag/RowMapping-v0``): see every fruit of a row segment within a motion budget.

An episode:

- ``reset`` draws, from ``self.np_random`` only, a start: a scene of the split, then a view of it,
  each uniformly (with a robot, only views it reaches). The fruit the start view sees count as seen
  (``coverage_0``) and earn nothing.
- Actions: the scenario's moves in :data:`davis_ag.scene.specs` order (a row: forward, backward,
  left, right, up, down, rotate_cw, rotate_ccw); there is no ``done``: the budget ends an episode.
  A move with no view there (off the grid, into the row, or a view the robot does not reach) leaves
  the camera where it is and still costs a step.
- Reward: the fruit a step's view sees for the first time, as a share of the segment's fruit
  (:mod:`davis_ag.mapping.coverage`), so an episode's return is its coverage gain.
- The episode ends (``terminated=True``) after ``budget`` moves: by default the fixed sweep's
  length, :func:`sweep_budget`, the moves that drive the row once at each camera height. With a
  robot and ``budget_s``, it also ends when the next move would overrun the robot's seconds (that
  move is not made). ``truncated`` is always False.
- Observation ``(224, 224, 4)`` uint8: the view (RGB, as TVM-v0's) and, as a fourth channel, the
  memory a learner needs: a plan view of the grid (x across, y down) in which every camera position
  visited is 96 at its camera height's band, the current one 255, and every fruit seen so far a
  192 dot at its centre (fruit of the row lie between the alleys, where no camera stands).
- ``info``: ``seen`` (the ids of the segment's fruit seen so far, sorted), ``coverage`` (their
  share of the segment's fruit), ``new`` (fruit first seen this step), ``refused`` (whether the
  move was refused), ``fruit`` (the segment's fruit), ``scene``, ``path`` (view names, the start
  then one per step), ``steps``; with a robot ``robot`` as TVM-v0's.
"""

from __future__ import annotations

import copy
import os
from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from davis_ag.benchmark.cache import OBS_SIZE, SceneCache, load_scene_cache
from davis_ag.benchmark.episode_rules import discrete_action, named_action
from davis_ag.benchmark.robot_moves import RobotOnGrid, attach_robot, no_reachable_start
from davis_ag.benchmark.splits import as_dataset, select_scenes
from davis_ag.environments import MAPPING_ID
from davis_ag.errors import UserError
from davis_ag.mapping.coverage import SEEN_FRACTION, SegmentCoverage, segment_coverage
from davis_ag.scene.specs import ALL_ACTIONS, scenario_spec

if TYPE_CHECKING:
    from davis_ag.data.reader import Dataset, Scene

#: The memory channel's values: a camera position visited, the current one, a fruit seen.
VISITED, CURRENT, FRUIT_SEEN = 96, 255, 192


def sweep_budget(scene: Scene) -> int:
    """The moves the fixed sweep takes to drive one alley line once at each camera height: the
    line's positions less one per height, and one move up (or down) between heights."""
    metadata = scene.metadata
    grid = metadata.grid if metadata is not None else None
    if grid is None or not grid.extent_m or not grid.step_m or not grid.altitudes_m:
        raise UserError(f"scene {scene.id}'s scene.json records no grid: mapping needs scenes davis-ag generate wrote")
    columns = round(float(grid.extent_m[0]) / float(grid.step_m)) + 1
    levels = len(grid.altitudes_m)
    return (columns - 1) * levels + (levels - 1)


def grid_places(scene: Scene, view_names: tuple[str, ...]) -> tuple[np.ndarray, np.ndarray]:
    """Each view's nominal camera position (x, y before slip) and grid place (column, row, altitude
    level, heading), from scene.json.

    Raises:
        UserError: when scene.json does not record them (only scenes davis-ag generate wrote do).
    """
    places = scene.metadata.views if scene.metadata is not None else None
    try:
        if places is None:
            raise KeyError("views")
        xy = np.array([(places[name].nominal or [])[:2] for name in view_names], dtype=np.float64)
        grid = np.array([places[name].grid for name in view_names], dtype=np.int64)
        xy, grid = xy.reshape(len(view_names), 2), grid.reshape(len(view_names), 4)
    except (KeyError, TypeError, IndexError, ValueError):
        raise UserError(
            f"scene {scene.id}'s scene.json lacks its views' grid places: mapping needs scenes davis-ag generate wrote"
        ) from None
    return xy, grid


class _PlanView:
    """Where each view's camera and each fruit lie in the memory channel's plan view of one scene."""

    def __init__(self, scene: Scene, cache: SceneCache, coverage: SegmentCoverage) -> None:
        xy, grid = grid_places(scene, cache.view_names)
        level = grid[:, 2]
        xs, ys = np.unique(np.round(xy[:, 0], 3)), np.unique(np.round(xy[:, 1], 3))
        dx = float(np.min(np.diff(xs))) if len(xs) > 1 else 1.0
        dy = float(np.min(np.diff(ys))) if len(ys) > 1 else 1.0
        lo = np.array([xs[0] - dx / 2, ys[0] - dy / 2])
        span = np.array([xs[-1] - xs[0] + dx, ys[-1] - ys[0] + dy])
        scale = OBS_SIZE / span
        band = dy * scale[1] / (int(level.max()) + 1)
        x0 = np.floor((xy[:, 0] - dx / 2 - lo[0]) * scale[0])
        y0 = np.floor((xy[:, 1] - dy / 2 - lo[1]) * scale[1] + level * band)
        x1, y1 = x0 + max(dx * scale[0], 1.0), y0 + max(band, 1.0)
        clip = lambda a: np.clip(a, 0, OBS_SIZE).astype(np.int32)  # noqa: E731 - local one-liner
        #: Per view: the rows and columns of its cell, as [y0, y1, x0, x1).
        self.cells = np.stack([clip(y0), clip(y1), clip(x0), clip(x1)], axis=1)
        pixel = np.floor((coverage.fruit_xyz[:, :2] - lo) * scale)
        #: Per fruit: its dot's row and column.
        self.dots = np.clip(np.nan_to_num(pixel[:, ::-1], nan=0), 0, OBS_SIZE - 2).astype(np.int32)


class RowMappingEnv(gym.Env[np.ndarray, np.int64]):
    """Row mapping; see the module docstring for the rules."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 2}  # noqa: RUF012 - Gymnasium declares it an instance attribute

    def __init__(
        self,
        dataset: Dataset | str | os.PathLike[str],
        scenario: str = "row",
        split: str = "test",
        crop: str | None = None,
        cache_dir: str | os.PathLike[str] | None = None,
        budget: int | None = None,
        seen_fraction: float = SEEN_FRACTION,
        render_mode: str | None = None,
        robot: str | None = None,
        budget_s: float | None = None,
    ) -> None:
        """Open the scenes of one scenario and split, building their caches if needed.

        Args:
            dataset: A dataset root or an opened ``davis_ag.data.reader.Dataset``.
            scenario: ``row`` (default) or ``mp``; ``sp`` works too (one plant is its segment).
            split: ``train``, ``test`` or ``all``.
            crop: Keep one crop only.
            cache_dir: Base folder of the observation caches.
            budget: Moves per episode (default :func:`sweep_budget` of the split's scenes, the largest).
            seen_fraction: The visible fraction a sighting needs (:data:`SEEN_FRACTION`).
            render_mode: ``None`` or ``"rgb_array"``.
            robot: A robot (``davis-ag robots``, or a YAML file): moves only between views it
                reaches, each costing its seconds.
            budget_s: With a robot, also end an episode when its seconds are spent.

        Raises:
            UserError: for a bad split, a scene without scene.json, a budget below 1, or no start.
        """
        spec = scenario_spec(scenario)
        if render_mode not in (None, "rgb_array"):
            raise UserError(f"unknown render_mode {render_mode!r}: use None or 'rgb_array'")
        if budget_s is not None and (robot is None or not budget_s > 0):
            raise UserError(f"budget_s={budget_s} needs a robot and a positive number of seconds")
        self.render_mode = render_mode
        self.dataset = as_dataset(dataset)
        self.scenario, self.split, self.budget_s = spec.name, split, budget_s
        self.action_names: tuple[str, ...] = tuple(spec.actions)
        self._columns = [ALL_ACTIONS.index(a) for a in spec.actions]
        self.action_space = spaces.Discrete(len(self.action_names))
        self.observation_space = spaces.Box(0, 255, (OBS_SIZE, OBS_SIZE, 4), dtype=np.uint8)
        self.scenes = select_scenes(self.dataset, spec.name, split, crop)
        self.caches: list[SceneCache] = [load_scene_cache(s, self.dataset.root, cache_dir) for s in self.scenes]
        self.robot: RobotOnGrid | None = None
        if robot is not None:
            self.robot, self.caches = attach_robot(robot, self.scenes, self.caches, self.dataset.root, cache_dir)
        moves = [cache.pointers[:, self._columns] for cache in self.caches]
        self.coverage = [
            segment_coverage(scene, cache, table, seen_fraction)
            for scene, cache, table in zip(self.scenes, self.caches, moves)
        ]
        self.seen_fraction = float(seen_fraction)
        self.budget = int(budget if budget is not None else max(sweep_budget(s) for s in self.scenes))
        if self.budget < 1:
            raise UserError(f"budget must be at least 1 move, got {self.budget}")
        #: Per scene, the view each move leads to, refused moves staying put: ``(n_views, n_moves)``.
        self.next_views = [np.where(t >= 0, t, np.arange(len(t))[:, None]).astype(np.int32) for t in moves]
        self._plans = [_PlanView(s, c, v) for s, c, v in zip(self.scenes, self.caches, self.coverage)]
        #: Per scene, the views an episode may start from (every view; with a robot, those it reaches).
        self.start_views = [
            np.flatnonzero(self.robot.reaches[i].reachable) if self.robot is not None else np.arange(c.n_views)
            for i, c in enumerate(self.caches)
        ]
        playable = [
            i for i, (views, cov) in enumerate(zip(self.start_views, self.coverage)) if len(views) and cov.fruit
        ]
        if not playable and self.robot is not None:
            raise no_reachable_start(self.robot, self.scenes, split, self.dataset.root)
        if not playable:
            raise UserError(
                f"no scene of the {split} split of {self.dataset.root} has fruit on its row segment: "
                "use another split or dataset"
            )
        self._playable = np.array(playable, dtype=np.int64)
        self._scene = self._view = self._t = -1
        self._seen = np.zeros(0, dtype=bool)
        self._seen_ids: list[int] = []
        self._map = np.zeros((OBS_SIZE, OBS_SIZE, 4), dtype=np.uint8)
        self._path: list[str] = []
        self._new, self._refused, self._over = 0, False, True
        self._seconds = self._move_seconds = 0.0

    # ----------------------------------------------------------------------------- episode

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode.

        Args:
            seed: Reseeds ``self.np_random``, the only source of randomness.
            options: ``{"start": (scene_id, view_name)}`` forces a start.

        Returns:
            The first observation and the info dict.
        """
        super().reset(seed=seed)
        if options and "start" in options:
            self._scene, self._view = self._forced_start(*options["start"])
        else:
            self._scene = int(self._playable[int(self.np_random.integers(len(self._playable)))])
            views = self.start_views[self._scene]
            self._view = int(views[int(self.np_random.integers(len(views)))])
        self._t, self._over, self._refused = 0, False, False
        self._seconds = self._move_seconds = 0.0
        self._seen = self.coverage[self._scene].seen[self._view].copy()
        self._seen_ids = self.coverage[self._scene].fruit_ids[self._seen].tolist()
        self._new = 0
        self._path = [self.caches[self._scene].view_names[self._view]]
        self._map[...] = 0
        plan = self._plans[self._scene]
        self._draw_cell(self._view, CURRENT)
        for r, c in plan.dots[self._seen]:
            self._map[r : r + 2, c : c + 2, 3] = FRUIT_SEEN
        return self._observation(), self._info()

    def _forced_start(self, scene_id: str, view_name: str) -> tuple[int, int]:
        ids = [s.id for s in self.scenes]
        if scene_id not in ids:
            raise UserError(f"start scene {scene_id!r} is not in the {self.split} split")
        cache = self.caches[ids.index(scene_id)]
        if view_name not in cache.view_names:
            raise UserError(f"start view {view_name!r} is not in scene {scene_id}")
        return ids.index(scene_id), cache.view_names.index(view_name)

    def fork(self) -> RowMappingEnv:
        """An environment over the same scenes and tables (shared, read only) with an episode and
        a random generator of its own."""
        twin = copy.copy(self)
        twin._np_random = None
        twin._map = np.zeros_like(self._map)
        twin._scene = twin._view = twin._t = -1
        twin._path, twin._over = [], True
        return twin

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Make one move.

        Args:
            action: An integer index into :attr:`action_names`.

        Returns:
            ``(observation, reward, terminated, truncated, info)``.

        Raises:
            UserError: for an action outside the action space, or a step after the end.
        """
        a = self._action_index(action)
        if self._over:
            raise UserError("the episode is over (or never started): call reset() first")
        self._t += 1
        view = int(self.next_views[self._scene][self._view, a])
        self._refused = view == self._view
        over_budget = False
        self._move_seconds = 0.0
        if self.robot is not None and not self._refused:
            self._move_seconds = self.robot.seconds(self._scene, self._view, self._columns[a])
            if self.budget_s is not None and self._seconds + self._move_seconds > self.budget_s:
                over_budget, view, self._move_seconds = True, self._view, 0.0
        self._seconds += self._move_seconds
        if view != self._view:
            self._draw_cell(self._view, VISITED)
            self._draw_cell(view, CURRENT)
        self._view = view
        self._path.append(self.caches[self._scene].view_names[view])
        coverage = self.coverage[self._scene]
        fresh = coverage.seen[view] & ~self._seen
        self._new = int(fresh.sum())
        if self._new:
            self._seen |= fresh
            self._seen_ids = sorted(self._seen_ids + coverage.fruit_ids[fresh].tolist())
            for r, c in self._plans[self._scene].dots[fresh]:
                self._map[r : r + 2, c : c + 2, 3] = FRUIT_SEEN
        terminated = self._t >= self.budget or over_budget
        self._over = terminated
        return self._observation(), self._new / coverage.fruit, terminated, False, self._info()

    def _draw_cell(self, view: int, value: int) -> None:
        y0, y1, x0, x1 = self._plans[self._scene].cells[view]
        cell = self._map[y0:y1, x0:x1, 3]
        if value == CURRENT:
            cell[...] = CURRENT
        else:  # leaving: the current mark becomes visited, dots drawn since stay
            cell[cell == CURRENT] = value

    def _action_index(self, action: Any) -> int:
        return discrete_action(action, self.action_names)

    def action_masks(self) -> np.ndarray:
        """Which moves are not refused from here (sb3-contrib's MaskablePPO convention)."""
        return self.next_views[self._scene][self._view] != self._view

    def action_for(self, name: str) -> int:
        """The index of the move called ``name``.

        Raises:
            UserError: for a name that is not a move of this scenario.
        """
        return named_action(name, self.action_names, "this environment")

    # ----------------------------------------------------------------------------- state

    @property
    def scene_index(self) -> int:
        """Index of the current episode's scene in :attr:`scenes`."""
        return self._scene

    @property
    def current_view(self) -> int:
        """Index of the current view in the scene's cache."""
        return self._view

    @property
    def seen_mask(self) -> np.ndarray:
        """Which of the scene's segment fruit the episode has seen (read only)."""
        view = self._seen.view()
        view.flags.writeable = False
        return view

    @property
    def coverage_now(self) -> float:
        """The episode's coverage so far."""
        return len(self._seen_ids) / self.coverage[self._scene].fruit

    def describe(self) -> dict[str, Any]:
        """What a results file's protocol records of this environment."""
        return {
            "environment": MAPPING_ID,
            "scenario": self.scenario,
            "split": self.split,
            "budget": self.budget,
            "budget_s": self.budget_s,
            "seen_fraction": self.seen_fraction,
            "scenes": [s.id for s in self.scenes],
            "dataset": str(self.dataset.root),
            "actions": list(self.action_names),
            "robot": self.robot.record() if self.robot is not None else None,
        }

    def _observation(self) -> np.ndarray:
        # The cache's fourth channel is zeros and the memory's first three are: one add joins them.
        return np.add(self.caches[self._scene].images[self._view], self._map)

    def _info(self) -> dict[str, Any]:
        coverage = self.coverage[self._scene]
        info: dict[str, Any] = {
            "seen": list(self._seen_ids),
            "coverage": len(self._seen_ids) / coverage.fruit,
            "new": self._new,
            "refused": self._refused,
            "fruit": coverage.fruit,
            "scene": self.scenes[self._scene].id,
            "path": list(self._path),
            "steps": self._t,
        }
        if self.robot is not None:
            info["robot"] = self.robot.info(self._scene, self._view, self._move_seconds, self._seconds)
        return info

    def render(self) -> np.ndarray | None:
        """``rgb_array``: the 224x224 view beside its memory channel (grey)."""
        if self.render_mode != "rgb_array" or self._scene < 0:
            return None
        view = np.array(self.caches[self._scene].images[self._view, :, :, :3])
        memory = np.repeat(self._map[:, :, 3:], 3, axis=2)
        return np.concatenate([view, memory], axis=1)

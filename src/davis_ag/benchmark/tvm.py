"""Target visibility maximisation (TVM, section V-A) as a Gymnasium environment.

An episode (section V-D):

- ``reset`` draws, from ``self.np_random`` only, a start: a (scene, view, target) of the split
  whose target fruit is boxed in that view with OER < 0.4 and has at least ``min_fruit_pixels``
  visible pixels (section III-C): scene.json's value where the scene has one (what its boxes
  were made with), else the crop's, scaled by image area relative to 1280x720. By default
  (``start_rule="pairs"``) every such start is equally likely, section V-D's "a random
  viewpoint showing a target fruit with an OER < .400"; ``start_rule="scene"`` (the rule
  before) draws a scene, then a view of it, then a target, each uniformly, so a scene with two
  eligible starts gets as many episodes as one with two hundred. The start list is built once;
  :meth:`TVMEnv.start_probabilities` gives each start's probability under the rule.
- The observation is the view resized to 224x224 plus a fourth channel that is 255 inside the
  target's box and 0 elsewhere (section V-C uses 1; 255 keeps one uint8 image space, which
  Stable-Baselines3 scales by 1/255 anyway).
- The box, and so the OER, is always the target's box as annotated in the *current* view (the
  instance id is stable across a scene's views).
- Actions: the scenario's moves in :data:`davis_ag.scene.specs` order, then ``done``: SP forward,
  backward, left, right, up, down, done (7); MP adds rotate_cw, rotate_ccw before done (9).
- A move that points to "" or to a view where the target has no box leaves the agent where it
  is (section V-D); it still costs a step.
- Every action, ``done`` included, is a step; the episode ends after ``tau`` steps (3 SP, 5 MP)
  or on ``done``, so the episode length is the paper's "Ep. Length" (1 when ``done`` comes
  first). Both endings are ``terminated=True``: the reward is the final one and nothing
  follows, so a learner must not bootstrap past it (``truncated`` would make SB3 add
  ``gamma * V(last obs)``). ``truncated`` is always False.
- Reward: ``max(OER_end - OER_0, 0) ** 2`` on the last step, 0 before.
- ``info``: ``oer_0``, ``oer_t`` (current), ``path`` (view names: the start, then one per move,
  repeated where a move was refused; ``done`` adds none), ``target_fruit`` (instance id),
  ``scene`` (id) and ``steps``.
- Exact planners read the dynamics through :meth:`TVMEnv.move_table`, not the image;
  :meth:`TVMEnv.action_masks` gives the actions not refused now (sb3-contrib's MaskablePPO).
- ``robot=``: moves only between reachable views, each costing its seconds, with ``info["robot"]``
  and an optional ``budget_s`` (:mod:`davis_ag.benchmark.robot_moves`).
"""

from __future__ import annotations

import copy
import os
from typing import TYPE_CHECKING, Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from davis_ag.benchmark.cache import OBS_SIZE, SceneCache, load_scene_cache
from davis_ag.benchmark.episode_rules import (
    MAX_START_OER,
    START_RULES,
    discrete_action,
    episode_reward,
    named_action,
)
from davis_ag.benchmark.robot_moves import RobotOnGrid, attach_robot, no_reachable_start
from davis_ag.benchmark.splits import as_dataset, select_scenes
from davis_ag.benchmark.starts import SceneStarts, compress, eligible, keep_side, min_pixels
from davis_ag.errors import UserError
from davis_ag.formats.splits import check_split_rule
from davis_ag.scene.specs import ALL_ACTIONS, scenario_spec

if TYPE_CHECKING:  # the reader loads on first use (see as_dataset)
    from davis_ag.data.reader import Dataset

#: With ``budget_s`` and no ``tau``: the most steps an episode takes (refused moves cost no seconds).
BUDGET_STEP_CAP = 100


class TVMEnv(gym.Env[np.ndarray, np.int64]):
    """DAVIS-Ag target visibility maximisation; see the module docstring for the rules."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 2}  # noqa: RUF012 - Gymnasium declares it an instance attribute

    def __init__(
        self,
        dataset: Dataset | str | os.PathLike[str],
        scenario: str = "sp",
        split: str = "train",
        crop: str | None = None,
        cache_dir: str | os.PathLike[str] | None = None,
        max_start_oer: float = MAX_START_OER,
        tau: int | None = None,
        render_mode: str | None = None,
        start_rule: str = "pairs",
        robot: str | None = None,
        budget_s: float | None = None,
        split_rule: str = "scenes",
    ) -> None:
        """Open the scenes of one scenario and split, building their caches if needed.

        Args:
            dataset: A dataset root (path) or an opened ``davis_ag.data.reader.Dataset``; passing
                the opened one lets several environments share one parse.
            scenario: ``sp`` or ``mp``.
            split: ``train``, ``test`` or ``all`` (see :mod:`davis_ag.benchmark.splits`).
            crop: Keep one crop only; ``None`` keeps all crops of the scenario.
            cache_dir: Base folder of the observation caches (default under the dataset root).
            max_start_oer: A target must start with an OER below this (0.4 in the paper).
            tau: Steps per episode; default the scenario's (3 SP, 5 MP).
            render_mode: ``None`` or ``"rgb_array"``.
            start_rule: ``pairs`` (default: every eligible start equally likely) or ``scene``
                (scene, then view, then target; see :data:`START_RULES`).
            robot: A robot (``davis-ag robots``, or a YAML file): moves are restricted to the views it
                reaches and cost its seconds (:mod:`davis_ag.benchmark.robot_moves`).
            budget_s: With a robot, end an episode when its seconds are spent (a move that would
                overrun the budget is not made and ends the episode) instead of after ``tau``
                steps; ``tau`` then defaults to :data:`BUDGET_STEP_CAP`, a cap on refused moves.
            split_rule: ``scenes`` (default: the split's scenes, every start of them), ``starts`` or
                ``fruits`` (every scene of the split, the starts of ``split``'s side;
                :mod:`davis_ag.benchmark.starts`).

        Raises:
            UserError: when the path is not a dataset, the split has no scene, or no scene has
                an eligible start.
        """
        spec = scenario_spec(scenario)
        if render_mode not in (None, "rgb_array"):
            raise UserError(f"unknown render_mode {render_mode!r}: use None or 'rgb_array'")
        if start_rule not in START_RULES:
            raise UserError(f"unknown start_rule {start_rule!r}: use one of {', '.join(START_RULES)}")
        self.start_rule = start_rule
        self.split_rule = check_split_rule(split_rule)
        self.render_mode = render_mode
        self.dataset = as_dataset(dataset)
        self.scenario = spec.name
        self.split = split
        if budget_s is not None and (robot is None or not budget_s > 0):
            raise UserError(f"budget_s={budget_s} needs a robot and a positive number of seconds")
        self.budget_s = budget_s
        self.tau = int(tau if tau is not None else (BUDGET_STEP_CAP if budget_s is not None else spec.tau))
        if self.tau < 1:
            raise UserError(f"tau must be at least 1, got {self.tau}")
        #: Action names by index: the scenario's moves, then ``done``.
        self.action_names: tuple[str, ...] = (*tuple(spec.actions), "done")
        self.done_action = len(self.action_names) - 1
        # Column of each move in the cache's pointer table (which follows ALL_ACTIONS).
        self._columns = [ALL_ACTIONS.index(a) for a in spec.actions]
        self.action_space = spaces.Discrete(len(self.action_names))
        self.observation_space = spaces.Box(0, 255, (OBS_SIZE, OBS_SIZE, 4), dtype=np.uint8)

        self.scenes = select_scenes(self.dataset, spec.name, split, crop, split_rule)
        self.caches: list[SceneCache] = [load_scene_cache(s, self.dataset.root, cache_dir) for s in self.scenes]
        self.robot: RobotOnGrid | None = None
        if robot is not None:
            self.robot, self.caches = attach_robot(robot, self.scenes, self.caches, self.dataset.root, cache_dir)
        masks = [eligible(c, min_pixels(s, c), max_start_oer) for s, c in zip(self.scenes, self.caches)]
        masks = keep_side(self.dataset, self.scenes, self.caches, masks, split_rule, split)
        self._starts: list[tuple[int, SceneStarts]] = []
        for index, (mask, cache) in enumerate(zip(masks, self.caches)):
            if self.robot is not None:  # after the split's side: a robot narrows a split, never moves it
                mask = mask & self.robot.reaches[index].reachable[cache.box_view]
            starts = compress(cache, mask)
            if len(starts.views):
                self._starts.append((index, starts))
        if not self._starts and self.robot is not None:
            raise no_reachable_start(self.robot, self.scenes, split, self.dataset.root)
        if not self._starts:
            raise UserError(
                f"no eligible start in the {split} split of {self.dataset.root} "
                f"({len(self.scenes)} {spec.name} scenes): no boxed fruit has OER < "
                f"{max_start_oer} and enough visible pixels; use another split or dataset"
            )
        # Every eligible start as (scene index, box row), in scene, view, annotation order.
        self.starts: np.ndarray = np.array(
            [(scene, int(box)) for scene, starts in self._starts for box in starts.boxes], dtype=np.int64
        ).reshape(-1, 2)
        self._scene = self._view = self._box = self._fruit = self._t = -1
        self._oer_0 = self._seconds = self._move_seconds = 0.0
        self._path: list[str] = []
        self._over = True

    # ----------------------------------------------------------------------------- episode

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode.

        Args:
            seed: Reseeds ``self.np_random``, the only source of randomness.
            options: ``{"start": (scene_id, view_name, fruit_id)}`` forces a start (any boxed
                fruit, eligible or not); used by tests and hand-made cases.

        Returns:
            The first observation and the info dict (see :meth:`_info`).
        """
        super().reset(seed=seed)
        if options and "start" in options:
            self._force_start(*options["start"])
        elif self.start_rule == "pairs":
            scene, box = self.starts[int(self.np_random.integers(len(self.starts)))]
            self._scene, self._box = int(scene), int(box)
        else:
            rng = self.np_random
            scene, starts = self._starts[int(rng.integers(len(self._starts)))]
            k = int(rng.integers(len(starts.views)))
            lo, hi = int(starts.offsets[k]), int(starts.offsets[k + 1])
            box = int(starts.boxes[lo + int(rng.integers(hi - lo))])
            self._scene, self._box = scene, box
        cache = self.caches[self._scene]
        self._view = int(cache.box_view[self._box])
        self._fruit = int(cache.box_fruit[self._box])
        self._t = 0
        self._seconds = self._move_seconds = 0.0
        self._oer_0 = float(cache.box_oer[self._box])
        self._path = [cache.view_names[self._view]]
        self._over = False
        return self._observation(), self._info()

    def fork(self) -> TVMEnv:
        """An environment over the same scenes, starts and caches (shared, read only) with an
        episode and a random generator of its own: what lets many episodes be played in step
        (:mod:`davis_ag.benchmark.lockstep`) without a second copy of the images."""
        twin = copy.copy(self)
        twin._np_random = None  # reset(seed=...) makes its own; never the original's generator
        twin._scene = twin._view = twin._box = twin._fruit = twin._t = -1
        twin._path, twin._over = [], True
        return twin

    def start_probabilities(self) -> np.ndarray:
        """The probability that ``reset`` starts from each row of :attr:`starts` under the rule."""
        if self.start_rule == "pairs":
            return np.full(len(self.starts), 1.0 / len(self.starts))
        weights = []
        for _, starts in self._starts:
            per_view = np.diff(starts.offsets)
            weights.append(np.repeat(1.0 / (len(self._starts) * len(per_view) * per_view), per_view))
        return np.concatenate(weights)

    def _force_start(self, scene_id: str, view_name: str, fruit_id: int) -> None:
        """Point the episode at a given scene, view and fruit (``options["start"]``)."""
        ids = [s.id for s in self.scenes]
        if scene_id not in ids:
            raise UserError(f"start scene {scene_id!r} is not in the {self.split} split")
        cache = self.caches[ids.index(scene_id)]
        if view_name not in cache.view_names:
            raise UserError(f"start view {view_name!r} is not in scene {scene_id}")
        view = cache.view_names.index(view_name)
        column = np.flatnonzero(cache.fruit_ids == int(fruit_id))
        box = int(cache.box_index[view, column[0]]) if len(column) else -1
        if box < 0:
            raise UserError(f"fruit {fruit_id} has no box in {scene_id}/{view_name}")
        self._scene, self._box = ids.index(scene_id), box

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Apply one action.

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
        over_budget = False
        if a != self.done_action:
            view, box = self._move(self._view, a)
            if self.robot is not None and view != self._view:
                self._move_seconds = self.robot.seconds(self._scene, self._view, self._columns[a])
                over_budget = self.budget_s is not None and self._seconds + self._move_seconds > self.budget_s
                if over_budget:  # the move is not made: the budget ends the episode where it is
                    self._move_seconds, view, box = 0.0, self._view, self._box
            else:
                self._move_seconds = 0.0
            self._seconds += self._move_seconds
            self._view, self._box = view, box
            self._path.append(self.caches[self._scene].view_names[self._view])
        terminated = a == self.done_action or self._t >= self.tau or over_budget
        reward = 0.0
        if terminated:
            self._over = True
            reward = self.reward(self._oer_0, self.oer)
        return self._observation(), reward, terminated, False, self._info()

    def action_masks(self) -> np.ndarray:
        """Which actions are not refused from here: ``done``, and each move to a view where the target has a box."""
        return np.array([self._move(self._view, a)[0] != self._view for a in range(self.done_action)] + [True])

    def action_for(self, name: str) -> int:
        """The index of the action called ``name`` (a policy may answer with names).

        Raises:
            UserError: for a name that is not an action of this scenario.
        """
        return named_action(name, self.action_names, f"this {self.scenario} environment")

    def describe(self) -> dict[str, Any]:
        """What an evaluation's protocol records of this environment: its id, scenario, split,
        split rule, tau, scenes, dataset root, action names, start rule and eligible start count."""
        return {
            "environment": "davis_ag/TVM-v0",
            "scenario": self.scenario,
            "split": self.split,
            "tau": self.tau,
            "scenes": [s.id for s in self.scenes],
            "dataset": str(self.dataset.root),
            "actions": list(self.action_names),
            "start_rule": self.start_rule,
            "split_rule": self.split_rule,
            "starts": len(self.starts),
            "robot": self.robot.record() if self.robot is not None else None,
        }

    def _action_index(self, action: Any) -> int:
        """Validate an action (Python or NumPy integer, or a one-element integer array)."""
        return discrete_action(action, self.action_names)

    def _move(self, view: int, action: int) -> tuple[int, int]:
        """Where a move leads for the current target: ``(view, box row)``; refused: stays."""
        cache = self.caches[self._scene]
        nxt = int(cache.pointers[view, self._columns[action]])
        if nxt >= 0:
            box = int(cache.box_index[nxt, self._fruit])
            if box >= 0:
                return nxt, box
        return view, int(cache.box_index[view, self._fruit])

    @staticmethod
    def reward(oer_0: float, oer_end: float) -> float:
        """Section V-C: ``max(OER_end - OER_0, 0) ** 2`` (:func:`episode_reward`)."""
        return episode_reward(oer_0, oer_end)

    # ----------------------------------------------------------------------------- state

    @property
    def oer(self) -> float:
        """The target's OER in the current view."""
        return float(self.caches[self._scene].box_oer[self._box])

    @property
    def steps_taken(self) -> int:
        """Steps of the current episode so far (``done`` included)."""
        return self._t

    @property
    def current_view(self) -> int:
        """Index of the current view in the current scene's cache."""
        return self._view

    @property
    def scene_id(self) -> str:
        """Id of the current episode's scene."""
        return self.scenes[self._scene].id

    def move_table(self) -> tuple[np.ndarray, np.ndarray]:
        """The current target's dynamics, for exact planners such as the Oracle agent.

        Returns:
            The tables :meth:`target_move_table` returns for the current episode's scene and target.
        """
        return self.target_move_table(self._scene, self._fruit)

    def target_move_table(self, scene: int, fruit: int) -> tuple[np.ndarray, np.ndarray]:
        """One target's dynamics, read from the scene's tables (not the image).

        Args:
            scene: Index into :attr:`scenes`.
            fruit: Column of the scene cache's ``fruit_ids`` (``box_fruit`` of a box row).

        Returns:
            ``next_view``: ``(n_views, n_moves)`` int32, the view each move (actions
                ``0..done_action-1``) leads to from each view, with refused moves staying put;
                and ``oer``: ``(n_views,)`` float32, the target's OER per view, NaN where it has
                no box (such views are never entered).
        """
        cache = self.caches[scene]
        nxt = cache.pointers[:, self._columns]
        here = np.arange(cache.n_views, dtype=np.int32)[:, None]
        boxes = cache.box_index[:, fruit]
        valid = (nxt >= 0) & (boxes[np.maximum(nxt, 0)] >= 0)
        oer = np.where(boxes >= 0, cache.box_oer[np.maximum(boxes, 0)], np.nan)
        return np.where(valid, nxt, here).astype(np.int32), oer.astype(np.float32)

    def _observation(self) -> np.ndarray:
        """The current view (224x224 RGB) with the target's box as a fourth 0/255 channel."""
        cache = self.caches[self._scene]
        # The cache's fourth channel is all zeros: one contiguous copy, then the box.
        obs = np.array(cache.images[self._view])
        x0, y0, x1, y1 = cache.box_scaled[self._box].tolist()
        obs[y0 : y1 + 1, x0 : x1 + 1, 3] = 255
        return obs

    def _info(self) -> dict[str, Any]:
        """Episode facts: start and current OER, views visited, target, scene, steps."""
        info = {
            "oer_0": self._oer_0,
            "oer_t": self.oer,
            "path": list(self._path),
            "target_fruit": int(self.caches[self._scene].fruit_ids[self._fruit]),
            "scene": self.scenes[self._scene].id,
            "steps": self._t,
        }
        if self.robot is not None:
            info["robot"] = self.robot.info(self._scene, self._view, self._move_seconds, self._seconds)
        return info

    def render(self) -> np.ndarray | None:
        """``rgb_array``: the 224x224 view with the target's box outlined in red."""
        if self.render_mode != "rgb_array" or self._scene < 0:
            return None
        cache = self.caches[self._scene]
        frame = np.array(cache.images[self._view, :, :, :3])
        x0, y0, x1, y1 = cache.box_scaled[self._box].tolist()
        red = np.array([255, 0, 0], dtype=np.uint8)
        frame[y0, x0 : x1 + 1] = frame[y1, x0 : x1 + 1] = red
        frame[y0 : y1 + 1, x0] = frame[y0 : y1 + 1, x1] = red
        return frame

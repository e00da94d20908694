"""Target visibility maximisation with a continuous camera pose (``davis_ag/TVMContinuous-v0``).

The task is TVM-v0's (section V-A): start on a view of a target fruit with OER < 0.4, move for
``tau`` steps (3 SP, 5 MP), and earn ``max(OER_tau - OER_0, 0) ** 2`` at the end. What changes
is the camera: instead of stepping between the dataset's grid views, the agent moves anywhere,
and every observation is drawn live from the regrown scene (:mod:`davis_ag.live.scene`).

Why a separate environment: TVM-v0 reads any published dataset and knows nothing of renderers;
this one renders every pose, so it needs a scene of ours (a scene.json to regrow) and OpenGL.

- Action: a Box in [-1, 1]: ``(dx, dy, dz)`` in the world frame, scaled by ``max_move`` (default
  the scene's grid step) and ``max_climb`` (default half the span of the scene's altitudes); with
  ``aim="free"`` (MP default) two more, ``(dyaw, dpitch)``, scaled by ``max_turn`` degrees
  (default the scene grid's turn between headings: 30 on the MP grid's 12). Defaults follow each
  scene's own grid as scene.json records it (reduced grids, crops of other altitudes). With
  ``aim="plant"`` (SP default) the camera always looks at the plant, as the SP grid's views do.
- Slip (section III-B): a move with a horizontal part lands off by Gaussian noise of 2.5 cm on x
  and y (turning and climbing in place do not slip), drawn from ``self.np_random`` only.
- Refused moves (the agent stays, the step still counts), as section V-D refuses grid moves: the
  new position leaves the scenario's grid area or altitude range; the straight path comes within
  the crop's exclusion distance of a stem (section III-C: 0.75 m strawberry, 1 m others), the
  collision rule; or the target has no box from the new pose (section V-D).
- Observation: ``(224, 224, 4)`` uint8, drawn directly at that size by a square camera with the
  scene's vertical field of view (the dataset's 16:9 frames cover a wider horizontal angle), plus
  the target's box as a fourth channel, 255 inside and 0 elsewhere (TVM-v0's convention).
  The OER is the target's at this size; the box threshold is the crop's scaled to the area.
- Start (``reset``): a scene, then random poses inside the grid area (outside the exclusion
  distance), aimed at a plant (``aim="free"``: at a random plant, yaw jittered up to
  ``max_turn``), until one shows a boxed fruit with OER < ``max_start_oer``: the target.
- Episodes end after ``tau`` steps with ``terminated=True`` (no ``done`` action: standing still is
  a zero action); ``info`` has ``oer_0``, ``oer_t``, ``path`` (poses), ``refused`` (why the last
  move was refused, or ""), ``target_fruit``, ``scene`` and ``steps``.
"""

from __future__ import annotations

import math
import os
from pathlib import Path
from typing import Any

import gymnasium as gym
import numpy as np
from gymnasium import spaces

from davis_ag.benchmark.cache import OBS_SIZE
from davis_ag.benchmark.episode_rules import MAX_START_OER, can_start, episode_reward
from davis_ag.errors import UserError
from davis_ag.generate.recorded_settings import RecordedSettings
from davis_ag.live.continuous_moves import (
    PITCH_RANGE,
    blocked_move,
    grid_bounds,
    grid_climb,
    grid_turn,
    named_action,
    scene_folders,
)
from davis_ag.live.continuous_robot import RobotOnPoses
from davis_ag.live.scene import LiveScene, LiveView, open_live_scene
from davis_ag.scene.specs import SLIP_SIGMA, scenario_spec
from davis_ag.scene.view_grid import Viewpoint, excluded

#: Random poses tried per reset before giving up on a scene.
START_TRIES = 200


class TVMContinuousEnv(gym.Env[np.ndarray, np.ndarray]):
    """TVM with a continuous camera pose; see the module docstring for the rules."""

    metadata = {"render_modes": ["rgb_array"], "render_fps": 2}  # noqa: RUF012 - Gymnasium declares it an instance attribute
    action_space: spaces.Box

    def __init__(
        self,
        dataset: str | os.PathLike[str],
        scenario: str = "sp",
        split: str = "train",
        crop: str | None = None,
        aim: str | None = None,
        tau: int | None = None,
        max_move: float | None = None,
        max_climb: float | None = None,
        max_turn: float | None = None,
        max_start_oer: float = MAX_START_OER,
        size: int = OBS_SIZE,
        antialiasing: str = "none",
        render_mode: str | None = None,
        robot: str | None = None,
        budget_s: float | None = None,
    ) -> None:
        """Open (regrow or load) the scenes.

        Args:
            dataset: A dataset root made by ``davis-ag generate``, or one scene folder of it.
            scenario: ``sp`` or ``mp`` (a scene folder must be of this scenario).
            split: ``train``, ``test`` or ``all`` (ignored for a scene folder).
            crop: Keep one crop only.
            aim: ``plant`` (camera looks at the plant; SP default) or ``free`` (MP default).
            tau: Steps per episode (default the scenario's: 3 SP, 5 MP).
            max_move: Horizontal move of a full action, m (default the scene's grid step).
            max_climb: Vertical move of a full action, m (default half the scene's altitude span).
            max_turn: Yaw and pitch change of a full action, degrees (``aim="free"``; default
                360 over the scene grid's headings, or 30 for a grid of one heading).
            max_start_oer: A target must start below this OER.
            size: Observation side, pixels.
            antialiasing: The renderer's: ``none`` (default: the fastest), ``fxaa`` or ``msaa``; ids are
                exact in every mode.
            render_mode: None or ``"rgb_array"``.
            robot: The camera rides on this robot (:mod:`davis_ag.live.continuous_robot`).
            budget_s: With a robot, the most seconds an episode may spend.

        Raises:
            UserError: for bad settings, or when no scene of ours matches.
        """
        spec = scenario_spec(scenario)
        if render_mode not in (None, "rgb_array"):
            raise UserError(f"unknown render_mode {render_mode!r}: use None or 'rgb_array'")
        aim = aim or ("plant" if spec.name == "sp" else "free")
        if aim not in ("plant", "free"):
            raise UserError(f"aim {aim!r}: choose plant or free")
        if size < 16:
            raise UserError(f"observation size {size}: give at least 16 pixels")
        self.render_mode, self.scenario, self.split, self.aim, self.size = render_mode, spec.name, split, aim, int(size)
        self.antialiasing = antialiasing
        self.tau = int(tau if tau is not None else spec.tau)
        if self.tau < 1:
            raise UserError(f"tau must be at least 1, got {self.tau}")
        folders = scene_folders(dataset, spec.name, split, crop)
        self.dataset_root = str(Path(os.fspath(dataset)).expanduser().absolute())
        if folders == [Path(os.fspath(dataset))]:
            self.split = "scene"  # one scene folder: no split
        if not folders:
            raise UserError(f"{dataset}: no {spec.name} scene in the {split} split")
        self.scenes: list[LiveScene] = []
        try:
            for folder in folders:
                scene = open_live_scene(folder)
                if scene.settings.scenario.name != spec.name:
                    raise UserError(
                        f"{folder} is a {scene.settings.scenario.name} scene, not {spec.name}: "
                        f"pass scenario={scene.settings.scenario.name!r}"
                    )
                self.scenes.append(scene)
            self.robot = RobotOnPoses.made(robot, folders, budget_s)
        except BaseException:
            self.close()
            raise
        self._given_scales = (max_move, max_climb, max_turn)
        self.max_start_oer = float(max_start_oer)
        self.action_space = spaces.Box(-1.0, 1.0, (3 if aim == "plant" else 5,), dtype=np.float32)
        self.observation_space = spaces.Box(0, 255, (self.size, self.size, 4), dtype=np.uint8)
        self._scene = -1
        self._view: Viewpoint | None = None
        self._labels: LiveView | None = None
        self._target = -1
        self._t = 0
        self._oer_0 = 0.0
        self._path: list[list[float]] = []
        self._refused = ""
        self._over = True
        #: Views drawn so far (each one a render of the scene): what a step or a reset costs.
        self.draws = 0

    # ----------------------------------------------------------------------------- geometry

    @property
    def scene(self) -> LiveScene:
        """The current episode's scene."""
        return self.scenes[self._scene]

    def bounds(self, scene: LiveScene | None = None) -> tuple[np.ndarray, np.ndarray]:
        """Lower and upper corners (x, y, z) of where the camera may be: the grid's area (its odd
        rows reach half a step further east) and altitude range."""
        return grid_bounds((scene or self.scene).settings)

    def blocked(self, start: np.ndarray, end: np.ndarray) -> str:
        """Why a straight move from ``start`` to ``end`` is not allowed ("" when it is)."""
        return blocked_move(self.bounds(), self.scene.stems, self.scene.settings.crop.exclusion_radius, start, end)

    def _pose(self, position: np.ndarray, yaw: float, pitch: float) -> Viewpoint:
        if self.aim == "plant":
            return self.scene.aimed_pose(*position)
        return self.scene.pose(position[0], position[1], position[2], yaw, float(np.clip(pitch, *PITCH_RANGE)))

    def _draw(self, view: Viewpoint) -> LiveView:
        self.draws += 1
        # No depth: the task never looks at it, and leaving it out makes each draw cheaper.
        return self.scene.render(
            view, self.size, self.size, antialiasing=self.antialiasing, fractions=False, fast_ground=True, depth=False
        )

    # ----------------------------------------------------------------------------- episode

    def reset(
        self, *, seed: int | None = None, options: dict[str, Any] | None = None
    ) -> tuple[np.ndarray, dict[str, Any]]:
        """Start an episode.

        Args:
            seed: Reseeds ``self.np_random``, the only source of randomness.
            options: ``{"pose": [x, y, z, yaw, pitch], "target": fruit_id, "scene": index}`` forces
                a start (the target must have a box there); ``{"scene": index}`` alone draws the
                start in that scene.

        Returns:
            The first observation and the info dict.
        """
        super().reset(seed=seed)
        rng = self.np_random
        options = dict(options or {})
        unknown = sorted(set(options) - {"pose", "target", "scene"})
        scene = options.get("scene", 0)
        alone = "target" in options and "pose" not in options  # a target is chosen with its pose
        if unknown or alone or not isinstance(scene, (int, np.integer)) or not 0 <= scene < len(self.scenes):
            raise UserError(
                f"reset options {options}: give a scene index below {len(self.scenes)}, a pose and a target"
                + (f" (not {', '.join(unknown)})" if unknown else "")
            )
        if "pose" in options:
            self._scene = int(options.get("scene", 0))
            if len(options["pose"]) != 5:
                raise UserError(
                    f"start {options}: give a scene index below {len(self.scenes)} and a pose [x, y, z, yaw, pitch]"
                )
            x, y, z, yaw, pitch = (float(v) for v in options["pose"])
            self._view = self._pose(np.array([x, y, z]), yaw, pitch)
            self._labels = self._draw(self._view)
            self._target = int(options.get("target", -1))
            if self._labels.box(self._target) is None:
                raise UserError(f"fruit {self._target} has no box from pose {options['pose']}")
            if self.robot is not None and not self.robot.start(self._scene, self._view.pose, rng):
                raise UserError(f"the robot does not reach pose {options['pose']}")
        else:
            self._scene = int(options["scene"]) if "scene" in options else int(rng.integers(len(self.scenes)))
            self._start(rng)
        self._t, self._refused, self._over = 0, "", False
        self._oer_0 = self.oer
        self._path = [self._rounded_pose()]
        return self._observation(), self._info()

    def _start(self, rng: np.random.Generator) -> None:
        """Random poses until one shows a fruit with a box and OER below the start limit."""
        lo, hi = self.bounds()
        stems = self.scene.stems
        radius = self.scene.settings.crop.exclusion_radius
        for _ in range(START_TRIES):
            position = rng.uniform(lo, hi)
            if excluded(position[0], position[1], stems, radius):
                continue
            plant = stems[int(rng.integers(len(stems)))]
            aim_z = self.scene.assets.aim_height
            dx, dy = plant - position[:2]
            yaw = math.degrees(math.atan2(dy, dx)) + float(rng.uniform(-1, 1)) * self.max_turn
            pitch = math.degrees(math.atan2(aim_z - position[2], math.hypot(dx, dy)))
            view = self._pose(position, yaw, pitch)
            if self.robot is not None and not self.robot.start(self._scene, view.pose, rng):
                continue  # the arm first: a pose it cannot reach costs an IK, not a draw
            labels = self._draw(view)
            eligible = [f for f, oer in labels.oer.items() if can_start(oer, self.max_start_oer)]
            if eligible:
                self._view, self._labels = view, labels
                self._target = int(eligible[int(rng.integers(len(eligible)))])
                return
        raise UserError(
            f"{self.scene.settings.folder}: no start pose with a fruit of OER < {self.max_start_oer} "
            f"in {START_TRIES} tries; use another scene or a higher max_start_oer"
        )

    def action_for(self, name: str) -> np.ndarray:
        """A grid move's name as a full unit move along its axis (a policy may answer with names):
        left/right -x/+x, backward/forward -y/+y, down/up -z/+z, rotate_ccw/rotate_cw +yaw/-yaw
        (``aim="free"`` only); ``done`` stands still.

        Raises:
            UserError: for a name with no such move here.
        """
        return named_action(name, self.action_space.shape[0])

    def describe(self) -> dict[str, Any]:
        """What an evaluation's protocol records of this environment (its starts are drawn poses,
        so there is no start count)."""
        return {
            "environment": "davis_ag/TVMContinuous-v0",
            "scenario": self.scenario,
            "split": self.split,
            "tau": self.tau,
            "aim": self.aim,
            "scenes": [s.settings.metadata.scene for s in self.scenes],
            "dataset": self.dataset_root,
            "actions": ["dx", "dy", "dz", "dyaw", "dpitch"][: self.action_space.shape[0]],
            "robot": self.robot.record() if self.robot is not None else None,
        }

    @property
    def _grid(self) -> RecordedSettings:
        """The current scene's settings (the first scene's before any reset)."""
        return self.scenes[max(self._scene, 0)].settings

    @property
    def max_move(self) -> float:
        """Horizontal move of a full action, m: as given, else the current scene's grid step."""
        given = self._given_scales[0]
        return float(given if given is not None else self._grid.scenario.step)

    @property
    def max_climb(self) -> float:
        """Vertical move of a full action, m: as given, else half the current scene's altitude span."""
        given = self._given_scales[1]
        if given is not None:
            return float(given)
        return grid_climb(self._grid)

    @property
    def max_turn(self) -> float:
        """Yaw and pitch change of a full action, degrees: as given, else the current scene grid's
        turn between headings (30 for a grid of one heading)."""
        given = self._given_scales[2]
        if given is not None:
            return float(given)
        return grid_turn(self._grid)

    def _action(self, action: Any) -> np.ndarray:
        a = np.asarray(action, dtype=np.float64).reshape(-1)
        if a.shape != self.action_space.shape or not np.all(np.isfinite(a)):
            raise UserError(
                f"invalid action {action!r}: expected {self.action_space.shape[0]} finite numbers in [-1, 1]"
            )
        return np.clip(a, -1.0, 1.0)

    def proposed(self, action: Any, slip: bool = True) -> Viewpoint:
        """The pose an action aims for from the current one (slip drawn when ``slip``)."""
        a = self._action(action)
        here = np.asarray(self._here.position, dtype=np.float64)
        move = np.array([a[0] * self.max_move, a[1] * self.max_move, a[2] * self.max_climb])
        if slip and (move[0] or move[1]):
            move[:2] += self.np_random.normal(0.0, SLIP_SIGMA, size=2)
        turn = (a[3] * self.max_turn, a[4] * self.max_turn) if self.aim == "free" else (0.0, 0.0)
        return self._pose(here + move, self._here.yaw + turn[0], self._here.pitch + turn[1])

    def try_pose(self, view: Viewpoint) -> tuple[str, LiveView | None]:
        """Whether the camera may go from the current pose to ``view``, and the labels there.

        Returns:
            ``("", labels)`` when allowed, else ``(reason, labels or None)``: ``bounds``, ``collision``, ``target lost``, or the robot's.
        """
        reason = self.blocked(np.asarray(self._here.position), np.asarray(view.position))
        if not reason and self.robot is not None:  # the arm's IK before the draw, which costs more
            reason = self.robot.plan(self._scene, view.pose)
        if reason:
            return reason, None
        labels = self._draw(view)
        return ("" if labels.box(self._target) is not None else "target lost"), labels

    def step(self, action: Any) -> tuple[np.ndarray, float, bool, bool, dict[str, Any]]:
        """Move, render, and at the last step pay the reward.

        Raises:
            UserError: for an action of the wrong shape or not finite, or a step after the end.
        """
        if self._over:
            raise UserError("the episode is over (or never started): call reset() first")
        view = self.proposed(action)
        self._refused, labels = self.try_pose(view)
        if self.robot is not None:
            self.robot.settle(moved=not self._refused)
        if not self._refused:
            self._view, self._labels = view, labels
        self._t += 1
        self._path.append(self._rounded_pose())
        terminated = self._t >= self.tau or (self.robot is not None and self.robot.over_budget)
        reward = 0.0
        if terminated:
            self._over = True
            reward = episode_reward(self._oer_0, self.oer)
        return self._observation(), reward, terminated, False, self._info()

    # ----------------------------------------------------------------------------- state

    @property
    def oer(self) -> float:
        """The target's OER in the current view."""
        return float(self._seen.oer[self._target])

    @property
    def steps_taken(self) -> int:
        """Steps of the current episode so far."""
        return self._t

    @property
    def target(self) -> int:
        """The target fruit's id."""
        return self._target

    @property
    def _here(self) -> Viewpoint:
        """The current pose (an episode has started)."""
        assert self._view is not None, "no pose before reset()"
        return self._view

    @property
    def _seen(self) -> LiveView:
        """The labels of the current view (an episode has started)."""
        assert self._labels is not None, "no view before reset()"
        return self._labels

    def _target_box(self) -> list[int]:
        box = self._seen.box(self._target)
        assert box is not None  # a move that loses the target is refused, so the view holds it
        return box

    def _rounded_pose(self) -> list[float]:
        return [round(float(v), 4) for v in (*self._here.position, self._here.yaw, self._here.pitch)]

    def _observation(self) -> np.ndarray:
        obs = np.zeros((self.size, self.size, 4), dtype=np.uint8)
        obs[..., :3] = self._seen.colour
        x0, y0, w, h = self._target_box()[:4]
        obs[y0 : y0 + h, x0 : x0 + w, 3] = 255
        return obs

    def _info(self) -> dict[str, Any]:
        info = {
            "oer_0": self._oer_0,
            "oer_t": self.oer,
            "path": [list(p) for p in self._path],
            "refused": self._refused,
            "target_fruit": self._target,
            "scene": self.scene.settings.metadata.scene,
            "steps": self._t,
        }
        if self.robot is not None:
            info["robot"] = self.robot.info(self._scene)
        return info

    def render(self) -> np.ndarray | None:
        """``rgb_array``: the current view with the target's box outlined in red."""
        if self.render_mode != "rgb_array" or self._labels is None:
            return None
        frame = np.array(self._seen.colour)
        x0, y0, w, h = self._target_box()[:4]
        x1, y1 = x0 + w - 1, y0 + h - 1
        frame[y0, x0 : x1 + 1] = frame[y1, x0 : x1 + 1] = (255, 0, 0)
        frame[y0 : y1 + 1, x0] = frame[y0 : y1 + 1, x1] = (255, 0, 0)
        return frame

    def close(self) -> None:
        """Release every scene's renderers."""
        for scene in getattr(self, "scenes", []):
            scene.close()

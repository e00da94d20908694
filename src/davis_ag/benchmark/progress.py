"""Training's progress: a bar on a terminal, a line a minute in a log (tqdm formats both), and the
learning curve the training record keeps (Fig. 4a)."""

from __future__ import annotations

import sys
import time
from typing import TYPE_CHECKING, Any

from stable_baselines3.common.callbacks import BaseCallback

from davis_ag.benchmark.selection import KeepBestOnTrain

if TYPE_CHECKING:  # tqdm loads when training starts
    from tqdm import tqdm

#: Seconds between progress lines in a log (on a terminal a bar is redrawn instead).
PROGRESS_EVERY_S = 60.0


class TrainingProgress(BaseCallback):
    """Training's progress over environment steps: a tqdm bar on a terminal (steps, rate, time
    left, the last train-split score), and in a log (not a terminal) the same line once a minute.

    A run resumed from a checkpoint starts at the checkpoint's step count, not at 0.
    """

    def __init__(
        self, total: int, label: str, selection: KeepBestOnTrain | None = None, every_s: float | None = None
    ) -> None:
        """Args:
        total: The run's total environment steps.
        label: What is trained (``PPO sp``), the bar's description.
        selection: The snapshot scorer whose last score is shown.
        every_s: Seconds between log lines when not on a terminal (default :data:`PROGRESS_EVERY_S`).
        """
        super().__init__()
        self.total, self.label, self.selection = total, label, selection
        self.every_s = PROGRESS_EVERY_S if every_s is None else every_s
        self.steps, self._first, self._start, self._last = 0, 0, 0.0, 0.0
        self.bar: tqdm | None = None

    def _on_training_start(self) -> None:
        from tqdm import tqdm

        self.steps = self._first = int(self.model.num_timesteps)
        self._start = self._last = time.monotonic()
        # disable=None: no bar where stderr is not a terminal (a log), the lines below instead.
        self.bar = tqdm(
            total=self.total,
            initial=self.steps,
            desc=self.label,
            unit="step",
            mininterval=2,
            disable=None,
            dynamic_ncols=True,
        )

    def _score(self) -> str:
        best = self.selection.scores[-1] if self.selection and self.selection.scores else None
        return (
            f"train {self.selection.score_text(best)} at {best['step']}"
            if self.selection and best
            else "no train score yet"
        )

    def _on_step(self) -> bool:
        from tqdm import tqdm

        n = self.training_env.num_envs
        self.steps += n
        assert self.bar is not None  # made when training starts
        if not self.bar.disable:
            self.bar.set_postfix_str(self._score(), refresh=False)
            self.bar.update(n)
        elif time.monotonic() - self._last >= self.every_s:
            self._last = time.monotonic()
            line = tqdm.format_meter(
                self.steps,
                self.total,
                self._last - self._start,
                prefix=self.label,
                unit="step",
                initial=self._first,
                ncols=0,
            )
            print(f"{line} | {self._score()}", file=sys.stderr, flush=True)
        return True

    def _on_training_end(self) -> None:
        if self.bar is not None:
            self.bar.close()


class LearningCurve(BaseCallback):
    """Episode rewards while training, averaged over bins of ``every`` environment steps (Fig. 4a).

    Reads the ``episode`` entry SB3's ``Monitor`` puts in an ending step's info. Each point is
    ``{"step", "episodes", "reward", "length"}``: the bin's last step, the episodes that ended in
    it and their mean reward and length. Points before a resumed run's checkpoint are passed in.
    """

    def __init__(self, every: int, points: list[dict[str, Any]] | None = None) -> None:
        super().__init__()
        self.every = every
        self.points: list[dict[str, Any]] = list(points or [])
        self._rewards: list[float] = []
        self._lengths: list[int] = []
        self._edge = 0

    def _on_training_start(self) -> None:
        self._edge = (self.model.num_timesteps // self.every + 1) * self.every

    def _on_step(self) -> bool:
        for info in self.locals.get("infos", []):
            episode = info.get("episode")
            if episode:
                self._rewards.append(float(episode["r"]))
                self._lengths.append(int(episode["l"]))
        if self.model.num_timesteps >= self._edge:
            self.flush(self._edge)
            self._edge += self.every
        return True

    def flush(self, step: int) -> None:
        """Close the current bin at ``step`` (a bin without episodes adds no point)."""
        if self._rewards:
            self.points.append(
                {
                    "step": int(step),
                    "episodes": len(self._rewards),
                    "reward": round(float(sum(self._rewards) / len(self._rewards)), 6),
                    "length": round(sum(self._lengths) / len(self._lengths), 4),
                }
            )
        self._rewards, self._lengths = [], []

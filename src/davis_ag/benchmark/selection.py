"""Which snapshot a training run keeps: the last one, or the best one on the train split.

Why: A2C with SB3's learning rate (7e-4, RMSprop) on the paper's 36M-parameter network moves a
long way in a few updates. On SP strawberry (2026-11-24 ``medium`` run) the 300K-step snapshot put
probability .998 on "backward" at every train start, while the episodes of the last rollouts
earned .05-.06 reward and, trained on from that snapshot, the policy was varied again within ten
updates: the last snapshot is a draw from a policy that swings, not where training converged.
So by default a run plays ``episodes`` episodes on the *train* split every ``every`` steps (sampled
play as in evaluation, the same starts and seeds each time, so snapshots are compared on equal
terms) and keeps the snapshot with the highest mean OER_tau. The test split is never touched.

Snapshots are files named by their step (``NAME.best-0010000.zip``); a superseded one is removed
only after a checkpoint that names the new best is written, so a killed run resumes with the
best it had.
"""

from __future__ import annotations

import os
from pathlib import Path
from typing import Any

import numpy as np
import torch
from stable_baselines3.common.callbacks import BaseCallback

from davis_ag.errors import UserError, stops_held

#: What a training run keeps: ``best-train`` (default) or ``last``.
KEEP_RULES: tuple[str, ...] = ("best-train", "last")
#: Train-split episodes per snapshot score: one of the paper's 200-episode sessions.
SELECT_EPISODES = 200
#: Base seed of the scoring episodes (fixed: every snapshot plays the same starts and draws).
SELECT_SEED = 12345


def check_keep(keep: str) -> str:
    """Refuse a keep rule other than :data:`KEEP_RULES`.

    Raises:
        UserError: naming the rule and the choices.
    """
    if keep not in KEEP_RULES:
        raise UserError(f"unknown --keep {keep!r}: choose one of {', '.join(KEEP_RULES)}")
    return keep


def snapshot_path(final: Path, step: int) -> Path:
    """The file of the snapshot taken at ``step`` of a run saving to ``final`` (``NAME.zip``)."""
    stem = final.with_suffix("")
    return stem.with_name(f"{stem.name}.best-{step:07d}.zip")


def train_split_score(
    model: Any,
    env: Any,
    episodes: int = SELECT_EPISODES,
    seed: int = SELECT_SEED,
    play: Any = None,
    keys: tuple[str, ...] = ("oer_tau", "reward", "length"),
) -> dict[str, float]:
    """Mean OER_tau and reward of ``model`` over ``episodes`` episodes of ``env`` (the train split).

    Play is sampled or deterministic as in the benchmark (``DETERMINISTIC_PLAY``). Torch's random
    state is restored afterwards, so scoring does not change the training run's own draws.

    Args:
        model, env, episodes, seed: What plays where, how many episodes, their base seed.
        play: ``(env, policy, resets, draws) -> records`` of another task (default TVM-v0's
            :func:`davis_ag.benchmark.evaluation.play_episodes`).
        keys: The records' fields to average.

    Returns:
        ``{"oer_tau", "reward", "length"}`` (the ``keys``), means over the episodes.
    """
    from davis_ag.benchmark.evaluation import episode_seeds, play_episodes
    from davis_ag.benchmark.policies import DETERMINISTIC_PLAY, ModelPolicy, prepare

    agent = ModelPolicy(model, deterministic=DETERMINISTIC_PLAY)
    prepare(agent, env)  # once for all the episodes
    resets, draws = episode_seeds(seed, 0, episodes)
    # The agent seeds torch on every device; on a GPU the training run samples its actions from
    # that device's generator, so it is saved and restored too, not only the CPU's.
    device = getattr(model, "device", torch.device("cpu"))
    with torch.random.fork_rng(devices=[device] if device.type == "cuda" else []):
        records = (play or play_episodes)(env, agent, resets, draws)
    return {key: round(float(np.mean([r[key] for r in records])), 6) for key in keys}


class KeepBestOnTrain(BaseCallback):
    """Scores the policy on the train split every ``every`` steps and at the end; saves each new
    best as a snapshot file (see the module docstring).

    ``scores`` is a list of ``{"step", "oer_tau", "reward", "length"}`` (another task's score in
    place of ``oer_tau``: ``key``); ``best`` the entry of the kept snapshot. Earlier scores of a
    resumed run are passed in.
    """

    def __init__(
        self,
        env: Any,
        final: Path,
        every: int,
        save: Any,
        scores: list[dict[str, Any]] | None = None,
        episodes: int = SELECT_EPISODES,
        prune_at_once: bool = False,
        score: Any = None,
        key: str = "oer_tau",
        label: str = "OER_tau",
    ) -> None:
        """Args:
        env: The train split's environment the snapshots play.
        final: The run's model path.
        every: Environment steps between scores (0: only at the end).
        save: Saves a model to a path.
        scores: Earlier scores of a resumed run.
        episodes: Episodes per score.
        prune_at_once: Remove a superseded snapshot at once (no checkpoint names it).
        score: ``(model, env, episodes) -> dict`` of a task other than TVM-v0 (default
            :func:`train_split_score`, looked up when it scores); its ``key`` is the score kept.
        key, label: The score's name in the records and in messages.
        """
        super().__init__()
        self.score, self.key, self.label = score, key, label
        self.env, self.final, self.every, self.save = env, final, every, save
        self.episodes, self.prune_at_once = episodes, prune_at_once
        self.scores: list[dict[str, Any]] = list(scores or [])
        #: The entry of a new best whose snapshot could not be written (a full disk): the model in
        #: memory, which the run stopped on, is that snapshot, and only it holds it.
        self.unsaved: dict[str, Any] | None = None
        if self.best is not None and not snapshot_path(final, self.best["step"]).is_file():
            print(
                f"note: the best snapshot so far ({self.best['step']} steps) is gone; earlier scores are dropped",
                flush=True,
            )
            self.scores = []
        self._last = 0

    @property
    def best(self) -> dict[str, Any] | None:
        """The highest-scoring entry (the earliest of ties), or ``None`` before any score."""
        return max(self.scores, key=lambda s: (s[self.key], -s["step"])) if self.scores else None

    def score_text(self, entry: dict[str, Any]) -> str:
        """An entry's score as messages show it (``OER_tau 0.412``)."""
        return f"{self.label} {entry[self.key]:.3f}"

    def _on_training_start(self) -> None:
        # On the run's multiples of ``every``, whatever step a sitting resumes at.
        self._last = last_multiple(self.model.num_timesteps, self.every)

    def _on_step(self) -> bool:
        return True

    def _on_rollout_start(self) -> None:
        # Between rollouts, after the update of the last one: the policy scored is the one that
        # step count names (inside a rollout it would lack its last update).
        if self.every and self.model.num_timesteps - self._last >= self.every:
            self._last = last_multiple(self.model.num_timesteps, self.every)
            self.score_now()

    def score_now(self) -> None:
        """Score the current policy; save it when it is the best so far."""
        step = int(self.model.num_timesteps)
        if any(s["step"] == step for s in self.scores):
            return
        before = self.best
        score = self.score or train_split_score  # by name at each score: a test may replace it
        entry = {"step": step, **score(self.model, self.env, self.episodes)}
        self.scores.append(entry)
        if self.best is entry:
            try:
                self.save(self.model, snapshot_path(self.final, step))
            except BaseException as error:  # a full disk: the best stays the last one saved, whose file is there
                self.scores.remove(entry)
                self.unsaved = entry if isinstance(error, OSError) else None
                raise
        if self.prune_at_once:
            self.prune()
        if self.best is entry or before is None:  # (before is None only where this entry is the best)
            note = " (best so far)"
        else:
            note = f" (best {before[self.key]:.3f} at {before['step']})"
        print(f"train-split score at {step} steps: {self.score_text(entry)}" + note, flush=True)

    def prune(self, keep_none: bool = False) -> None:
        """Remove every snapshot file but the best's (all of them with ``keep_none``)."""
        best = self.best
        for path in self.final.parent.glob(f"{self.final.with_suffix('').name}.best-*.zip"):
            if keep_none or best is None or path != snapshot_path(self.final, best["step"]):
                path.unlink(missing_ok=True)

    def record(self) -> dict[str, Any]:
        """What the training record says of the choice."""
        best = self.best
        return {
            "rule": "best-train",
            "every": self.every,
            "episodes": self.episodes,
            "play": _play(),
            "scores": self.scores,
            "kept_step": best["step"] if best else None,
        }


def last_multiple(step: int, every: int) -> int:
    """The last multiple of ``every`` at or before ``step`` (``step`` itself when ``every`` is 0)."""
    return step - step % every if every else step


def publish_snapshot(snapshot: Path, final: Path) -> None:
    """Put the kept ``snapshot`` at ``final`` without copying it: a hard link, so the snapshot
    keeps its own name until the run's records are written (pruned after), or a rename where the
    file system has no links."""
    if final.exists() and os.path.samefile(snapshot, final):
        return  # published before (a run stopped before its record): renaming onto itself keeps the link
    link = final.with_name(f".{final.name}.link")  # one name: a stop between the two steps leaves it for the next
    with stops_held():
        try:
            link.unlink(missing_ok=True)
            os.link(snapshot, link)
        except OSError:
            os.replace(snapshot, final)
            return
        os.replace(link, final)


def _play() -> str:
    from davis_ag.benchmark.policies import DETERMINISTIC_PLAY

    return "deterministic" if DETERMINISTIC_PLAY else "sampled"

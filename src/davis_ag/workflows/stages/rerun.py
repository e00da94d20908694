"""``davis-ag verify RESULTS.json --dataset DATA --policy NAME=SPEC``: a row's code played again.

The replay (:mod:`davis_ag.benchmark.replay`) proves that a file's episodes follow from its
recorded actions; it cannot prove that the row's code chose them: a row replaced by the Oracle's,
its name and digest kept, replays sound. The re-run closes that, as EvalAI re-scores a submission
by running it:

1. the code given (SPEC as ``evaluate --policy`` takes it: ``file.py:function``, ``file.py:Class``,
   ``module:attr``, an SB3 zip) must have the SHA-256 the row records
   (:mod:`davis_ag.benchmark.code_digest`), else the row is not sound: the digests differ;
2. the environment is built from the file's protocol (TVM-v0, TVMContinuous-v0 or RowMapping-v0,
   with its robot), the policy prepared once, and every episode of the row played again from its
   recorded seeds (``SeedSequence([seed, session])`` for the start, ``[seed, session, 1]`` for
   the policy's draws), a model as ``evaluate`` played it (sampled or deterministic, in step);
3. every episode must come out with the recorded actions; the first that does not is named.

Baseline rows need no code: they are ours, and the replay checks their exact expectations.
"""

from __future__ import annotations

import os
import time
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from davis_ag.benchmark.code_digest import code_digest
from davis_ag.benchmark.evaluation import episode_seeds, play_episodes
from davis_ag.benchmark.policies import DETERMINISTIC_PLAY, policy_from_spec, prepare
from davis_ag.benchmark.replay import Difference, same
from davis_ag.errors import UserError


@dataclass(frozen=True)
class RerunReport:
    """What re-running one row found: the episodes played, how long, the first difference."""

    path: str
    policy: str
    spec: str
    episodes: int
    seconds: float
    difference: Difference | None = None

    @property
    def sound(self) -> bool:
        """Whether the code gave every recorded action."""
        return self.difference is None

    def text(self) -> str:
        """One line: re-run sound with the rate, or the first difference."""
        if self.difference is not None:
            return f"{self.path}: {self.policy} not re-run sound with {self.spec}: {self.difference.text()}"
        rate = self.episodes / max(self.seconds, 1e-9)
        return (
            f"{self.path}: {self.policy} re-run sound with {self.spec}: {self.episodes} episodes played again "
            f"with the same actions in {self.seconds:.1f} s ({rate:,.1f} episodes/s)"
        )


def parse_policy_arguments(values: list[str]) -> dict[str, str]:
    """``NAME=SPEC`` arguments as ``{name: spec}``.

    Raises:
        UserError: for one without ``=``, an empty side, or a name given twice.
    """
    chosen: dict[str, str] = {}
    for value in values:
        name, equals, spec = value.partition("=")
        if not equals or not name.strip() or not spec.strip():
            raise UserError(
                f"--policy {value!r}: give NAME=SPEC, the row's name and its code (e.g. mine=my_policy.py:act)"
            )
        if name.strip() in chosen:
            raise UserError(f"--policy {name.strip()} is given twice: give each row's code once")
        chosen[name.strip()] = spec.strip()
    return chosen


def _environment(results: Any, root: Path, cache_dir: Any, robot: str | None) -> Any:
    """The environment the file's protocol describes (its robot, or the YAML given for it)."""
    protocol = results.protocol
    rides = (robot or protocol.robot["name"]) if protocol.robot else None
    if protocol.environment == "davis_ag/RowMapping-v0":
        from davis_ag.mapping.env import RowMappingEnv

        return RowMappingEnv(
            root, protocol.scenario, protocol.split, crop=protocol.crop, cache_dir=cache_dir, budget=protocol.budget,
            seen_fraction=protocol.seen_fraction, robot=rides, budget_s=protocol.budget_s,
        )  # fmt: skip
    if protocol.environment == "davis_ag/TVMContinuous-v0":
        from davis_ag.live.tvm_continuous import TVMContinuousEnv

        return TVMContinuousEnv(
            root, protocol.scenario, protocol.split, crop=protocol.crop, aim=protocol.aim, tau=protocol.tau, robot=rides
        )
    from davis_ag.benchmark.tvm import TVMEnv

    return TVMEnv(
        root, protocol.scenario, protocol.split, crop=protocol.crop, cache_dir=cache_dir, tau=protocol.tau,
        start_rule=protocol.start_rule or "pairs", robot=rides,
    )  # fmt: skip


def _played_actions(env: Any, policy: Any, results: Any, session: int) -> list[list[Any]]:
    """Every episode of one session played again: its actions."""
    protocol = results.protocol
    resets, draws = episode_seeds(protocol.seed, session, protocol.episodes)
    if protocol.environment == "davis_ag/RowMapping-v0":
        from davis_ag.mapping.evaluation import play_episode

        return [play_episode(env, policy, r, d, session).actions for r, d in zip(resets, draws)]
    return [record["actions"] for record in play_episodes(env, policy, resets, draws)]


def rerun_row(
    path: str | os.PathLike[str],
    results: Any,
    root: str | os.PathLike[str],
    name: str,
    spec: str,
    cache_dir: str | os.PathLike[str] | None = None,
    robot: str | None = None,
) -> RerunReport:
    """Play a row's episodes again with the code given for it (see the module docstring).

    Args:
        path: The results file, for messages.
        results: Its results (TVM-v0's, TVMContinuous-v0's or RowMapping-v0's), summaries checked.
        root: The dataset it evaluated.
        name: The row.
        spec: The row's code, as ``evaluate --policy`` takes it.
        cache_dir: The grid's observation cache folder.
        robot: The YAML of the file's robot where it is not built in.

    Raises:
        UserError: for a row the file lacks or that kept no episodes, or code that cannot be
            loaded or fails while it plays (one line each).
    """
    rows = results.policies
    if name not in rows:
        raise UserError(f"{path}: has no row {name!r} (its rows: {', '.join(rows)}); give NAME=SPEC of one of them")
    row = rows[name]
    if not row.episodes or row.digest is None:
        raise UserError(f"{path}: row {name} keeps no episodes or no code digest to re-run: evaluate it again")
    play = getattr(row, "play", None)
    policy = policy_from_spec(spec, name, deterministic=(play == "deterministic") if play else DETERMINISTIC_PLAY)
    began = time.perf_counter()
    digest = code_digest(policy)
    if digest.sha256 != row.digest.sha256:
        stored = f"{row.digest.short()} ({row.digest.of}{', ' + row.digest.file if row.digest.file else ''})"
        found = f"{digest.short()} ({digest.of}{', ' + digest.file if digest.file else ''})"
        return RerunReport(str(path), name, spec, 0, 0.0, Difference(name, "code digest", stored, found))
    env = _environment(results, Path(os.fspath(root)), cache_dir, robot)
    try:
        prepare(policy, env)
        played = 0
        for session in range(results.protocol.sessions):
            recorded = [e.actions for e in row.episodes if e.session == session]
            for episode, (theirs, ours) in enumerate(zip(recorded, _played_actions(env, policy, results, session))):
                played += 1
                if not same(theirs, ours):
                    difference = Difference(name, "actions", theirs, ours, session, episode)
                    return RerunReport(str(path), name, spec, played, time.perf_counter() - began, difference)
    finally:
        close = getattr(env, "close", None)
        if callable(close):
            close()
    return RerunReport(str(path), name, spec, played, time.perf_counter() - began)

"""``davis-ag verify RESULTS.json --dataset DATA``: every episode of a results file played again.

A results file can be consistent with itself and still untrue: episodes edited together with
their summary (:mod:`davis_ag.benchmark.summaries` catches an edited summary, not this). A
leaderboard maintainer therefore replays what was claimed, as EvalAI re-scores submissions:

1. the dataset is the one evaluated (its fingerprint, scene by scene:
   :class:`davis_ag.benchmark.results.DatasetIdentity`), and the environment built on it with the
   file's protocol (its split rule included: none recorded reads as ``scenes``) describes itself as
   the file says (scenes, eligible starts, actions, tau, start rule);
2. episode ``e`` of session ``s`` of every policy resets with the protocol's seed for it
   (:func:`davis_ag.benchmark.evaluation.episode_seeds`), so its scene, start view, target and
   OER_0 must be the recorded ones; then its recorded actions are stepped through the scene's
   move tables, and the path, OER_tau, reward and length must come out as recorded, the episode
   ending exactly at its last action;
3. the exact expectations of every fixed action (and so the Best fixed action's choice) and of
   the image-blind baselines are computed again on the split.

The first difference is named (policy, session, episode, field, stored and replayed value). What
cannot be replayed is the policy's own choice of actions (its code may be anyone's): a row's
actions are taken as played, and the digest of its code (:mod:`davis_ag.benchmark.code_digest`)
says which code claims them. The continuous environment's replay is
:func:`davis_ag.live.replay.replay_continuous`.
"""

from __future__ import annotations

import math
import os
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any, Protocol

from davis_ag.benchmark.results import (
    PROTOCOL_VERSION,
    DatasetIdentity,
    EvaluationResults,
    dataset_identity,
    scene_identity,
)
from davis_ag.errors import UserError

#: How far a replayed number may be from the stored one (the tables hold float32; JSON keeps
#: every float exactly, so this only forgives another summation order).
TOLERANCE = 1e-9


@dataclass(frozen=True)
class Difference:
    """Where a results file and its replay first part: ``policy`` is empty for the dataset or the
    environment, ``session`` and ``episode`` are None where no episode is meant."""

    policy: str
    field: str
    stored: Any
    replayed: Any
    session: int | None = None
    episode: int | None = None

    def text(self) -> str:
        """One line: where, which field, both values."""
        where = self.policy
        if self.session is not None:
            where += f" session {self.session} episode {self.episode}"
        where = f"{where}: " if where else ""
        return f"{where}{self.field} is {_shown(self.stored)} in the file, {_shown(self.replayed)} replayed"


@dataclass(frozen=True)
class ReplayReport:
    """What a replay found: the episodes and policies replayed, how long it took, the first difference."""

    path: str
    episodes: int
    policies: int
    seconds: float
    difference: Difference | None = None

    @property
    def sound(self) -> bool:
        """Whether every episode (and the dataset) came out as recorded."""
        return self.difference is None

    def text(self) -> str:
        """One line: sound with the rate, or the first difference."""
        if self.difference is not None:
            return f"{self.path}: not sound: {self.difference.text()}"
        rate = self.episodes / max(self.seconds, 1e-9)
        return (
            f"{self.path}: sound: {self.episodes} episodes of {self.policies} policies replayed on the "
            f"dataset in {self.seconds:.1f} s ({rate:,.0f} episodes/s)"
        )


class DifferenceFound(Exception):
    """A difference, raised from deep in a replay (:func:`expect`) to its top."""

    def __init__(self, difference: Difference) -> None:
        super().__init__(difference.text())
        self.difference = difference


def same(stored: Any, replayed: Any, tolerance: float = TOLERANCE) -> bool:
    """Whether two recorded values agree (numbers within ``tolerance``, lists item by item)."""
    if isinstance(stored, (list, tuple)) and isinstance(replayed, (list, tuple)):
        return len(stored) == len(replayed) and all(same(a, b, tolerance) for a, b in zip(stored, replayed))
    numbers = (int, float)
    if isinstance(stored, numbers) and isinstance(replayed, numbers) and not isinstance(stored, bool):
        return math.isclose(float(stored), float(replayed), rel_tol=tolerance, abs_tol=tolerance)
    return bool(stored == replayed)


def expect(
    stored: Any,
    replayed: Any,
    policy: str,
    field: str,
    session: int | None = None,
    episode: int | None = None,
    tolerance: float = TOLERANCE,
) -> None:
    """Raise the difference when ``stored`` and ``replayed`` disagree."""
    if not same(stored, replayed, tolerance):
        raise DifferenceFound(Difference(policy, field, stored, replayed, session, episode))


def check_replayable(results: Any, where: str, environment: str, version: int = PROTOCOL_VERSION) -> None:
    """Refuse, in one line, a file that cannot be replayed: of another protocol version than
    ``version`` (the environment's), without its dataset's identity or its episodes, or of another
    environment than ``environment``.

    Raises:
        UserError: naming the file and what to do.
    """
    protocol = results.protocol
    if protocol.version != version:
        raise UserError(
            f"{where}: written with protocol version {protocol.version}, this davis-ag plays version "
            f"{version}: evaluate again to verify it"
        )
    if results.dataset is None:
        raise UserError(f"{where}: records no dataset identity to check: evaluate again with this davis-ag")
    if protocol.environment != environment:
        raise UserError(f"{where}: results of {protocol.environment}, not {environment}")
    missing = [name for name, policy in results.policies.items() if not policy.episodes]
    if missing:
        raise UserError(f"{where}: {missing[0]} kept no episodes to replay: evaluate it again keeping them")


class Identified(Protocol):
    """Any results file that records the dataset it evaluated (TVM's, row mapping's)."""

    dataset: DatasetIdentity | None


def dataset_difference(results: Identified, root: str | os.PathLike[str]) -> Difference | None:
    """Whether ``root`` is the dataset the file evaluated: None, or the first scene that differs."""
    from davis_ag.benchmark.splits import as_dataset

    dataset = as_dataset(root)
    found = dataset_identity([scene_identity(s.id, s.metadata) for s in dataset.scenes])
    stored = results.dataset
    assert stored is not None  # check_replayable
    if found.fingerprint == stored.fingerprint:
        return None
    theirs = {s.id: s for s in found.scenes}
    for scene in stored.scenes:
        other = theirs.get(scene.id)
        if other is None:
            return Difference("", f"scene {scene.id}", "evaluated", "not in the dataset")
        if other != scene:
            field = next(k for k in ("seed", "code", "drawn") if getattr(scene, k) != getattr(other, k))
            return Difference("", f"dataset scene {scene.id} {field}", getattr(scene, field), getattr(other, field))
    return Difference("", "dataset fingerprint", stored.fingerprint, found.fingerprint)


def replay_grid(
    results: EvaluationResults,
    root: str | os.PathLike[str],
    where: str,
    cache_dir: str | os.PathLike[str] | None = None,
    robot: str | None = None,
) -> ReplayReport:
    """Replay a TVM-v0 results file on the dataset at ``root`` (see the module docstring).

    Args:
        results: The results, their summaries checked already (:func:`davis_ag.benchmark.results.load_results`).
        root: The dataset folder.
        where: The file, for messages.
        cache_dir: The observation cache folder, as evaluate took it.
        robot: The robot's YAML file, for a file evaluated with a robot of one (a built-in robot is
            found by the name the file records).

    Returns:
        The report: sound, or the first difference.

    Raises:
        UserError: for a file that cannot be replayed (:func:`check_replayable`) or a dataset
            that is not one.
    """
    from davis_ag.benchmark.tvm import TVMEnv

    recorded = results.protocol.robot
    if robot is not None and recorded is None:
        raise UserError(f"{where} was evaluated without a robot; verify it without --robot")

    def make_env(protocol: Any) -> TVMEnv:
        return TVMEnv(
            root,
            protocol.scenario,
            protocol.split,
            crop=protocol.crop,
            cache_dir=cache_dir,
            tau=protocol.tau,
            start_rule=protocol.start_rule or "pairs",
            split_rule=protocol.split_rule or "scenes",  # a file from before the rules: scenes
            robot=robot or (recorded["name"] if recorded else None),
        )

    keys = ("scenario", "split", "tau", "scenes", "actions", "start_rule", "starts", "robot")
    return replay_on(results, root, where, "davis_ag/TVM-v0", make_env, keys, _replay_episode, before=_replay_exact)


def replay_on(
    results: Any,
    root: str | os.PathLike[str],
    where: str,
    environment: str,
    make_env: Callable[[Any], Any],
    keys: tuple[str, ...],
    replay_episode: Callable[..., None],
    before: Callable[[Any, Any], None] | None = None,
    version: int = PROTOCOL_VERSION,
) -> ReplayReport:
    """The replay every environment shares: the file checked (:func:`check_replayable`) and its
    dataset compared (:func:`dataset_difference`); then ``make_env(protocol)``, the protocol's
    ``keys`` against its ``describe()``, ``before(results, env)`` (the grid's exact expectations)
    and ``replay_episode`` on every episode of every policy; the environment is closed after.

    Args:
        results: The results file, read (TVM-v0's, TVMContinuous-v0's or RowMapping-v0's).
        root: The dataset folder.
        where: The file, for messages.
        environment: The environment id the file must name (``davis_ag/TVM-v0``, ...).
        make_env: Builds the environment from the file's protocol.
        keys: The protocol fields the environment's ``describe()`` must repeat.
        replay_episode: Plays one recorded episode again; raises on the first difference.
        before: Checks run once before the episodes (the grid's exact expectations), or None.
        version: The protocol version this davis-ag plays for the environment.

    Returns:
        The report: sound, or the first difference.

    Raises:
        UserError: for a file that cannot be replayed or a dataset that is not one.
    """
    check_replayable(results, where, environment, version)
    began = time.perf_counter()
    count = sum(len(p.episodes or []) for p in results.policies.values())
    difference = dataset_difference(results, root)
    if difference is None:
        difference = _replay_episodes(make_env(results.protocol), results, keys, replay_episode, before)
    return ReplayReport(where, count, len(results.policies), time.perf_counter() - began, difference)


def _replay_episodes(
    env: Any,
    results: Any,
    keys: tuple[str, ...],
    replay_episode: Callable[..., None],
    before: Callable[[Any, Any], None] | None,
) -> Difference | None:
    protocol = results.protocol
    try:
        described = env.describe()
        for key in keys:
            expect(getattr(protocol, key), described[key], "", f"protocol {key}")
        if before is not None:
            before(results, env)
        for name, policy in results.policies.items():
            for index, episode in enumerate(policy.episodes or []):
                replay_episode(env, name, episode.model_dump(), index, protocol.seed, protocol.episodes)
    except DifferenceFound as found:
        return found.difference
    finally:
        env.close()
    return None


def _replay_episode(env: Any, name: str, stored: dict[str, Any], index: int, seed: int, per_session: int) -> None:
    """Play one recorded episode again: its seeded start, then its actions."""
    from davis_ag.benchmark.evaluation import episode_seeds

    session, episode = divmod(index, per_session)

    def check(field: str, replayed: Any) -> None:
        expect(stored[field], replayed, name, field, session, episode)

    _, info = env.reset(seed=episode_seeds(seed, session, per_session)[0][episode])
    check("scene", info["scene"])
    check("target_fruit", info["target_fruit"])
    expect(stored["path"][:1], info["path"][:1], name, "path[0] (the start view)", session, episode)
    check("oer_0", info["oer_0"])
    reward, ended = 0.0, False
    for step, action in enumerate(stored["actions"]):
        if ended:
            expect(stored["length"], step, name, "length (the episode ended)", session, episode)
        if not isinstance(action, int) or not 0 <= action < env.action_space.n:
            expect(action, f"an action in 0..{env.action_space.n - 1}", name, f"actions[{step}]", session, episode)
        _, gained, terminated, truncated, info = env.step(action)
        reward += float(gained)
        ended = terminated or truncated
    if not ended:
        expect(len(stored["actions"]), "more actions (the episode had not ended)", name, "length", session, episode)
    check("path", info["path"])
    check("oer_tau", info["oer_t"])
    check("reward", reward)
    check("length", len(stored["actions"]))


def _replay_exact(results: EvaluationResults, env: Any) -> None:
    """The exact expectations of every fixed action and of the image-blind baselines, made again."""
    from davis_ag.benchmark import exact
    from davis_ag.benchmark.agents import AGENT_NAMES, build_agents

    if results.fixed_actions is not None:
        fixed = exact.fixed_action_expectations(env)
        for action, metrics in results.fixed_actions.items():
            expect(metrics, fixed.get(action), "", f"fixed_actions.{action}")
        best = results.policies.get(exact.BEST_FIXED)
        if best is not None:
            expect(best.action, exact.best_fixed_action(fixed), exact.BEST_FIXED, "action")
    for name, policy in results.policies.items():
        if policy.exact is None or name not in AGENT_NAMES:
            continue
        probs = exact.agent_probabilities(build_agents([name])[0], env)
        if probs is not None:
            made = exact.expected_metrics(env, probs)
            for key, value in policy.exact.items():
                expect(value, made.get(key), name, f"exact.{key}")


def _shown(value: Any) -> str:
    return repr(round(value, 6)) if isinstance(value, float) else str(value)

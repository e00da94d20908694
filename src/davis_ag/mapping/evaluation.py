"""Score policies on row mapping, and replay a mapping results file on its dataset.

The protocol is TVM-v0's (:mod:`davis_ag.benchmark.evaluation`): ``sessions`` sessions of
``episodes`` episodes, episode ``e`` of session ``s`` reset with ``SeedSequence([seed, s])``'s
``e``-th state and the policy's own randomness with ``SeedSequence([seed, s, 1])``'s, so every
policy maps from the same starts. Beside the policies the results hold each scene's segment: its
fruit, the grid's ceiling, and per part of the move graph (an alley) its ceiling and the budget's
coverage bound (:mod:`davis_ag.mapping.bound`).

The replay (``davis-ag verify``) checks the dataset's identity, builds the environment with the
file's protocol, resets each episode with its seed (scene, start and start part must agree), steps
the recorded actions and requires the same path and the same fruit first seen at every step;
the segments' ceilings and bounds are computed again.
"""

from __future__ import annotations

import os
from collections.abc import Sequence
from typing import Any

import numpy as np

from davis_ag.benchmark.code_digest import code_digest
from davis_ag.benchmark.evaluation import episode_seeds
from davis_ag.benchmark.policies import Policy, as_policies, prepare
from davis_ag.benchmark.replay import Difference, DifferenceFound, ReplayReport, expect, replay_on
from davis_ag.benchmark.results import identify_dataset
from davis_ag.environments import MAPPING_ID
from davis_ag.errors import UserError
from davis_ag.mapping.baselines import BASELINES, FixedMove, build_baselines
from davis_ag.mapping.bound import best_views
from davis_ag.mapping.coverage import SEEN_FRACTION
from davis_ag.mapping.env import RowMappingEnv
from davis_ag.mapping.results import (
    MAPPING_PROTOCOL_VERSION,
    MappingEpisode,
    MappingPolicyResult,
    MappingProtocol,
    MappingResults,
    PartBound,
    SceneSegment,
    summarise,
)
from davis_ag.provenance import code_version


def scene_segments(env: RowMappingEnv) -> dict[str, SceneSegment]:
    """Each scene's segment: fruit, the ceiling of every view an episode may use (with a robot, the
    views it reaches), and each start part's ceiling and bound."""
    segments = {}
    for scene, coverage, starts in zip(env.scenes, env.coverage, env.start_views):
        parts = []
        for index in np.unique(coverage.part[starts]):
            views = coverage.part_views(int(index))
            bound = best_views(coverage.seen[views], env.budget + 1)
            ceiling = int(coverage.seen[views].any(axis=0).sum())
            parts.append(
                PartBound(index=int(index), views=len(views), ceiling=ceiling, bound=bound.fruit, exact=bound.exact)
            )
        # Over every view an episode may use: the grid's, or with a robot the views it reaches.
        segments[scene.id] = SceneSegment(
            fruit=coverage.fruit, ceiling=int(coverage.seen[starts].any(axis=0).sum()), parts=parts
        )
    return segments


def _start_record(env: RowMappingEnv, session: int, info: dict[str, Any]) -> dict[str, Any]:
    coverage = env.coverage[env.scene_index]
    part = int(coverage.part[env.current_view])
    return {
        "session": session,
        "scene": info["scene"],
        "fruit": coverage.fruit,
        "part": part,
        "part_ceiling": int(coverage.seen[coverage.part_views(part)].any(axis=0).sum()),
        "seen_0": len(info["seen"]),
    }


def play_episode(env: Any, policy: Policy, reset_seed: int, policy_seed: int, session: int) -> MappingEpisode:
    """Play one episode; the policy was prepared for ``env`` before.

    Raises:
        UserError: when the policy fails or answers with something that is not a move.
    """
    inner: RowMappingEnv = env.unwrapped
    obs, info = env.reset(seed=reset_seed)
    policy.reset(policy_seed)
    start = _start_record(inner, session, info)
    gains: list[int] = []
    actions: list[int] = []
    step_seconds: list[float] = []
    while True:
        try:
            action = policy.act(obs, info)
            if isinstance(action, str):
                action = inner.action_for(action)
            obs, _, terminated, truncated, info = env.step(action)
        except UserError as error:
            raise UserError(f"policy {policy.name}: {error}") from None
        except Exception as error:  # a user's policy: one line, not a traceback
            raise UserError(f"policy {policy.name} failed: {type(error).__name__}: {error}") from None
        actions.append(int(np.asarray(action).reshape(())))
        gains.append(int(info["new"]))
        if "robot" in info:
            step_seconds.append(float(info["robot"]["seconds"]))
        if terminated or truncated:
            break
    robot = "robot" in info
    return MappingEpisode(
        **start,
        gains=gains,
        path=list(info["path"]),
        actions=actions,
        seconds=float(info["robot"]["seconds_total"]) if robot else None,
        step_seconds=step_seconds if robot else None,
    )


#: The row of the best policy that always makes one move.
BEST_FIXED_MOVE = "Best fixed move"


def best_fixed_move(env: Any, episodes: int, sessions: int, seed: int) -> FixedMove:
    """Of the policies that always make the same move, the one with the highest mean coverage on
    these episodes, named :data:`BEST_FIXED_MOVE` (the move it makes is in its ``source``)."""
    inner: RowMappingEnv = env.unwrapped
    best, best_coverage = inner.action_names[0], -1.0
    for move in inner.action_names:
        policy = FixedMove(move)
        coverages = []
        for session in range(sessions):
            resets, draws = episode_seeds(seed, session, episodes)
            for r, d in zip(resets, draws):
                episode = play_episode(env, policy, r, d, session)
                coverages.append((episode.seen_0 + sum(episode.gains)) / episode.fruit)
        if float(np.mean(coverages)) > best_coverage:
            best, best_coverage = move, float(np.mean(coverages))
    return FixedMove(best, name=BEST_FIXED_MOVE)


def evaluate_mapping_policies(
    env: Any,
    policies: Sequence[Policy],
    episodes: int = 200,
    sessions: int = 3,
    seed: int = 0,
    best_fixed: bool = False,
) -> MappingResults:
    """Run every policy on the same starts and summarise (see the module docstring).

    Args:
        env: RowMappingEnv (wrapped or not).
        policies: The policies, names distinct.
        episodes, sessions, seed: The protocol.
        best_fixed: Add the :data:`BEST_FIXED_MOVE` row, so that a learner that collapsed to one
            move is seen beside the best such policy.

    Raises:
        UserError: for two policies of one name, or a policy that does not fit the environment.
    """
    inner: RowMappingEnv = env.unwrapped
    policies = list(policies)
    if best_fixed:
        policies.append(best_fixed_move(env, episodes, sessions, seed))
    names = [p.name for p in policies]
    if len(set(names)) != len(names):
        twice = next(n for n in names if names.count(n) > 1)
        raise UserError(f"two policies are named {twice!r}: give one another name (--name)")
    for policy in policies:
        prepare(policy, env)
    protocol = MappingProtocol(
        version=MAPPING_PROTOCOL_VERSION, episodes=episodes, sessions=sessions, seed=seed, **inner.describe()
    )
    segments = scene_segments(inner)
    rows = {}
    for policy in policies:
        played = []
        for session in range(sessions):
            resets, draws = episode_seeds(seed, session, episodes)
            played += [play_episode(env, policy, r, d, session) for r, d in zip(resets, draws)]
        row = summarise(played, inner.budget, sessions, segments)
        row.update(source=getattr(policy, "source", None), digest=code_digest(policy), episodes=played)
        rows[policy.name] = MappingPolicyResult.model_validate(row)
    return MappingResults(
        protocol=protocol,
        dataset=identify_dataset(protocol.dataset),
        code=code_version(),
        segments=segments,
        policies=rows,
    )


def evaluate_mapping(
    policies: Sequence[Any],
    dataset: Any,
    scenario: str = "row",
    split: str = "test",
    sessions: int = 3,
    episodes: int = 200,
    seed: int = 0,
    *,
    crop: str | None = None,
    baselines: bool | list[str] = True,
    deterministic: bool | None = None,
    cache_dir: str | os.PathLike[str] | None = None,
    budget: int | None = None,
    seen_fraction: float = SEEN_FRACTION,
    robot: str | None = None,
    budget_s: float | None = None,
) -> MappingResults:
    """Score policies beside the mapping baselines (``davis-ag evaluate --task mapping``).

    Args:
        policies: Policies, callables or SPEC strings (as :func:`davis_ag.benchmark.evaluate` takes them).
        dataset: A dataset root or an opened dataset.
        scenario: ``row`` (default) or ``mp``.
        split: ``test`` (default), ``train`` or ``all``.
        sessions: Sessions of the protocol.
        episodes: Episodes per session.
        seed: The protocol's seed.
        crop: Keep one crop.
        baselines: True: Sweep, Rand and Greedy; False: none; or a list of names. With any, the
            best fixed move's row too.
        deterministic: How SPEC models play (default: the benchmark's).
        cache_dir: The observation cache folder.
        budget: Moves per episode (default: the sweep's length).
        seen_fraction: The visible fraction a sighting needs.
        robot: A robot (name or YAML) the camera rides on.
        budget_s: With a robot, the seconds an episode may spend.

    Returns:
        The results, exactly what ``--out`` writes.
    """
    import gymnasium as gym

    from davis_ag.benchmark.policies import DETERMINISTIC_PLAY
    from davis_ag.environments import MAPPING_ID

    play = DETERMINISTIC_PLAY if deterministic is None else deterministic
    chosen = as_policies(policies, play)
    if baselines:
        chosen += build_baselines(list(BASELINES) if baselines is True else list(baselines))
    made = gym.make(
        MAPPING_ID,
        disable_env_checker=True,
        dataset=dataset,
        scenario=scenario,
        split=split,
        crop=crop,
        cache_dir=cache_dir,
        budget=budget,
        seen_fraction=seen_fraction,
        robot=robot,
        budget_s=budget_s,
    )
    try:
        results = evaluate_mapping_policies(
            made, chosen, episodes=episodes, sessions=sessions, seed=seed, best_fixed=bool(baselines)
        )
    finally:
        made.close()
    results.protocol.crop = crop
    return results


def replay_mapping(
    results: MappingResults,
    root: str | os.PathLike[str],
    where: str,
    cache_dir: str | os.PathLike[str] | None = None,
    robot: str | None = None,
) -> ReplayReport:
    """Replay a mapping results file on the dataset at ``root`` (see the module docstring), through
    the replay every environment shares (:func:`davis_ag.benchmark.replay.replay_on`).

    Args:
        results: The results, summaries checked already (:func:`davis_ag.mapping.results.load_mapping_results`).
        root: The dataset folder.
        where: The file's name, for messages.
        cache_dir: The observation cache folder.
        robot: The YAML of the file's robot where it is not built in.

    Raises:
        UserError: for a file of another protocol version or without its dataset's identity.
    """

    def make_env(protocol: MappingProtocol) -> RowMappingEnv:
        return RowMappingEnv(
            root, protocol.scenario, protocol.split, crop=protocol.crop, cache_dir=cache_dir, budget=protocol.budget,
            seen_fraction=protocol.seen_fraction, robot=(robot or protocol.robot["name"]) if protocol.robot else None,
            budget_s=protocol.budget_s,
        )  # fmt: skip

    def segments(stored: MappingResults, env: RowMappingEnv) -> None:
        fresh = scene_segments(env)
        for scene, segment in stored.segments.items():
            expect(
                segment.model_dump(), fresh[scene].model_dump() if scene in fresh else None, "", f"segment of {scene}"
            )

    keys = ("scenario", "split", "budget", "budget_s", "seen_fraction", "scenes", "actions", "robot")
    return replay_on(
        results, root, where, MAPPING_ID, make_env, keys, _replay_episode, segments, MAPPING_PROTOCOL_VERSION
    )


def _replay_episode(
    env: RowMappingEnv, name: str, stored: dict[str, Any], index: int, seed: int, per_session: int
) -> None:
    """Play one recorded episode again: its seeded start (scene, fruit, part, what it sees), then its
    moves, which must see the recorded fruit first at every step, along the recorded path."""
    session, episode = divmod(index, per_session)

    def check(field: str, value: Any) -> None:
        expect(stored[field], value, name, field, session, episode)

    _, info = env.reset(seed=episode_seeds(seed, session, per_session)[0][episode])
    start = _start_record(env, session, info)
    for field in ("scene", "fruit", "part", "part_ceiling", "seen_0"):
        check(field, start[field])
    gains, step_seconds = [], []
    terminated = False
    for step, action in enumerate(stored["actions"]):
        if terminated:
            raise DifferenceFound(Difference(name, "actions", len(stored["actions"]), step, session, episode))
        try:
            _, _, terminated, _, info = env.step(action)
        except UserError as error:
            raise DifferenceFound(Difference(name, f"action {step}", action, str(error), session, episode)) from None
        gains.append(int(info["new"]))
        if "robot" in info:
            step_seconds.append(float(info["robot"]["seconds"]))
    check("gains", gains)
    check("path", list(info["path"]))
    if not terminated:
        raise DifferenceFound(Difference(name, "length", len(stored["actions"]), "more moves", session, episode))
    if stored["seconds"] is not None or "robot" in info:
        check("seconds", float(info["robot"]["seconds_total"]) if "robot" in info else None)
        check("step_seconds", step_seconds if "robot" in info else None)

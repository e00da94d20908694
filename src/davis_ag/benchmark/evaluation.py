"""Benchmark any set of policies as in section V-D and Table 4, on TVM-v0 or TVMContinuous-v0.

Protocol: the test split; ``sessions`` (3) sessions of ``episodes`` (200) episodes. Episode
``e`` of session ``s`` resets the environment with a seed drawn from
``numpy.random.SeedSequence([seed, s])``, so every policy plays exactly the same episodes
(same scene, view and target; on the continuous environment the same start pose, slip then
follows the environment's generator); a policy's own randomness is seeded from
``SeedSequence([seed, s, 1])`` so that it never mirrors the environment's draws. Per policy
and session the mean final OER (``OER_tau``), cumulative reward and episode length are taken;
the table reports their mean and standard deviation (population, ``ddof=0``) over sessions.
Beside them: the standard error of each mean over all episodes (``sem``: the per-episode
standard deviation over the square root of the episode count), and, for the grid policies that
ignore the image (LRD, UDD, Rand, fixed actions), the exact expectation over the split's starts
(``exact``, :mod:`davis_ag.benchmark.exact`) that the sampled mean estimates. On the grid the
row :data:`BEST_FIXED` is added (``best_fixed_action``): of the policies that always play the
same action, the one with the highest exact OER_tau on this split, played on the same episodes,
so that a learner that collapsed to one move is seen beside it. Every policy gets its paired
gap (:mod:`davis_ag.benchmark.paired`) to each of :data:`~davis_ag.benchmark.summaries.PAIRED_BASELINES` present.

Policies follow :class:`davis_ag.benchmark.policies.Policy`; a policy may answer with an action
name, which the environment's ``action_for`` turns into its action.
"""

from __future__ import annotations

import importlib
import os
import traceback
from collections.abc import Callable, Sequence
from pathlib import Path
from typing import TYPE_CHECKING, Any, cast

import numpy as np

from davis_ag.benchmark import exact
from davis_ag.benchmark.agents import FixedActionAgent
from davis_ag.benchmark.code_digest import code_digest
from davis_ag.benchmark.lockstep import episode_record, play_lockstep
from davis_ag.benchmark.policies import Policy, prepare
from davis_ag.benchmark.results import (
    PROTOCOL_VERSION,
    EvaluationResults,
    PairedGap,
    PolicyResult,
    Protocol,
    as_results,
    identify_dataset,
)
from davis_ag.benchmark.results_table import METRICS
from davis_ag.benchmark.summaries import (
    action_counts,
    mean_abs_action,
    paired_gaps,
    session_metrics,
)
from davis_ag.errors import UserError
from davis_ag.formats.splits import check_split_rule
from davis_ag.provenance import code_version

if TYPE_CHECKING:
    from davis_ag.data.reader import Dataset

#: The row of the best policy that always plays one action (see the module docstring).
BEST_FIXED = exact.BEST_FIXED


def episode_seeds(seed: int, session: int, episodes: int) -> tuple[list[int], list[int]]:
    """Reset seeds and policy seeds of one session.

    Args:
        seed: The evaluation's base seed.
        session: Session index.
        episodes: Episodes in the session.

    Returns:
        ``(reset_seeds, policy_seeds)``, one each per episode.
    """
    env_seeds = np.random.SeedSequence([seed, session]).generate_state(episodes)
    agent_seeds = np.random.SeedSequence([seed, session, 1]).generate_state(episodes)
    return [int(s) for s in env_seeds], [int(s) for s in agent_seeds]


def _action(env: Any, action: Any) -> Any:
    """A policy's answer as the environment's action (a name through ``action_for``)."""
    if isinstance(action, str):
        return env.unwrapped.action_for(action)
    return action


def _act(policy: Policy, observation: Any, info: dict[str, Any]) -> Any:
    """The policy's answer; a policy that fails is one line naming where (its own code's last frame)."""
    try:
        return policy.act(observation, info)
    except UserError:
        raise
    except Exception as error:
        frame = traceback.extract_tb(error.__traceback__)[-1]
        raise UserError(
            f"act failed with {type(error).__name__}: {error} (at {frame.filename}:{frame.lineno}); "
            "fix the policy and evaluate again"
        ) from None


def run_episode(
    env: Any, policy: Policy, reset_seed: int, policy_seed: int | None = None, prepared: bool = False
) -> dict[str, Any]:
    """Play one episode.

    Args:
        env: A TVM-v0 or TVMContinuous-v0 environment (wrapped or not).
        policy: The policy (its ``prepare(env)`` is called first unless ``prepared``).
        reset_seed: Seed of ``env.reset``; fixes the scene, start and target.
        policy_seed: Seed of the policy's own randomness.
        prepared: Whether the caller has called ``prepare(env)`` already (once for many episodes).

    Returns:
        ``{"oer_0", "oer_tau", "reward", "length", "scene", "target_fruit", "path", "actions"}``,
        and ``"refused"`` (moves refused) where the environment reports them.

    Raises:
        UserError: when the policy answers with something that is not an action here.
    """
    if not prepared:
        prepare(policy, env)
    obs, info = env.reset(seed=reset_seed)
    policy.reset(policy_seed)
    total, actions, refused = 0.0, [], 0
    while True:
        try:
            action = _action(env, _act(policy, obs, info))
            obs, reward, terminated, truncated, info = env.step(action)
        except UserError as error:
            raise UserError(f"policy {policy.name}: {error}") from None
        discrete = hasattr(env.action_space, "n")
        actions.append(
            int(np.asarray(action).reshape(()))
            if discrete
            else [round(float(a), 4) for a in np.asarray(action, dtype=float).reshape(-1)]
        )
        total += float(reward)
        refused += bool(info.get("refused"))
        if terminated or truncated:
            break
    return episode_record(info, total, actions, refused if "refused" in info else None)


def play_episodes(env: Any, policy: Policy, resets: list[int], draws: list[int]) -> list[dict[str, Any]]:
    """Play episode ``i`` from reset seed ``resets[i]`` with policy seed ``draws[i]``: a trained
    model's episodes in step, one forward pass for all (:mod:`davis_ag.benchmark.lockstep`), any
    other policy's one after another; the policy was prepared for ``env`` before.

    Returns:
        One record per episode, as :func:`run_episode` returns it.
    """
    played = play_lockstep(env, policy, resets, draws)
    if played is None:
        played = [run_episode(env, policy, r, d, prepared=True) for r, d in zip(resets, draws)]
    return played


def play_sessions(
    env: Any, policy: Policy, keys: tuple[str, ...], seed: int, sessions: int, episodes: int
) -> tuple[dict[str, Any], list[dict[str, Any]]]:
    """Play ``sessions`` x ``episodes`` seeded episodes (the same for every policy) and summarise;
    the policy was prepared for ``env`` once before (the Policy protocol: not once per episode).

    Returns:
        Per key the mean, std and per-session values over sessions and the standard error of the
        mean over all episodes (``sem``); and every episode's record with its ``session``.
    """
    records: list[dict[str, Any]] = []
    for session in range(sessions):
        env_seeds, policy_seeds = episode_seeds(seed, session, episodes)
        runs = play_episodes(env, policy, env_seeds, policy_seeds)
        records.extend({"session": session, **run} for run in runs)
    summary: dict[str, Any] = session_metrics(records, keys, sessions)
    return summary, records


def evaluate_policies(
    env: Any,
    policies: Sequence[Policy],
    episodes: int = 200,
    sessions: int = 3,
    seed: int = 0,
    keep_episodes: bool = False,
    best_fixed_action: bool = False,
) -> EvaluationResults:
    """Run every policy on the same episodes and summarise as Table 4 (see the module docstring).

    Args:
        env: The environment (TVM-v0 or TVMContinuous-v0, of the split to score on).
        policies: :class:`davis_ag.benchmark.policies.Policy` objects; ``name`` labels the rows
            (names must differ).
        episodes: Episodes per session (200 in the paper).
        sessions: Sessions (3 in the paper).
        seed: Base seed of the episode draw.
        keep_episodes: Keep every episode's record in the results (``davis-ag plot actions``,
            ``episode`` and ``compare`` across files read them).
        best_fixed_action: Add the :data:`BEST_FIXED` row (grid only) and the exact expectations
            of every fixed action.

    Returns:
        The results (:class:`davis_ag.benchmark.results.EvaluationResults`).

    Raises:
        UserError: for two policies of one name, or a policy that does not fit the environment
            (before any episode is played).
    """
    from davis_ag.benchmark.tvm import TVMEnv

    inner = env.unwrapped if hasattr(env, "unwrapped") else env
    grid = isinstance(inner, TVMEnv)
    policies = list(policies)
    fixed = None
    if best_fixed_action and grid:
        fixed = exact.fixed_action_expectations(inner)
        policies.append(FixedActionAgent(exact.best_fixed_action(fixed), name=BEST_FIXED))
    names = [p.name for p in policies]
    if len(set(names)) != len(names):
        twice = next(n for n in names if names.count(n) > 1)
        raise UserError(f"two policies are named {twice!r}: give one another name (--name)")
    for policy in policies:  # a policy made for another scenario is refused before any episode runs
        prepare(policy, env)
    described = inner.describe()
    protocol = Protocol(version=PROTOCOL_VERSION, episodes=episodes, sessions=sessions, seed=seed, **described)
    keys = (*METRICS, "oer_0") + (("refused",) if not grid else ()) + (("seconds",) if inner.robot else ())
    rows: dict[str, dict[str, Any]] = {}
    records: dict[str, list[dict[str, Any]]] = {}
    for policy in policies:
        summary, played = play_sessions(env, policy, keys, seed, sessions, episodes)
        records[policy.name] = played
        summary["source"] = getattr(policy, "source", None)
        summary["digest"] = code_digest(policy)
        if grid:
            summary["action_counts"] = action_counts(played, inner.action_names)
            probs = exact.agent_probabilities(policy, inner)
            if probs is not None:
                summary["exact"] = exact.expected_metrics(inner, probs)
        else:
            summary["mean_abs_action"] = mean_abs_action(played, protocol.actions)
        if isinstance(play := getattr(policy, "play", None), str):
            summary["play"] = play
        if isinstance(policy, FixedActionAgent):
            summary["action"] = policy.action
        if keep_episodes:
            summary["episodes"] = played
        rows[policy.name] = summary
    for name, row in rows.items():
        row["paired"] = {b: PairedGap.model_validate(g) for b, g in paired_gaps(name, records, seed).items()}
    return EvaluationResults(
        protocol=protocol,
        dataset=identify_dataset(protocol.dataset),
        code=code_version(),
        policies={n: PolicyResult.model_validate(r) for n, r in rows.items()},
        fixed_actions=fixed,
    )


def write_json(results: EvaluationResults | dict[str, Any], path: str | os.PathLike[str]) -> Path:
    """Write the results as indented JSON (atomically: temp file then rename)."""
    return as_results(results).write(path)


def evaluate(
    policies: Sequence[Policy | Callable[..., Any] | str | os.PathLike[str]],
    dataset: Dataset | str | os.PathLike[str],
    scenario: str = "sp",
    split: str = "test",
    sessions: int = 3,
    episodes: int = 200,
    seed: int = 0,
    *,
    env: str = "grid",
    crop: str | None = None,
    baselines: bool | list[str] = True,
    deterministic: bool | None = None,
    cache_dir: str | os.PathLike[str] | None = None,
    keep_episodes: bool = True,
    robot: str | None = None,
    split_rule: str = "scenes",
) -> EvaluationResults:
    """Score policies beside the baselines with section V-D's protocol (``davis_ag.benchmark.evaluate``).

    Args:
        policies: Each a :class:`davis_ag.benchmark.policies.Policy`, a callable
            ``(observation, info) -> action``, or a SPEC string (``MODEL.zip``, ``module:attr``,
            ``path/to/file.py:attr``; :func:`davis_ag.benchmark.policies.policy_from_spec`).
        dataset: A dataset root (or an opened dataset, on the grid).
        scenario: ``sp`` or ``mp``.
        split: ``test`` (default), ``train`` or ``all``.
        sessions: Sessions of the protocol (3, as in the paper's setting).
        episodes: Episodes per session (200, as in the paper's setting).
        seed: The protocol's seed (0, as in the paper's setting).
        env: ``grid`` (TVM-v0) or ``continuous`` (TVMContinuous-v0).
        crop: Keep one crop of the scenario.
        baselines: True: the environment's baselines (grid: LRD, UDD, Rand, Oracle and the Best
            fixed action; continuous: LR, UD, Rand, Greedy); False: none; or a list of names.
        deterministic: How SPEC models play (default
            :data:`davis_ag.benchmark.policies.DETERMINISTIC_PLAY`).
        cache_dir: The grid's observation cache folder.
        keep_episodes: Keep every episode in the results.
        robot: A robot (name or YAML) the camera rides on (:mod:`davis_ag.benchmark.robot_moves` on the
            grid, :mod:`davis_ag.live.continuous_robot` on the continuous environment).
        split_rule: ``scenes`` (default), ``starts`` or ``fruits``: which starts ``split`` holds
            (:mod:`davis_ag.formats.splits`); the grid only.

    Returns:
        The results, exactly what ``davis-ag evaluate --out`` writes.

    Raises:
        UserError: for a bad dataset, split, SPEC or a policy that does not fit the environment.
    """
    import gymnasium as gym

    from davis_ag.benchmark.policies import DETERMINISTIC_PLAY, as_policies
    from davis_ag.environments import CONTINUOUS_ID, TVM_ID

    if env not in ENVIRONMENTS:
        raise UserError(f"unknown env {env!r}: choose one of {', '.join(ENVIRONMENTS)}")
    if check_split_rule(split_rule) != "scenes" and env != "grid":
        raise UserError(f"--split-rule {split_rule} splits TVM-v0's starts; --env {env} splits by scenes: leave it out")
    play = DETERMINISTIC_PLAY if deterministic is None else deterministic
    chosen = as_policies(policies, play)
    names, builder = ENVIRONMENTS[env]
    if baselines:
        # By name, as Gymnasium loads an entry point: the continuous baselines are a later stage's.
        module, attr = builder.split(":")
        build = cast("Callable[[list[str]], list[Policy]]", getattr(importlib.import_module(module), attr))
        chosen += build(list(names if baselines is True else baselines))
    kwargs: dict[str, Any] = {"dataset": dataset, "scenario": scenario, "split": split, "crop": crop}
    if env == "grid":
        kwargs["cache_dir"] = cache_dir
        kwargs["split_rule"] = split_rule
    if robot is not None:
        kwargs["robot"] = robot
    made = gym.make(TVM_ID if env == "grid" else CONTINUOUS_ID, disable_env_checker=True, **kwargs)
    try:
        results = evaluate_policies(
            made,
            chosen,
            episodes=episodes,
            sessions=sessions,
            seed=seed,
            keep_episodes=keep_episodes,
            best_fixed_action=env == "grid" and bool(baselines),
        )
    finally:
        made.close()
    results.protocol.crop = crop
    return results


#: The environments :func:`evaluate` knows: their baselines' names and the function (``module:attr``,
#: loaded like a Gymnasium entry point, since the continuous one lives in a later stage) that builds them.
ENVIRONMENTS: dict[str, tuple[tuple[str, ...], str]] = {
    "grid": (("LRD", "UDD", "Rand", "Oracle"), "davis_ag.benchmark.agents:build_agents"),
    "continuous": (("LR", "UD", "Rand", "Greedy"), "davis_ag.live.policies:build_policies"),
}

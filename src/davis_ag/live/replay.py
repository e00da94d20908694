"""Replay a TVMContinuous-v0 results file on its dataset (``davis-ag verify RESULTS.json --dataset DATA``).

As on the grid (:mod:`davis_ag.benchmark.replay`), the dataset must be the one evaluated and the
environment built with the file's protocol must describe itself as the file says. Then each
episode resets with its protocol seed: its scene, target, start pose and OER_0 must be the
recorded ones. Its recorded actions are stepped again (the slip draws follow the seed, as they
did), every pose is drawn again, and each must land where the file says and the final OER,
reward, length and refused moves come out as recorded.

Poses and actions are recorded to 4 decimals, so a replayed pose may differ from the recorded one
by a rounding: within :data:`POSE_TOLERANCE` (metres, degrees), and the target's OER within
:data:`OER_TOLERANCE` (a pixel or two of the 224x224 view).
"""

from __future__ import annotations

import os
from typing import Any

from davis_ag.benchmark.episode_rules import episode_reward
from davis_ag.benchmark.replay import ReplayReport, expect, replay_on
from davis_ag.benchmark.results import EvaluationResults

#: How far a replayed pose may be from the recorded one (metres; degrees for yaw and pitch).
POSE_TOLERANCE = 1e-3
#: How far a replayed OER may be from the recorded one (the pose's rounding moves a pixel or two).
OER_TOLERANCE = 0.01


def replay_continuous(
    results: EvaluationResults, root: str | os.PathLike[str], where: str, robot: str | None = None
) -> ReplayReport:
    """Replay a TVMContinuous-v0 results file on the dataset at ``root`` (see the module docstring);
    with the file's robot (``robot``: its YAML where it is not built in).

    Raises:
        UserError: for a file that cannot be replayed or a dataset that is not one.
    """
    from davis_ag.live.tvm_continuous import TVMContinuousEnv

    def make_env(protocol: Any) -> TVMContinuousEnv:
        rides = (robot or protocol.robot["name"]) if protocol.robot else None
        return TVMContinuousEnv(
            root, protocol.scenario, protocol.split, crop=protocol.crop, aim=protocol.aim, tau=protocol.tau, robot=rides
        )

    keys = ("scenario", "split", "tau", "aim", "scenes", "actions", "robot")
    return replay_on(results, root, where, "davis_ag/TVMContinuous-v0", make_env, keys, _replay_episode)


def _replay_episode(env: Any, name: str, stored: dict[str, Any], index: int, seed: int, per_session: int) -> None:
    """Play one recorded episode again: its seeded start, then its actions, every pose drawn."""
    from davis_ag.benchmark.evaluation import episode_seeds

    session, episode = divmod(index, per_session)

    def check(field: str, replayed: Any, tolerance: float = 0.0) -> None:
        expect(stored[field], replayed, name, field, session, episode, tolerance or 1e-9)

    _, info = env.reset(seed=episode_seeds(seed, session, per_session)[0][episode])
    check("scene", info["scene"])
    check("target_fruit", info["target_fruit"])
    expect(stored["path"][:1], info["path"][:1], name, "path[0] (the start pose)", session, episode)
    check("oer_0", info["oer_0"])
    refused, ended = 0, False
    for step, action in enumerate(stored["actions"]):
        if ended:
            expect(stored["length"], step, name, "length (the episode ended)", session, episode)
        _, _, terminated, truncated, info = env.step(action)
        refused += bool(info.get("refused"))
        pose = info["path"][-1]
        expect(stored["path"][step + 1 : step + 2], [pose], name, f"path[{step + 1}]", session, episode, POSE_TOLERANCE)
        ended = terminated or truncated
    if not ended:
        expect(len(stored["actions"]), "more actions (the episode had not ended)", name, "length", session, episode)
    check("path", info["path"], POSE_TOLERANCE)
    check("oer_tau", info["oer_t"], OER_TOLERANCE)
    check("reward", episode_reward(info["oer_0"], info["oer_t"]), OER_TOLERANCE)
    check("length", len(stored["actions"]))
    if stored.get("refused") is not None:
        check("refused", refused)

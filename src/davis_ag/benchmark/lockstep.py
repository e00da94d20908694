"""Many episodes of one trained model played in step: one forward pass of its network for all.

Why: the paper's network has 36M weights, nearly all in its first dense layer (143 MB read on
every forward pass). One observation at a time, reading them is most of a pass; a batch reads
them once for all its observations. Every evaluation of a model and every train-split score that
picks a training run's snapshot (:mod:`davis_ag.benchmark.selection`) plays sessions of 200
episodes, so they play them in step; ``davis-ag bench --only play`` measures the gain
(docs/performance.md).

The episodes are those :func:`davis_ag.benchmark.evaluation.run_episode` plays one after another:
the same reset seeds, and each episode's actions drawn from a torch generator seeded with its
policy seed, as :meth:`ModelPolicy.reset` seeds torch's own (:meth:`ModelPolicy.act_batch`). The
records are the same but where a batch's forward pass rounds a probability differently in its
last bit and a draw falls within that bit of a boundary between two actions (the tests play both
ways on the CPU and compare; on a GPU each generator is the device's, seeded as torch seeds its
own, which no test here can run). This applies to a :class:`ModelPolicy` that batches on TVM-v0,
bare or under Gymnasium's own wrappers that change nothing an episode sees; any other policy or
environment plays one episode at a time.
"""

from __future__ import annotations

from typing import Any

from gymnasium.wrappers import OrderEnforcing, PassiveEnvChecker

from davis_ag.benchmark.policies import ModelPolicy
from davis_ag.benchmark.tvm import TVMEnv

#: Episodes in one forward pass at most (a session's 200 fit: about 160 MB of float input).
BATCH = 256
#: Wrappers that change no observation, reward or ending, so the bare environment plays as they do.
TRANSPARENT_WRAPPERS = (OrderEnforcing, PassiveEnvChecker)


def episode_record(
    info: dict[str, Any], total: float, actions: list[Any], refused: int | None = None
) -> dict[str, Any]:
    """What an evaluation keeps of one episode, from its last ``info``.

    Returns:
        ``{"oer_0", "oer_tau", "reward", "length", "scene", "target_fruit", "path", "actions"}``,
        ``"refused"`` where it is given and ``"seconds"`` where a robot moved the camera.
    """
    record = {
        "oer_0": float(info["oer_0"]),
        "oer_tau": float(info["oer_t"]),
        "reward": total,
        "length": len(actions),
        "scene": info["scene"],
        "target_fruit": int(info["target_fruit"]),
        "path": list(info["path"]),
        "actions": actions,
    }
    if refused is not None:
        record["refused"] = refused
    if "robot" in info:  # TVM-v0 with a robot: the seconds its moves took
        record["seconds"] = float(info["robot"]["seconds_total"])
    return record


def bare_grid(env: Any) -> TVMEnv | None:
    """The TVM-v0 environment under ``env`` when every wrapper around it is transparent, else None."""
    while not isinstance(env, TVMEnv):
        if not isinstance(env, TRANSPARENT_WRAPPERS):
            return None
        env = env.env
    return env


def play_lockstep(env: Any, policy: Any, resets: list[int], draws: list[int]) -> list[dict[str, Any]] | None:
    """Play episode ``i`` from ``env.reset(seed=resets[i])`` with policy seed ``draws[i]``, all in step.

    The policy was prepared for ``env`` before (the Policy protocol).

    Returns:
        One record per episode (:func:`episode_record`), in order; None when this policy or
        environment does not play in step (see the module docstring), for the caller to play
        one at a time.
    """
    grid = bare_grid(env)
    if grid is None or not isinstance(policy, ModelPolicy) or not policy.batches:
        return None
    records: list[dict[str, Any]] = []
    for lo in range(0, len(resets), BATCH):
        records += _play_batch(grid, policy, resets[lo : lo + BATCH], draws[lo : lo + BATCH])
    return records


def _play_batch(grid: TVMEnv, policy: ModelPolicy, resets: list[int], draws: list[int]) -> list[dict[str, Any]]:
    envs = [grid.fork() for _ in resets]
    started = [e.reset(seed=seed) for e, seed in zip(envs, resets)]
    observations = [obs for obs, _ in started]
    infos = [info for _, info in started]
    streams = policy.streams(draws)
    actions: list[list[Any]] = [[] for _ in envs]
    totals = [0.0] * len(envs)
    playing = list(range(len(envs)))
    while playing:
        chosen = policy.act_batch([observations[i] for i in playing], [streams[i] for i in playing])
        still = []
        for i, action in zip(playing, chosen):
            observations[i], reward, terminated, truncated, infos[i] = envs[i].step(action)
            actions[i].append(action)
            totals[i] += float(reward)
            if not (terminated or truncated):
                still.append(i)
        playing = still
    return [episode_record(info, total, acts) for info, total, acts in zip(infos, totals, actions)]

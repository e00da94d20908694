"""The Gymnasium ids of davis-ag's environments, registered by name so that nothing loads until one is made.

Registration names each environment's class as a ``"module:Class"`` string: registering imports
Gymnasium's registry, not the benchmark (numpy caches, torch) nor the live renderer (Helios).
``import davis_ag`` registers them when Gymnasium is already imported (``import gymnasium`` first,
as the README does); ``import davis_ag.benchmark`` always does, and so does
``gymnasium.make("davis_ag:davis_ag/TVM-v0")`` (Gymnasium imports the module before the id).
"""

from __future__ import annotations

#: The grid environment (:class:`davis_ag.benchmark.tvm.TVMEnv`).
TVM_ID = "davis_ag/TVM-v0"
#: The continuous-pose environment (:class:`davis_ag.live.tvm_continuous.TVMContinuousEnv`).
CONTINUOUS_ID = "davis_ag/TVMContinuous-v0"
#: Every environment id and its class, as Gymnasium's ``"module:Class"`` entry point.
ENTRY_POINTS: dict[str, str] = {
    TVM_ID: "davis_ag.benchmark.tvm:TVMEnv",
    CONTINUOUS_ID: "davis_ag.live.tvm_continuous:TVMContinuousEnv",
}


def register_environments() -> None:
    """Register every davis-ag environment with Gymnasium (again: a no-op)."""
    from gymnasium.envs.registration import register, registry

    for env_id, entry_point in ENTRY_POINTS.items():
        if env_id not in registry:
            # No max_episode_steps: the environments end their own episodes at tau with
            # terminated=True (a TimeLimit would report truncated and make learners bootstrap past
            # the final reward).
            register(id=env_id, entry_point=entry_point)

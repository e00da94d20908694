"""``davis-ag bench --only play``: what a trained model's episodes cost, one at a time against in
step (:mod:`davis_ag.benchmark.lockstep`), and that both play the same episodes.

One session of section V-D's protocol (200 episodes) of an A2C model with the paper's network,
played twice in this process on a single-plant strawberry scene drawn here: one forward pass per
step of each episode, then one forward pass per step of all the episodes. The model is untrained
(what a forward pass costs does not depend on its weights; an untrained model ends its episodes
early on ``done`` more often than a trained one, so the episodes/s are a trained model's upper
bound and the ratio is what to read). Every evaluation of a model and every train-split score
that picks a training run's snapshot plays this way.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import write_marked_section
from davis_ag.workflows.bench.report import doc_section

#: The dataset seed and the image size of the scene (the observation is 224x224 whatever the size).
SEED = 0
SIZE = (160, 90)
#: One session of the paper's protocol.
EPISODES = 200


def play_speed(scratch: Path) -> dict[str, Any]:
    """Draw the scene, then play the model's episodes both ways, each timed.

    Returns:
        The episodes and steps played, each way's seconds and episodes per second, the ratio, and
        whether the two ways played the same episodes.

    Raises:
        RuntimeError: when they did not (a bench of a speed-up that changes results measures nothing).
    """
    from stable_baselines3 import A2C

    from davis_ag.benchmark import TVMEnv
    from davis_ag.benchmark.evaluation import episode_seeds, run_episode
    from davis_ag.benchmark.lockstep import play_lockstep
    from davis_ag.benchmark.networks import ARCHITECTURES
    from davis_ag.benchmark.policies import ModelPolicy, prepare
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.scene.camera import Camera
    from davis_ag.scene.specs import CROPS, scenario_spec
    from davis_ag.workflows.stages import generate_scenes

    crop = CROPS["strawberry"]
    root = scratch / "play"
    generate_scenes([SceneRequest(scenario_spec("sp", crop), crop, 0, SEED, Camera(*SIZE))], root, progress=False)
    env = TVMEnv(root, "sp", split="all")
    model = A2C("CnnPolicy", env, seed=SEED, device="cpu", policy_kwargs=dict(ARCHITECTURES["paper"]))
    policy = ModelPolicy(model)
    prepare(policy, env)
    resets, draws = episode_seeds(SEED, 0, EPISODES)
    began = time.perf_counter()
    alone = [run_episode(env, policy, r, d, prepared=True) for r, d in zip(resets, draws)]
    one_at_a_time = time.perf_counter() - began
    began = time.perf_counter()
    together = play_lockstep(env, policy, resets, draws)
    in_step = time.perf_counter() - began
    if together != alone:
        raise RuntimeError("the episodes played in step differ from those played one at a time")
    return {
        "episodes": EPISODES,
        "steps": sum(r["length"] for r in alone),
        "parameters": sum(p.numel() for p in model.policy.parameters()),
        "one_at_a_time_s": round(one_at_a_time, 2),
        "in_step_s": round(in_step, 2),
        "one_at_a_time_episodes_per_second": round(EPISODES / one_at_a_time, 1),
        "in_step_episodes_per_second": round(EPISODES / in_step, 1),
        "gain": round(one_at_a_time / in_step, 1),
        "same_episodes": True,
    }


def play_table(result: dict[str, Any], load: tuple[float, float]) -> str:
    """The two ways' times as Markdown."""
    return (
        f"{result['episodes']} episodes ({result['steps']} steps) of an A2C model with the paper's network "
        f"({result['parameters']:,} weights, untrained) on a single-plant strawberry scene, seed {SEED}, "
        f"on the CPU; the two ways played the same episodes; load average {load[0]:.2f} at the start, "
        f"{load[1]:.2f} at the end, {os.cpu_count()} CPUs.\n\n"
        "| play | seconds | episodes/s | against one at a time |\n"
        "|---|---|---|---|\n"
        f"| one episode at a time (a forward pass per step) | {result['one_at_a_time_s']} | "
        f"{result['one_at_a_time_episodes_per_second']} | 1.0x |\n"
        f"| in step (a forward pass per step of all the episodes) | {result['in_step_s']} | "
        f"{result['in_step_episodes_per_second']} | **{result['gain']}x** |"
    )


def write_play(result: dict[str, Any], load: tuple[float, float], doc: Path | None, gpu_machine: bool = False) -> None:
    """Write the table into the doc's play section."""
    if doc:
        write_marked_section(doc, doc_section("bench-play", gpu_machine), play_table(result, load))

"""Where an A2C training step goes on this machine, and how close it comes to the network's floor.

    .venv/bin/python tools/a2c_speed.py [--dataset DIR] [--steps 2000] [--doc docs/performance.md]

Trains the benchmark's A2C (SB3's defaults, the paper's network of section V-B, 8 environments,
so one update every 8 x 5 = 40 environment steps) on the SP scenes of ``--dataset`` (without one,
two small SP strawberry scenes are generated first) and times every update's parts: collecting the
rollout (the environments' steps and, apart, the rest: the policy's forward passes and SB3's
bookkeeping) and the update itself (``train()``: forward, backward, RMSprop step). The same
training with the convolutions in the plain NCHW layout (before they ran channels-last) is timed
alongside, alternating, as the "before". The floor is the network alone on observations of the
same shape: five forward passes of a batch of 8 and one forward, backward and optimiser step of
40, timed after the runs, both layouts in turn. With ``--doc`` the table is written between the
file's ``<!-- a2c:start -->`` and ``<!-- a2c:end -->``.
"""

from __future__ import annotations

import argparse
import os
import statistics
import tempfile
import time
from pathlib import Path

import torch
from stable_baselines3 import A2C
from stable_baselines3.common.vec_env import VecEnvWrapper

from davis_ag.atomic_files import write_marked_section
from davis_ag.benchmark.networks import ARCHITECTURES
from davis_ag.benchmark.training import make_vec_tvm

N_ENVS = 8


class TimedSteps(VecEnvWrapper):
    """Adds up the seconds the wrapped environments spend stepping."""

    def __init__(self, venv) -> None:
        super().__init__(venv)
        self.seconds = 0.0

    def reset(self):
        return self.venv.reset()

    def step_wait(self):
        start = time.perf_counter()
        result = self.venv.step_wait()
        self.seconds += time.perf_counter() - start
        return result


class TimedA2C(A2C):
    """SB3's A2C with the time of each rollout and each update recorded."""

    rollout_s: list[float]
    update_s: list[float]

    def collect_rollouts(self, *args, **kwargs):
        start = time.perf_counter()
        result = super().collect_rollouts(*args, **kwargs)
        self.rollout_s.append(time.perf_counter() - start)
        return result

    def train(self) -> None:
        start = time.perf_counter()
        super().train()
        self.update_s.append(time.perf_counter() - start)


def network_floors(models: list[A2C], repeats: int = 10) -> list[float]:
    """Median seconds of each model's network share of one update, the models timed in turn.

    One repetition is 5 rollout forward passes of 8 and one update of 40 on random observations.
    """
    times: list[list[float]] = [[] for _ in models]
    for _ in range(repeats + 1):
        for model, spent in zip(models, times):
            policy = model.policy
            shape = model.observation_space.shape
            small = torch.randint(0, 256, (N_ENVS, *shape), dtype=torch.uint8)
            batch = torch.randint(0, 256, (N_ENVS * model.n_steps, *shape), dtype=torch.uint8)
            actions = torch.randint(0, model.action_space.n, (len(batch),))
            start = time.perf_counter()
            with torch.no_grad():
                for _ in range(model.n_steps):
                    policy(small)
            values, log_prob, entropy = policy.evaluate_actions(batch, actions)
            loss = -log_prob.mean() + 0.5 * values.pow(2).mean() - 0.0 * entropy.mean()
            policy.optimizer.zero_grad()
            loss.backward()
            torch.nn.utils.clip_grad_norm_(policy.parameters(), model.max_grad_norm)
            policy.optimizer.step()
            spent.append(time.perf_counter() - start)
    return [statistics.median(spent[1:]) for spent in times]


def small_dataset(folder: Path) -> Path:
    """Two SP strawberry scenes at 320x180 on the grid every 0.5 m (a minute or two)."""
    from dataclasses import replace

    from davis_ag.generate.one_scene import SceneRequest, generate_scene
    from davis_ag.scene.camera import Camera
    from davis_ag.scene.specs import CROPS, scenario_spec

    crop = CROPS["strawberry"]
    grid = replace(scenario_spec("sp", crop), step=0.5)
    for index in range(2):
        generate_scene(SceneRequest(grid, crop, index, 0, Camera(320, 180)), folder)
    return folder


def measure(dataset: Path, steps: int, chunks: int = 5) -> dict:
    """Train for ``steps`` steps with timers; return the per-update times and the floor.

    The same training is run twice in this process, the convolutions in the shipped
    channels-last layout and in the plain NCHW one (before the layout change), alternating in
    ``chunks`` pieces so that both see the same machine; the floor is taken for each.
    """
    runs = {}
    for layout in (True, False):
        env = TimedSteps(make_vec_tvm(dataset, "sp", N_ENVS, 0, "all"))
        kwargs = {**ARCHITECTURES["paper"], "features_extractor_kwargs": {"channels_last": layout}}
        model = TimedA2C("CnnPolicy", env, seed=0, device="cpu", policy_kwargs=kwargs)
        model.rollout_s, model.update_s = [], []
        model.learn(N_ENVS * model.n_steps * 5)  # warm-up: caches, allocator, oneDNN kernels
        model.rollout_s, model.update_s, env.seconds = [], [], 0.0
        runs[layout] = {"model": model, "env": env, "wall": 0.0}
    for _ in range(chunks):
        for run in runs.values():
            start = time.perf_counter()
            run["model"].learn(steps // chunks, reset_num_timesteps=False)
            run["wall"] += time.perf_counter() - start
    floors = dict(zip(runs, network_floors([run["model"] for run in runs.values()])))
    results = {}
    for layout, run in runs.items():
        model, env = run["model"], run["env"]
        updates = len(model.update_s)
        per_update = {"rollout": sum(model.rollout_s) / updates, "env": env.seconds / updates,
                      "update": sum(model.update_s) / updates}
        results[layout] = {"steps": updates * N_ENVS * model.n_steps, "wall_s": run["wall"], "updates": updates,
                           "steps_per_second": updates * N_ENVS * model.n_steps / run["wall"],
                           "per_update_s": per_update, "floor_s": floors[layout],
                           "threads": torch.get_num_threads()}
        env.close()
    return {**results[True], "nchw_steps_per_second": results[False]["steps_per_second"],
            "nchw_floor_s": results[False]["floor_s"]}


def table(result: dict) -> str:
    """The Markdown table of one measurement."""
    u = result["per_update_s"]
    whole = result["wall_s"] / result["updates"]
    policy = u["rollout"] - u["env"]
    other = whole - u["rollout"] - u["update"]
    rows = [("rollout: environments' steps", u["env"]), ("rollout: policy forward passes and SB3", policy),
            ("update: forward, backward, RMSprop", u["update"]), ("callbacks, logging", other)]
    lines = [f"{result['steps']:,} A2C steps ({result['updates']} updates of {N_ENVS} x 5) with the paper's "
             f"network, {result['threads']} torch threads, load average {os.getloadavg()[0]:.1f} on "
             f"{os.cpu_count()} CPUs at the end: **{result['steps_per_second']:.1f} steps/s**.", "",
             "| part of an update | ms | share |", "|---|---|---|"]
    lines += [f"| {name} | {1000 * s:.0f} | {s / whole:.0%} |" for name, s in rows]
    lines += [f"| whole update | {1000 * whole:.0f} | 100% |", "",
              f"The network alone (five forward passes of 8, one forward, backward and RMSprop step of 40, "
              f"random observations): {1000 * result['floor_s']:.0f} ms per update, "
              f"{N_ENVS * 5 / result['floor_s']:.1f} steps/s; training runs at "
              f"{result['floor_s'] / whole:.0%} of that floor.", "",
              f"Before the convolutions ran channels-last (the plain NCHW layout, trained alongside in "
              f"the same process): **{result['nchw_steps_per_second']:.1f} steps/s**, the network alone "
              f"{1000 * result['nchw_floor_s']:.0f} ms per update; channels-last is "
              f"{result['steps_per_second'] / result['nchw_steps_per_second']:.2f}x that."]
    return "\n".join(lines)


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--dataset", type=Path, help="a dataset with SP scenes (default: generate two small ones)")
    parser.add_argument("--steps", type=int, default=2000, help="environment steps to time (default 2000)")
    parser.add_argument("--doc", type=Path, help="write the table into this Markdown file's a2c section")
    args = parser.parse_args()
    with tempfile.TemporaryDirectory(prefix="davis-ag-a2c-") as scratch:
        dataset = args.dataset or small_dataset(Path(scratch) / "dataset")
        result = measure(dataset, args.steps)
    text = table(result)
    print(text)
    if args.doc:
        write_marked_section(args.doc, "a2c", text)
        print(f"written {args.doc}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

"""``davis-ag bench --only training`` (and ``make bench``): what one training step costs for each
learner ``reproduce`` trains, on the paper's network with its 8 environments, and what PPO would
cost with Stable-Baselines3's defaults instead of the zoo's Atari settings it trains with.

Each learner trains the same number of steps on the same three single-plant strawberry scenes
(small images: the observation is 224x224 whatever the view's size), one after the other in this
process, so the ratios between them hold on a busy machine where the absolute rates do not. SB3's
PPO defaults are timed with 256-step rollouts instead of 2,048 (one whole rollout and update fit
in the timed steps): what a step costs, one forward pass in the rollout and 10 epochs of forward
and backward passes in 64-sample batches, does not depend on the rollout's length.
"""

from __future__ import annotations

import os
import time
from functools import partial
from pathlib import Path
from typing import Any

from davis_ag.atomic_files import read_page, write_marked_section
from davis_ag.workflows.bench.report import doc_section

SEED = 0
#: Steps each learner is timed for: a whole number of every timed rollout (8 environments x 128
#: for the zoo's PPO, 8 x 256 for SB3's defaults).
STEPS = 2048
#: SB3's own PPO defaults (``PPO.__init__``), rollout shortened as the module says.
SB3_PPO_DEFAULTS = {
    "n_steps": 256,
    "n_epochs": 10,
    "batch_size": 64,
    "learning_rate": 3e-4,
    "clip_range": 0.2,
    "vf_coef": 0.5,
    "ent_coef": 0.0,
}
#: (row, algorithm, settings): what is timed, the first row the reference of the ratios.
LEARNERS: tuple[tuple[str, str, Any], ...] = (
    ("A2C (ours)", "a2c", "ours"),
    ("PPO (the zoo's Atari settings, ours)", "ppo", "ours"),
    ("PPO (SB3's defaults)", "ppo", SB3_PPO_DEFAULTS),
)
#: Steps per scenario of the ``medium`` and ``paper-scale`` runs, for the hours column.
RUN_STEPS = 300_000


def training_scenes(root: Path) -> Path:
    """Three single-plant strawberry scenes at 160x90 (dataset seed 0): two to train on."""
    from davis_ag.generate.one_scene import SceneRequest
    from davis_ag.scene.camera import Camera
    from davis_ag.scene.specs import crop_spec, scenario_spec
    from davis_ag.workflows.stages import generate_scenes

    crop = crop_spec("strawberry")
    requests = [SceneRequest(scenario_spec("sp", crop), crop, i, SEED, Camera(160, 90)) for i in range(3)]
    generate_scenes(requests, root, progress=False)
    return root


def training_speed(scratch: Path, steps: int = STEPS, devices: tuple[str, ...] = ("cpu",)) -> dict[str, Any]:
    """Steps per second of each of :data:`LEARNERS` on each torch device, trained ``steps`` steps
    on the paper's network (8 environments, the observation cache built before the first is
    timed); the first device's A2C is the reference of the ratios.

    Args:
        scratch: A folder for the scenes and models.
        steps: Steps each learner is timed for.
        devices: Torch devices, the CPU first (``("cpu", "cuda")`` on a GPU machine: what the GPU
            gains, measured in the same process).

    Returns:
        ``{"steps": n, "devices": [...], "learners": {row: {"algo", "device", "steps_per_second",
        "over_reference", "hours_300k"}}}``; a row is named by its learner, and by its device too
        where several are timed.
    """
    from davis_ag.benchmark.training import check_device, train_agent

    for device in devices:
        check_device(device)  # before minutes of measuring
    root = training_scenes(scratch / "training")
    train = partial(train_agent, seed=SEED, n_envs=8, arch="paper", checkpoint_every=0, keep="last", progress=False)
    rows: dict[str, Any] = {}
    for device in devices:
        # Builds the cache (first device) and warms the device up before anything is timed.
        train(root, "sp", total_timesteps=8, out_path=scratch / f"warm-{device}.zip", device=device)
        for number, (row, algo, settings) in enumerate(LEARNERS):
            started = time.perf_counter()
            train(
                root,
                "sp",
                total_timesteps=steps,
                out_path=scratch / f"{device}-{number}.zip",
                algo=algo,
                settings=settings,
                device=device,
            )
            rate = steps / (time.perf_counter() - started)
            reference = next(iter(rows.values()))["steps_per_second"] if rows else rate
            rows[row if len(devices) == 1 else f"{row} on {device}"] = {
                "algo": algo,
                "device": device,
                "steps_per_second": round(rate, 1),
                "over_reference": round(rate / reference, 2),
                "hours_300k": round(RUN_STEPS / rate / 3600, 1),
            }
    return {"steps": steps, "seed": SEED, "devices": list(devices), "learners": rows}


def training_table(result: dict[str, Any], load: tuple[float, float]) -> str:
    """The training rates as Markdown."""
    from davis_ag.provenance import machine_summary

    devices = result.get("devices", ["cpu"])
    where = "the CPU" if devices == ["cpu"] else f"each device in turn ({', '.join(devices)}; {machine_summary()})"
    lines = [
        f"The paper's network on {where}, 8 environments, {result['steps']:,} steps of each learner on three "
        f"single-plant strawberry scenes (seed {result['seed']}), one after the other in one process; load "
        f"average {load[0]:.2f} at the start, {load[1]:.2f} at the end, {os.cpu_count()} CPUs. SB3's PPO "
        "defaults with 256-step rollouts (what a step costs does not depend on the rollout's length).",
        "",
        f"| learner | steps/s | against {next(iter(result['learners']))} | hours for {RUN_STEPS // 1000}K steps "
        "at this rate |",
        "|---|---|---|---|",
    ]
    for row, r in result["learners"].items():
        lines.append(f"| {row} | **{r['steps_per_second']}** | {r['over_reference']:.2f}x | {r['hours_300k']} |")
    return "\n".join(lines)


def ppo_line(result: dict[str, Any]) -> str:
    """PPO's two settings in one sentence, for docs/benchmark.md (on the first device, the CPU)."""
    first = result.get("devices", ["cpu"])[0]
    zoo, sb3 = (r for row, r in result["learners"].items() if row.startswith("PPO") and r.get("device", first) == first)
    return (
        f"PPO's two settings, measured by `make bench` ([performance.md](performance.md)): SB3's defaults "
        f"train at {sb3['steps_per_second']} steps/s on the paper's network on this machine, the zoo's "
        f"settings at {zoo['steps_per_second']} ({zoo['steps_per_second'] / sb3['steps_per_second']:.1f} "
        "times as fast)."
    )


def write_training(
    result: dict[str, Any], load: tuple[float, float], doc: Path | None, gpu_machine: bool = False
) -> None:
    """Write the training rates into the doc and PPO's line into docs/benchmark.md beside it (whose
    sentence is the 2-core machine's: a GPU machine's rates go to the doc's GPU section only)."""
    if doc:
        write_marked_section(doc, doc_section("bench-training", gpu_machine), training_table(result, load))
        page = doc.absolute().parent / "benchmark.md"
        if not gpu_machine and page.is_file() and "<!-- ppo-rate:start -->" in read_page(page, "page"):
            write_marked_section(page, "ppo-rate", ppo_line(result))

"""A short PPO run on TVMContinuous-v0 and its training curve (docs/images/continuous-training.png).

    .venv/bin/python tools/continuous_training.py [--timesteps 12000] [--arch pooled] \
        [--doc docs/performance.md]

The scene is the bench's (single-plant strawberry, dataset seed 0, scene 0, the crop's full grid
area; :func:`tools/bench.py continuous_scene`). PPO (:func:`davis_ag.live.training.train_continuous`)
trains on it from seed 0; then PPO (deterministic), LR, UD, Rand and Greedy play the same 3 x 50
starts (:func:`davis_ag.live.evaluation.evaluate_continuous`). The curve is drawn from every
training episode; with ``--doc`` the numbers are written between the file's
``<!-- continuous-training:start -->`` and ``<!-- continuous-training:end -->`` markers.
"""

from __future__ import annotations

import argparse
import json
import os
import tempfile
import time
from pathlib import Path

import numpy as np

from davis_ag.atomic_files import write_marked_section
from davis_ag.benchmark.evaluation import evaluate_policies, format_table
from davis_ag.benchmark.policies import ModelPolicy
from davis_ag.figures.result_charts import plot_training_curve
from davis_ag.live.policies import build_policies
from davis_ag.live.training import train_continuous
from davis_ag.live.tvm_continuous import TVMContinuousEnv

from bench import continuous_scene  # tools/bench.py: this script runs beside it


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--timesteps", type=int, default=12_000)
    parser.add_argument("--arch", default="pooled", choices=("paper", "nature", "pooled"))
    parser.add_argument("--episodes", type=int, default=50, help="evaluation episodes per session (3 sessions)")
    parser.add_argument("--png", type=Path, default=Path("docs/images/continuous-training.png"))
    parser.add_argument("--doc", type=Path)
    args = parser.parse_args()
    load = os.getloadavg()[0]
    with tempfile.TemporaryDirectory(prefix="davis-ag-ppo-") as scratch:
        scene_dir = continuous_scene(Path(scratch))
        plants = json.loads((scene_dir / "scene.json").read_text())["plant_generator"]
        started = time.perf_counter()
        model, records = train_continuous(scene_dir, "sp", total_timesteps=args.timesteps, seed=0,
                                          out_path=Path(scratch) / "ppo.zip", arch=args.arch,
                                          progress_every=1000)
        train_s = time.perf_counter() - started
        plot_training_curve(records, args.png, f"PPO ({args.arch} network) on TVMContinuous-v0, "
                                               f"SP strawberry scene 0, {args.timesteps:,} steps", window=100)
        env = TVMContinuousEnv(scene_dir, "sp")
        try:
            # deterministic: the mean action, as this page's numbers were measured
            results = evaluate_policies(env, [ModelPolicy(model, deterministic=True),
                                              *build_policies(["LR", "UD", "Rand", "Greedy"])],
                                        episodes=args.episodes, sessions=3)
        finally:
            env.close()
    table = format_table(results)
    print(table)
    gains = np.array([r["oer_tau"] - r["oer_0"] for r in records])
    quarter = max(1, len(gains) // 4)
    text = (f"PPO (SB3 defaults, n_steps 128, batch 32, {args.arch} network; `--plants {plants}`), "
            f"{args.timesteps:,} steps "
            f"({len(records):,} episodes) in {train_s / 60:.1f} min, load average {load:.2f} at the start, "
            f"{os.getloadavg()[0]:.2f} at the end. Mean OER gain per training episode: "
            f"{gains[:quarter].mean():+.3f} in the first quarter, {gains[-quarter:].mean():+.3f} in the last. "
            f"Then every policy on the same 3 x {args.episodes} starts of the same scene:\n\n```\n{table}\n```\n\n"
            f"![training curve]({os.path.relpath(args.png, args.doc.parent) if args.doc else args.png})")
    print(text)
    if args.doc:
        write_marked_section(args.doc, "continuous-training", text)


if __name__ == "__main__":
    main()

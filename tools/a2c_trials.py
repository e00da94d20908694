"""A2C settings trials on the train split only: why SB3's defaults collapse to one move, and what fixes it.

Each trial trains A2C (the paper's network) on the dataset's train split with one setting set,
then plays 3 x 200 episodes on the *same train split* (never the test split: settings are chosen
here) with the trained model both deterministic and sampled, beside every fixed action, LRD, UDD
and Rand, and writes one JSON per trial: OER_tau, reward, length (mean ± std over sessions), the
action histogram of each policy and the training record's learning curve.

    PYTHONPATH=src python tools/a2c_trials.py --dataset DIR --out DIR --timesteps 30000 \
        --trial sb3 --trial ours --trial 'ent_only={"ent_coef": 0.01}'

A trial is a preset name of davis_ag.benchmark.training.SETTINGS_PRESETS, or NAME=JSON with SB3 A2C
arguments. Trials run one after another in this process; start several processes to run them side
by side.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

from davis_ag.benchmark import TVMEnv
from davis_ag.benchmark.agents import FixedActionAgent, heuristic
from davis_ag.benchmark.policies import ModelPolicy
from davis_ag.benchmark.evaluation import evaluate_policies
from davis_ag.benchmark.training import train_a2c, training_record_path


def parse_trial(text: str) -> tuple[str, str | dict]:
    """``ours`` -> (ours, "ours"); ``name={"ent_coef": 0.01}`` -> (name, {...})."""
    if "=" in text:
        name, _, settings = text.partition("=")
        return name, json.loads(settings)
    return text, text


def summary(results: dict) -> dict:
    """Per policy: mean and std of the Table 4 metrics and the action histogram."""
    return {name: {"oer_tau": [p["oer_tau"]["mean"], p["oer_tau"]["std"]],
                   "reward": [p["reward"]["mean"], p["reward"]["std"]],
                   "length": [p["length"]["mean"], p["length"]["std"]],
                   "actions": p["action_counts"]}
            for name, p in results["policies"].items()}


def policy_at_starts(model: object, env: TVMEnv) -> dict:
    """The policy's action probabilities at every start of the split: their mean, the mean of the
    largest, and how many starts each action is the most likely at (one action everywhere: a
    deterministic player is a fixed action)."""
    import numpy as np
    import torch

    observations = []
    for scene, box in env.starts:
        cache = env.caches[scene]
        start = (env.scenes[scene].id, cache.view_names[cache.box_view[box]], int(cache.fruit_ids[cache.box_fruit[box]]))
        observations.append(env.reset(options={"start": start})[0])
    tensor, _ = model.policy.obs_to_tensor(np.stack(observations))
    with torch.no_grad():
        probs = model.policy.get_distribution(tensor).distribution.probs.cpu().numpy()
    return {"mean_probs": [round(float(p), 3) for p in probs.mean(0)], "mean_max_prob": round(float(probs.max(1).mean()), 3),
            "argmax_counts": np.bincount(probs.argmax(1), minlength=probs.shape[1]).tolist()}


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--dataset", type=Path, required=True)
    parser.add_argument("--out", type=Path, required=True)
    parser.add_argument("--trial", action="append", required=True)
    parser.add_argument("--timesteps", type=int, default=30_000)
    parser.add_argument("--seed", type=int, default=0)
    parser.add_argument("--n-envs", type=int, default=8)
    parser.add_argument("--arch", default="paper")
    parser.add_argument("--device", default="cpu")
    parser.add_argument("--cache-dir", type=Path, default=None)
    parser.add_argument("--baselines", action="store_true", help="also play the fixed actions and heuristics")
    parser.add_argument("--keep", choices=["last", "best-train"], default="last",
                        help="snapshot to play (default last: a trial scores its settings, and the best "
                             "train-split snapshot would be scored on the split that chose it)")
    args = parser.parse_args()
    args.out.mkdir(parents=True, exist_ok=True)
    env = TVMEnv(args.dataset, "sp", split="train", crop="strawberry", cache_dir=args.cache_dir)
    for text in args.trial:
        name, settings = parse_trial(text)
        start = time.perf_counter()
        model = train_a2c(args.dataset, "sp", total_timesteps=args.timesteps, seed=args.seed,
                          out_path=args.out / f"{name}.zip", n_envs=args.n_envs, crop="strawberry",
                          arch=args.arch, device=args.device, checkpoint_every=0, settings=settings,
                          cache_dir=args.cache_dir, keep=args.keep)
        seconds = time.perf_counter() - start
        deterministic = ModelPolicy(model, deterministic=True, device=args.device)
        deterministic.name = "A2C deterministic"
        sampled = ModelPolicy(model, deterministic=False, device=args.device)
        sampled.name = "A2C sampled"
        agents = [deterministic, sampled]
        if args.baselines:
            agents += [heuristic(n) for n in ("LRD", "UDD", "Rand")]
            agents += [FixedActionAgent(a) for a in env.action_names]
        results = evaluate_policies(env, agents, episodes=200, sessions=3, seed=args.seed).as_json()
        record = json.loads(training_record_path(model).read_text())
        start_policy = policy_at_starts(deterministic.model, env)
        out = {"trial": name, "settings": record["a2c_settings"], "timesteps": args.timesteps,
               "train_seconds": round(seconds, 1), "split": "train", "policies": summary(results),
               "policy_at_starts": start_policy, "curve": record.get("curve", [])}
        (args.out / f"{name}.json").write_text(json.dumps(out, indent=1))
        for policy, stats in out["policies"].items():
            print(f"{name:10s} {policy:18s} OER {stats['oer_tau'][0]:.3f}±{stats['oer_tau'][1]:.3f} "
                  f"reward {stats['reward'][0]:.4f} length {stats['length'][0]:.2f} {stats['actions']}",
                  flush=True)
        print(f"{name:10s} at the split's starts: {start_policy}", flush=True)
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

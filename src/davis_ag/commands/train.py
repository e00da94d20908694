"""``davis-ag train``: train the paper's A2C agent (or PPO, DQN) on a dataset's train split."""

from __future__ import annotations

import argparse

from davis_ag.commands import arguments
from davis_ag.errors import UserError

HELP = "train an A2C (or PPO, DQN) agent for target visibility maximisation"
DESCRIPTION = (
    "Train a Stable-Baselines3 agent (--algo a2c, the paper's, by default; ppo; dqn) with the paper's network "
    "(CnnPolicy; A2C: SB3's default hyperparameters with an entropy bonus and normalised advantages; PPO: "
    "RL Baselines3 Zoo's Atari settings; DQN: SB3's defaults with a smaller replay buffer) on the train split of the TVM environment "
    "and save a .zip (the snapshot that scored best on the train split), with a training record "
    "(settings, sittings, learning curve) beside it. Shows steps, rate, time left and the last "
    "train-split score: a bar on a terminal, a line a minute in a log."
)


def setting(text: str) -> tuple[str, object]:
    """Parse ``KEY=VALUE``; the value as JSON (``128``, ``0.01``, ``true``), else as text."""
    import json

    key, equals, value = text.partition("=")
    if not equals or not key.strip().isidentifier():
        raise argparse.ArgumentTypeError(f"{text!r} is not KEY=VALUE, e.g. n_steps=128")
    try:
        return key.strip(), json.loads(value)
    except ValueError:
        return key.strip(), value


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``train``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    arguments.add_dataset_flags(parser, "train")
    parser.add_argument(
        "--algo",
        choices=["a2c", "ppo", "dqn", "recurrentppo", "qrdqn", "trpo", "maskableppo"],
        default="a2c",
        help="a2c (the paper's, default), ppo or dqn (on the discrete moves); with the contrib extra, "
        "sb3-contrib's recurrentppo, qrdqn, trpo or maskableppo",
    )
    parser.add_argument(
        "--timesteps",
        type=arguments.bounded(1, 10**9),
        default=300_000,
        metavar="N",
        help="environment steps (default: 300000, as in the paper)",
    )
    parser.add_argument("--seed", type=arguments.seed, default=0, help="seed of SB3 and the environments")
    parser.add_argument(
        "--n-envs",
        type=arguments.bounded(1, 256),
        default=None,
        help="parallel environments (default: 8, or the --a2c-settings set's own: zoo-atari's 16)",
    )
    parser.add_argument(
        "--arch",
        choices=["paper", "nature", "pooled"],
        default="paper",
        help="network: paper (section V-C, default), nature (SB3's NatureCNN) or pooled (fast smoke tests)",
    )
    parser.add_argument(
        "--a2c-settings",
        choices=["ours", "sb3", "zoo-atari"],
        default="ours",
        help="A2C only; ours (default): SB3's A2C defaults with ent_coef=0.01 and normalised advantages, "
        "which keep the policy from collapsing to one move; sb3: SB3's defaults alone; zoo-atari: RL "
        "Baselines3 Zoo's Atari A2C (16 environments, ent_coef=0.01, vf_coef=0.25, RMSpropTFLike eps 1e-5)",
    )
    parser.add_argument(
        "--set",
        action="append",
        type=setting,
        default=[],
        metavar="KEY=VALUE",
        dest="settings",
        help="a Stable-Baselines3 argument of the algorithm over its settings (repeatable), e.g. "
        "n_steps=32 for a short PPO rollout; recorded in the training record",
    )
    parser.add_argument(
        "--keep",
        choices=["best-train", "last"],
        default="best-train",
        help="which snapshot to save: best-train (default) scores the policy on the train split "
        "every 10000 steps and at the end (200 sampled episodes) and keeps the best; "
        "last keeps the last",
    )
    parser.add_argument("--device", default="auto", help="torch device (default: auto)")
    parser.add_argument(
        "--out", type=arguments.path, required=True, metavar="MODEL.zip", help="where to save the model"
    )
    parser.add_argument(
        "--checkpoint-every",
        type=arguments.whole,
        default=10_000,
        metavar="N",
        help="save a checkpoint beside --out every N steps (0: never); running the same "
        "command again resumes from it (default: 10000)",
    )
    parser.add_argument(
        "--force",
        action="store_true",
        help="replace an existing model at --out, and discard a checkpoint beside it that cannot "
        "be resumed (another run's, or a damaged one)",
    )
    parser.add_argument("--verbose", type=int, choices=(0, 1, 2), default=1, help="SB3 verbosity (default: 1)")
    parser.add_argument(
        "--robot",
        default=None,
        metavar="ROBOT",
        help="train with the camera on this robot (davis-ag robots lists them, or a YAML file): only the "
        "views it reaches (docs/robot.md)",
    )
    arguments.add_task_flags(parser, "train on")
    arguments.add_torch_threads_flag(parser, "train")


def run(args: argparse.Namespace) -> int:
    """Train and save; prints the model's path."""
    from davis_ag.benchmark.training import TVM_TASK, check_device, model_path, train_agent
    from davis_ag.errors import UserError
    from davis_ag.formats.outputs import claim_output

    task = TVM_TASK
    if args.task == "mapping":
        from davis_ag.mapping.coverage import SEEN_FRACTION
        from davis_ag.mapping.training import mapping_task

        fraction = SEEN_FRACTION if args.seen_fraction is None else args.seen_fraction
        task = mapping_task(args.budget, fraction)
    elif (args.budget, args.seen_fraction) != (None, None):
        raise UserError("--budget and --seen-fraction are for --task mapping: add it or leave them out")
    arguments.check_task_split_rule(args)
    check_device(args.device)
    arguments.use_torch_threads(args)
    arguments.prove_writable_file(args.out)
    if args.cache_dir is not None:
        arguments.prove_writable_folder(args.cache_dir, "--cache-dir")
    with claim_output(model_path(args.out), force=args.force):  # the output rule
        path = train_agent(
            args.dataset,
            args.scenario,
            total_timesteps=args.timesteps,
            seed=args.seed,
            out_path=args.out,
            n_envs=args.n_envs,
            crop=args.crop,
            cache_dir=args.cache_dir,
            arch=args.arch,
            device=args.device,
            verbose=args.verbose,
            checkpoint_every=args.checkpoint_every,
            settings=_settings(args),
            keep=args.keep,
            algo=args.algo,
            force=args.force,
            robot=args.robot,
            task=task,
            split_rule=args.split_rule,
        )
    print(f"saved {path}")
    return 0


def _settings(args: argparse.Namespace) -> str | dict[str, object]:
    """What :func:`davis_ag.benchmark.training.train_agent` takes as ``settings``: the A2C preset,
    with ``--set`` values over it (over PPO's or DQN's own settings for those)."""
    from davis_ag.benchmark.algorithms import SETTINGS_PRESETS

    chosen = dict(args.settings)
    if args.algo != "a2c":
        if args.a2c_settings != "ours":
            raise UserError(f"--a2c-settings is for --algo a2c; {args.algo} trains with its own settings and --set")
        return chosen or "ours"
    return {**SETTINGS_PRESETS[args.a2c_settings], **chosen} if chosen else args.a2c_settings

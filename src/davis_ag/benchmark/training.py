"""Train an agent with Stable-Baselines3 on the train split, checkpointed and resumable: the paper's
A2C (section V-C), PPO or DQN (on the discrete moves), each with the paper's network as its
features extractor, the same keep-best-train snapshot rule (:mod:`davis_ag.benchmark.selection`),
checkpoints, training record and progress (a bar on a terminal, a line a minute in a log).

A 300K-step run on a CPU takes hours, so training saves a checkpoint every few thousand steps
(model, optimiser state and step count in SB3's zip, beside a small JSON of the run's settings)
and a run started again with the same settings continues from the last checkpoint instead of
from scratch. What a resumed run does not restore: the environments' episodes in flight (they
start anew) and the random streams, which it draws afresh from ``[seed, TRAIN_RESUME_STREAM,
step]`` (:func:`davis_ag.seeds.resumed_training_seed`; SB3's load would reseed them as at step 0
and replay the first sitting), so a resumed run is a valid continuation, reproducible from the
steps its sittings begin at, not bit-identical to an uninterrupted one.
"""

from __future__ import annotations

import os
from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

import torch
from stable_baselines3.common.vec_env import DummyVecEnv

from davis_ag.atomic_files import prove_writable_file, write_json_atomic
from davis_ag.benchmark import TVMEnv
from davis_ag.benchmark.algorithms import (
    ALGORITHMS,
    CLASS_NAMES,
    POLICY_NAMES,
    algorithm_of,
    console_logger,
    environments_of,
    resolve_sb3_settings,
    resolve_settings,
    sb3_arguments,
)
from davis_ag.benchmark.checkpoints import CheckpointEvery, Sittings, check_checkpoint, load_checkpoint, save_model
from davis_ag.benchmark.networks import ARCHITECTURES
from davis_ag.benchmark.progress import LearningCurve, TrainingProgress
from davis_ag.benchmark.selection import KeepBestOnTrain, check_keep, publish_snapshot, snapshot_path
from davis_ag.benchmark.splits import as_dataset, select_scenes
from davis_ag.benchmark.training_record import model_path, training_record_path
from davis_ag.benchmark.training_rescue import keep_what_it_trained, rescued_selection, what_survives
from davis_ag.errors import MachineError, UserError
from davis_ag.formats.models import check_seed
from davis_ag.formats.splits import check_split_rule
from davis_ag.seeds import resumed_training_seed, training_env_seed

if TYPE_CHECKING:
    from davis_ag.data.reader import Dataset

#: Steps between checkpoints by default: about a minute of training on a 2-core CPU.
CHECKPOINT_EVERY = 10_000
#: Environment steps per point of the learning curve kept in the training record (Fig. 4a).
CURVE_EVERY = 1_000
#: Steps between train-split scores of the policy when a run keeps its best snapshot
#: (:mod:`davis_ag.benchmark.selection`): 30 scores over 300K steps, a few per cent of the time.
SELECT_EVERY = 10_000


@dataclass(frozen=True)
class TrainingTask:
    """What a run learns and how its snapshots are scored: TVM-v0 (:data:`TVM_TASK`) unless a later
    stage gives another (row mapping's, :func:`davis_ag.mapping.training.mapping_task`).

    Attributes:
        name: ``tvm``, or the task recorded in the run's settings.
        env_class: The environment (made with the dataset, scenario, split, crop, cache_dir, robot).
        env_kwargs: Its further settings (recorded in the run's settings).
        score: ``(model, env, episodes) -> dict`` of a snapshot on the train split; None: TVM-v0's.
        key, label: The score kept, by its record name and as messages show it.
    """

    name: str
    env_class: Any
    env_kwargs: dict[str, Any] = field(default_factory=dict)
    score: Any = None
    key: str = "oer_tau"
    label: str = "OER_tau"


#: The paper's task.
TVM_TASK = TrainingTask("tvm", TVMEnv)


def make_vec_tvm(
    dataset: Dataset | str | os.PathLike[str],
    scenario: str,
    n_envs: int,
    seed: int,
    split: str = "train",
    crop: str | None = None,
    cache_dir: str | os.PathLike[str] | None = None,
    env_seeds: str = "streams",
    robot: str | None = None,
    task: TrainingTask = TVM_TASK,
    split_rule: str = "scenes",
) -> Any:
    """``n_envs`` TVM environments in one SB3 ``DummyVecEnv`` (each wrapped in ``Monitor``).

    The environment is fast (tens of thousands of steps/s), so subprocesses would only add
    pickling; the network is the cost. The dataset is opened once and shared.

    Args:
        dataset: Dataset root or opened dataset.
        scenario: ``sp`` or ``mp``.
        n_envs: Number of environments.
        seed: The run's seed.
        split, crop, cache_dir, robot: As for :class:`davis_ag.benchmark.TVMEnv`.
        task: The environment's task (TVM-v0 by default).
        split_rule: The split rule (:mod:`davis_ag.formats.splits`); TVM-v0 only.
        env_seeds: ``streams``: environment ``i`` is seeded with
            :func:`~davis_ag.seeds.training_env_seed` ``(seed, i)``, so runs of different seeds
            share no episode stream; ``seed+i`` (runs from before, resumed as they began):
            SB3's ``seed + i``, under which environment 1 of seed 0 replays environment 0 of seed 1.

    Returns:
        The vectorised environment.
    """
    from stable_baselines3.common.env_util import make_vec_env

    opened = as_dataset(dataset)
    kwargs = {"dataset": opened, "scenario": scenario, "split": split, "crop": crop, "cache_dir": cache_dir}
    if robot is not None:
        kwargs["robot"] = robot
    if split_rule != "scenes":  # only then: other tasks' environments take no rule
        kwargs["split_rule"] = split_rule
    chosen = DummyVecEnv if env_seeds == "seed+i" else StreamSeededVecEnv
    return make_vec_env(
        task.env_class, n_envs=n_envs, seed=seed, env_kwargs={**kwargs, **task.env_kwargs}, vec_env_cls=chosen
    )


class StreamSeededVecEnv(DummyVecEnv):
    """SB3's ``DummyVecEnv`` seeding environment ``i`` from ``[seed, TRAIN_ENV_STREAM, i]``
    (:func:`~davis_ag.seeds.training_env_seed`) instead of ``seed + i``; SB3 seeds it when the
    vector is made and again when the learner is (``set_random_seed``), each time alike."""

    def seed(self, seed: int | None = None) -> list[int | None]:
        if seed is None:
            return list(super().seed(None))
        self._seeds = [training_env_seed(seed, i) for i in range(self.num_envs)]
        return list(self._seeds)


def checkpoint_paths(out_path: str | os.PathLike[str]) -> tuple[Path, Path]:
    """The checkpoint model and its settings file for a training run saving to ``out_path``."""
    final = model_path(out_path)
    stem = final.with_suffix("")
    return stem.with_name(stem.name + ".checkpoint.zip"), stem.with_name(stem.name + ".checkpoint.json")


def train_a2c(dataset: Dataset | str | os.PathLike[str], scenario: str, **kwargs: Any) -> Path:
    """:func:`train_agent` with ``algo="a2c"``: the paper's agent."""
    return train_agent(dataset, scenario, algo="a2c", **kwargs)


def train_agent(
    dataset: Dataset | str | os.PathLike[str],
    scenario: str,
    total_timesteps: int = 300_000,
    seed: int = 0,
    out_path: str | os.PathLike[str] = "a2c.zip",
    n_envs: int | None = None,
    crop: str | None = None,
    cache_dir: str | os.PathLike[str] | None = None,
    arch: str = "paper",
    device: str = "auto",
    verbose: int = 0,
    callback: Any = None,
    checkpoint_every: int = CHECKPOINT_EVERY,
    settings: str | dict[str, Any] = "ours",
    keep: str = "best-train",
    select_every: int = SELECT_EVERY,
    algo: str = "a2c",
    progress: bool = True,
    force: bool = False,
    robot: str | None = None,
    task: TrainingTask = TVM_TASK,
    split_rule: str = "scenes",
) -> Path:
    """Train an agent on the train split and save it; resume a killed run.

    PPO and DQN: Stable-Baselines3's defaults changed only by
    :data:`davis_ag.benchmark.algorithms.SB3_SETTINGS` (PPO: RL Baselines3 Zoo's Atari settings)
    and a ``settings`` dict, ``CnnPolicy``
    with the same ``arch`` network as A2C; DQN acts on the environment's discrete moves (``done``
    included). Everything else below holds for all three.
    A2C's hyperparameters (the paper gives none) are Stable-Baselines3's A2C defaults, learning rate
    7e-4, ``n_steps=5`` per environment and update, ``gamma=0.99``, ``gae_lambda=1``,
    ``vf_coef=0.5``, ``max_grad_norm=0.5``, RMSprop (alpha 0.99, eps 1e-5), changed by
    ``settings``: by default :data:`~davis_ag.benchmark.algorithms.A2C_SETTINGS` (``ent_coef=0.01``, normalised advantages);
    ``"sb3"`` keeps SB3's ``ent_coef=0`` and raw advantages. CnnPolicy scales the uint8
    observation by 1/255. ``n_envs`` (8, or a setting set's own: ``zoo-atari``'s 16) is ours; the paper's 300K timesteps count
    environment steps over all environments. By default the saved model is the snapshot that
    scored best on the train split (``keep``, :mod:`davis_ag.benchmark.selection`), not the
    last. The training record (:func:`training_record_path`) keeps the settings, the learning
    curve (:class:`~davis_ag.benchmark.progress.LearningCurve`) and the snapshots' train-split scores.

    Args:
        dataset: Dataset root or opened dataset.
        scenario: ``sp`` or ``mp``.
        total_timesteps: Environment steps to train for (300K in section VI).
        seed: Seeds SB3 (network init, action sampling) and the environments.
        out_path: Where to save the model (``.zip`` is added if missing).
        n_envs: Parallel environments per update; None: the setting set's ``n_envs`` where it
            carries one (``zoo-atari``: 16), else 8 (:func:`~davis_ag.benchmark.algorithms.environments_of`).
        crop: Train on one crop only (the paper: strawberry for SP, vine for MP).
        cache_dir: Observation cache folder (default under the dataset root).
        arch: ``paper`` (section V-C's network, default), ``nature`` (SB3's NatureCNN) or
            ``pooled`` (fast, for smoke tests); see :mod:`davis_ag.benchmark.networks`.
        device: Torch device for SB3 (``auto``, ``cpu``, ``cuda``).
        verbose: SB3 verbosity.
        callback: Optional SB3 callback.
        checkpoint_every: Environment steps between checkpoints (0: none). A checkpoint of a run
            with the same settings beside ``out_path`` is resumed; it is removed once the final
            model is saved.
        settings: A name of :data:`~davis_ag.benchmark.algorithms.SETTINGS_PRESETS` (``ours``, ``sb3``,
            ``zoo-atari``) or a dict of SB3 A2C arguments among
            :data:`~davis_ag.benchmark.algorithms.TUNABLE`, applied over SB3's defaults; an optimiser
            in its ``policy_kwargs`` is added to the network's.
        keep: ``best-train`` (default): save the snapshot with the best train-split OER_tau,
            scored every ``select_every`` steps and at the end; ``last``: the last one.
        select_every: Environment steps between train-split scores (``best-train`` only).
        algo: ``a2c`` (default), ``ppo``, ``dqn``, or sb3-contrib's ``recurrentppo``, ``qrdqn``, ``trpo``, ``maskableppo`` (:data:`ALGORITHMS`).
        progress: Show progress (:class:`TrainingProgress`).
        force: Discard a checkpoint beside ``out_path`` that cannot be resumed (another run's,
            or a damaged one) instead of refusing (:func:`check_checkpoint`).
        robot: Train with the camera on this robot (docs/robot.md): its reach and seconds, on the
            training and the scoring environments; recorded in the settings (name and digest).
        task: What to learn (TVM-v0 by default; row mapping's from :mod:`davis_ag.mapping.training`),
            recorded in the settings with its environment's settings when it is another.
        split_rule: ``scenes`` (default), ``starts`` or ``fruits`` (:mod:`davis_ag.formats.splits`):
            which starts train; recorded in the settings when not ``scenes``, and evaluation refuses
            the model on another rule's test split. TVM-v0 only.

    Returns:
        The saved model's path.

    Raises:
        UserError: for a bad dataset, scenario, split, algorithm or architecture, or a checkpoint
            that cannot be resumed without ``force``.
        MachineError: when the machine fails the run (a full disk), naming what survives where:
            a model in memory that no file beside ``out_path`` holds is kept in a rescue folder
            first, whatever ``keep`` says (:func:`keep_what_it_trained`).
    """

    if algo not in ALGORITHMS:
        raise UserError(f"unknown algorithm {algo!r}: choose one of {', '.join(ALGORITHMS)}")
    algorithm = algorithm_of(algo)
    if arch not in ARCHITECTURES:
        raise UserError(f"unknown network {arch!r}: choose one of {', '.join(ARCHITECTURES)}")
    if total_timesteps < 1 or (n_envs is not None and n_envs < 1) or checkpoint_every < 0 or select_every < 0:
        raise UserError("--timesteps and --n-envs must be positive, --checkpoint-every from 0")
    check_keep(keep)
    check_seed(seed, "--seed")
    check_device(device)
    check_split_rule(split_rule)
    if split_rule != "scenes" and task.name != TVM_TASK.name:
        raise UserError(f"--split-rule {split_rule} splits TVM-v0's starts; {task.name} splits by scenes: leave it out")
    chosen = resolve_settings(settings) if algo == "a2c" else resolve_sb3_settings(algo, settings)
    n_envs = environments_of(chosen, n_envs)
    arguments = sb3_arguments(chosen)  # a bad lin_X refused here, before the data is opened
    # The set's optimiser over the network's keyword arguments (SB3 takes one policy_kwargs).
    policy_kwargs = {**ARCHITECTURES[arch], **arguments.pop("policy_kwargs", {})}
    final = model_path(Path(out_path).expanduser().absolute())
    prove_writable_file(final)  # before hours of training, not after
    model_file, settings_file = checkpoint_paths(final)
    # A path names the dataset itself (a Path's own .root would be "/"); a reader's dataset, its root.
    root = dataset if isinstance(dataset, (str, os.PathLike)) else dataset.root
    settings = {
        "dataset": str(Path(root).expanduser().absolute()),
        "scenario": scenario,
        "crop": crop,
        "seed": seed,
        "n_envs": n_envs,
        "arch": arch,
        "algorithm": CLASS_NAMES[algo],
        "a2c_settings" if algo == "a2c" else "sb3_settings": chosen,
        "start_rule": "pairs",
        "keep": keep,
        "env_seeds": "streams",
    }
    if robot is not None:  # only when given: the settings of runs without one stay as they were
        from davis_ag.robot.definitions import load_robot

        definition = load_robot(robot)
        settings["robot"] = {"name": definition.name, "digest": definition.digest}
    if split_rule != "scenes":  # only then: the settings (and checkpoints) of runs before the rules stay as they were
        settings["split_rule"] = split_rule
    if task.name != TVM_TASK.name:  # only then: the settings of TVM-v0 runs stay as they were
        settings["task"] = {"name": task.name, **task.env_kwargs}
    opened = as_dataset(dataset)
    # What it learns from: evaluation refuses to score it on any of these (a split that changed
    # since, as scenes were added), and a checkpoint of another split is not resumed.
    settings["train_scenes"] = sorted(s.id for s in select_scenes(opened, scenario, "train", crop, split_rule))
    resumed = check_checkpoint(settings_file, model_file, settings, force)
    scores: list[dict[str, Any]] = []
    if resumed is not None:  # seeded as it began (a checkpoint from before the streams: seed + i)
        settings["env_seeds"] = resumed[4]
    env = make_vec_tvm(
        opened, scenario, n_envs, seed, "train", crop, cache_dir, settings["env_seeds"], robot, task, split_rule
    )
    if resumed is not None:
        _, earlier, points, scores, _ = resumed
        model = load_checkpoint(algorithm, model_file, env, device)
        # The model's own count: a stop between the checkpoint's zip and its record leaves the
        # record a checkpoint behind, and counting from it would train past the budget.
        done = int(model.num_timesteps)
        if earlier and earlier[-1].get("to_step") != done:  # that sitting made the model's steps
            earlier = [*earlier[:-1], {**earlier[-1], "to_step": done}]
        # SB3's load seeds torch, NumPy, Python and the environments with the run's seed, as at
        # step 0: every resumed sitting would replay the first one's episodes and draws.
        model.set_random_seed(resumed_training_seed(seed, done))
        print(f"resuming {final.name} from its checkpoint at {done} of {total_timesteps} steps", flush=True)
    else:
        model = algorithm(
            POLICY_NAMES.get(algo, "CnnPolicy"),
            env,
            seed=seed,
            device=device,
            verbose=verbose,
            policy_kwargs=policy_kwargs,
            **arguments,
        )
        done, earlier, points = 0, [], []
    model.set_logger(console_logger(verbose))
    sittings = Sittings(earlier, done)
    curve = LearningCurve(CURVE_EVERY, points)
    selection = None
    if keep == "best-train":
        rule = {"split_rule": split_rule} if split_rule != "scenes" else {}
        scoring_env = task.env_class(
            opened, scenario, split="train", crop=crop, cache_dir=cache_dir, robot=robot, **task.env_kwargs, **rule
        )
        selection = KeepBestOnTrain(
            scoring_env,
            final,
            select_every,
            save_model,
            scores,
            prune_at_once=not checkpoint_every,
            score=task.score,
            key=task.key,
            label=task.label,
        )
    shown = TrainingProgress(total_timesteps, f"{CLASS_NAMES[algo]} {scenario}", selection) if progress else None
    callbacks = [c for c in (callback, curve, selection, shown) if c is not None]
    if checkpoint_every:
        callbacks.append(
            CheckpointEvery(checkpoint_every, model_file, settings_file, settings, sittings, curve, selection)
        )
    written = False  # the final model is in place (what may fail after it: the training record)
    try:
        if total_timesteps > done:
            model.learn(
                total_timesteps=total_timesteps - done, callback=callbacks or None, reset_num_timesteps=done == 0
            )
        elif selection is not None:  # a checkpoint at the budget (older versions wrote one): nothing to learn
            selection.init_callback(model)
        env.close()
        curve.flush(int(model.num_timesteps))
        extra: dict[str, Any] = {}
        if selection is None:
            save_model(model, final)
        else:
            selection.score_now()  # the last snapshot competes too
            best = selection.best
            assert best is not None  # score_now has scored at least this snapshot
            # A link, not a copy: it needs no space, so a full disk cannot lose the best snapshot;
            # and the snapshot keeps its name until the record and checkpoint are done, so a run
            # stopped in between resumes with every score and snapshot it had (it then trains
            # from its last checkpoint to the budget again, and the last score is redrawn).
            publish_snapshot(snapshot_path(final, best["step"]), final)
            extra["selection"] = selection.record()
            print(
                f"kept the snapshot at {best['step']} steps (train-split {selection.score_text(best)}, "
                f"the best of {len(selection.scores)})",
                flush=True,
            )
        written = True
        write_json_atomic(training_record_path(final), training_record(settings, model, sittings, curve, extra))
    except OSError as error:  # a full disk, a folder it cannot write: keep what it trained, and say where
        if written:
            raise MachineError(what_survives(error, final, selection, model_file)) from None
        record = training_record(settings, model, sittings, curve, rescued_selection(selection, model))
        raise MachineError(
            keep_what_it_trained(error, model, total_timesteps, final, selection, model_file, record)
        ) from None
    model_file.unlink(missing_ok=True)
    settings_file.unlink(missing_ok=True)
    if selection is not None:
        selection.prune(keep_none=True)
    return final


def training_record(
    settings: dict[str, Any], model: Any, sittings: Sittings, curve: LearningCurve, extra: dict[str, Any]
) -> dict[str, Any]:
    """The training record of a run's model (:func:`training_record_path`): its settings, steps,
    sittings, speed and learning curve, with ``extra`` (the snapshot scores)."""
    steps = int(model.num_timesteps)
    record = sittings.upto(steps)
    seconds = sum(s["seconds"] for s in record)
    return {
        **settings,
        "timesteps": steps,
        "sittings": record,
        "seconds": round(seconds, 1),
        "steps_per_second": round((steps - record[0]["from_step"]) / max(seconds, 1e-9), 1),
        "curve": curve.points,
        **extra,
    }


def check_device(device: str) -> None:
    """Refuse a torch device name torch does not know, before any work.

    Raises:
        UserError: naming the device and the choices.
    """
    if device == "auto":
        return
    try:
        chosen = torch.device(device)
    except (RuntimeError, ValueError, TypeError):
        raise UserError(f"--device {device!r} is not a torch device: use auto, cpu or cuda") from None
    if chosen.type == "cuda":  # SB3 would fall back to the CPU without a word
        count = torch.cuda.device_count() if torch.cuda.is_available() else 0
        if count == 0 or (chosen.index or 0) >= count:
            have = f"cuda:0 to cuda:{count - 1}" if count else "no CUDA device"
            raise UserError(
                f"--device {device}: this machine has {have}: use auto, cpu" + (" or one of those" if count else "")
            )

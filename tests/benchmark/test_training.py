"""A2C training checkpoints and resumes: a run killed midway continues where it stopped."""

from __future__ import annotations

import json
import tempfile
from pathlib import Path

import numpy as np
import pytest
import torch
from stable_baselines3 import A2C
from stable_baselines3.common.callbacks import BaseCallback, CallbackList

from davis_ag.benchmark.algorithms import A2C_SETTINGS
from davis_ag.benchmark.selection import snapshot_path
from davis_ag.benchmark.training import check_device, checkpoint_paths, train_a2c, training_record_path
from davis_ag.errors import MachineError, UserError
from davis_ag.provenance import code_version
from davis_ag.seeds import resumed_training_seed
from kill_callback import KillAfter
from layout_factory import write_tiny_dataset

#: The smallest real training run: two environments, the tiny network, a checkpoint every 20 steps.
TINY_RUN = dict(n_envs=2, arch="pooled", device="cpu", checkpoint_every=20)


def test_a_killed_run_resumes_from_its_checkpoint(
    tmp_path: Path, one_thread: None, capsys: pytest.CaptureFixture[str], monkeypatch: pytest.MonkeyPatch
) -> None:
    system_tmp = tmp_path / "system-tmp"
    system_tmp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(system_tmp))
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "models" / "a2c"
    kwargs = dict(
        total_timesteps=240, seed=1, out_path=out, n_envs=2, arch="pooled", device="cpu", checkpoint_every=40, verbose=1
    )
    with pytest.raises(KeyboardInterrupt):
        train_a2c(root, "sp", callback=KillAfter(130), **kwargs)
    model_file, settings_file = checkpoint_paths(out)
    saved = json.loads(settings_file.read_text())
    assert 80 <= saved["timesteps_done"] <= 130 and model_file.is_file()
    # Taken between rollouts, after the last one's update: inside a rollout it lacked that update,
    # which the resumed run never made though it counted the steps.
    checkpoint = A2C.load(model_file, device="cpu")
    assert checkpoint._n_updates * checkpoint.n_steps * checkpoint.n_envs == saved["timesteps_done"]
    assert not (tmp_path / "models" / "a2c.zip").exists()  # no final model from a killed run

    path = train_a2c(root, "sp", **kwargs)
    assert f"at {saved['timesteps_done']} of 240 steps" in capsys.readouterr().out
    assert path == tmp_path / "models" / "a2c.zip"
    assert A2C.load(path, device="cpu").num_timesteps == 240  # no step trained twice or skipped
    assert not model_file.exists() and not settings_file.exists()
    # The record says it was made in two sittings, which steps each made, with what code and threads.
    record = json.loads(training_record_path(out).read_text())
    sittings = record["sittings"]
    assert [(s["from_step"], s["to_step"]) for s in sittings] == [
        (0, saved["timesteps_done"]),
        (saved["timesteps_done"], 240),
    ]
    assert all(s["code"] == code_version() and s["seconds"] > 0 for s in sittings)
    assert all(s["torch_threads"] == 1 for s in sittings)  # one_thread's: the same weights need the same count
    assert record["timesteps"] == 240 and record["seconds"] == pytest.approx(
        sum(s["seconds"] for s in sittings), abs=0.2
    )
    assert list(system_tmp.glob("SB3-*")) == []  # SB3 leaves no empty /tmp/SB3-<time> folder behind


def test_a_checkpoint_of_another_dataset_is_not_resumed(
    tmp_path: Path, one_thread: None, capsys: pytest.CaptureFixture[str]
) -> None:
    first = write_tiny_dataset(tmp_path / "first", "sp", "strawberry", scenes=2)
    second = write_tiny_dataset(tmp_path / "second", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    with pytest.raises(KeyboardInterrupt):
        train_a2c(
            first,
            "sp",
            total_timesteps=200,
            seed=1,
            out_path=out,
            **TINY_RUN,
            callback=KillAfter(60),
        )
    saved = json.loads(checkpoint_paths(out)[1].read_text())
    assert saved["dataset"] == str(Path(first).absolute())
    with pytest.raises(UserError, match=r"checkpoint of another run .*another dataset.*--force"):
        train_a2c(
            second,
            "sp",
            total_timesteps=100,
            seed=1,
            out_path=out,
            **TINY_RUN,
        )  # never discarded without a word
    train_a2c(
        second,
        "sp",
        total_timesteps=100,
        seed=1,
        out_path=out,
        **TINY_RUN,
        force=True,
    )
    assert "resuming" not in capsys.readouterr().out


def test_a_checkpoint_from_before_datasets_were_recorded_still_resumes(
    tmp_path: Path, one_thread: None, capsys: pytest.CaptureFixture[str]
) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    with pytest.raises(KeyboardInterrupt):
        train_a2c(
            root,
            "sp",
            total_timesteps=200,
            seed=1,
            out_path=out,
            **TINY_RUN,
            callback=KillAfter(60),
        )
    settings_file = checkpoint_paths(out)[1]
    saved = json.loads(settings_file.read_text())
    older = {k: v for k, v in saved.items() if k != "env_seeds"}
    settings_file.write_text(json.dumps({**older, "dataset": "/"}))  # as earlier versions wrote it
    train_a2c(
        root,
        "sp",
        total_timesteps=200,
        seed=1,
        out_path=out,
        **TINY_RUN,
    )
    assert "resuming" in capsys.readouterr().out
    # It went on as it began: its environments seeded seed + i, as the record says.
    assert json.loads(training_record_path(out).read_text())["env_seeds"] == "seed+i"


def test_a_model_is_never_scored_on_the_scenes_it_learnt_from(
    tmp_path: Path, one_thread: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """The split depends on the group's scene count: scenes added after training move some train
    scenes into the test split. The record lists the train scenes; evaluation refuses a test split
    holding one, a checkpoint of another split is not resumed, and one from before the list
    was recorded still is (a run under way keeps its hours)."""
    from davis_ag.benchmark import evaluate
    from davis_ag.benchmark.policies import ModelPolicy

    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    with pytest.raises(KeyboardInterrupt):
        train_a2c(root, "sp", total_timesteps=100, seed=1, out_path=out, **TINY_RUN, callback=KillAfter(50))
    settings_file = checkpoint_paths(out)[1]
    saved = json.loads(settings_file.read_text())
    assert saved["train_scenes"] == ["Single-Strawberry/000"]
    settings_file.write_text(json.dumps({k: v for k, v in saved.items() if k != "train_scenes"}))  # older
    train_a2c(root, "sp", total_timesteps=100, seed=1, out_path=out, **TINY_RUN)
    assert "resuming" in capsys.readouterr().out
    assert json.loads(training_record_path(out).read_text())["train_scenes"] == ["Single-Strawberry/000"]
    assert evaluate([ModelPolicy(out)], root, "sp", sessions=1, episodes=2).policies  # its own test split
    # The split changes (here by hand): the scene it learnt from is now a test scene.
    splits = root / "splits.json"
    splits.write_text(
        json.dumps(
            {**json.loads(splits.read_text()), "train": [], "test": ["Single-Strawberry/000", "Single-Strawberry/001"]}
        )
    )
    with pytest.raises(UserError, match=r"trained on 1 of the 2 test scenes .*Single-Strawberry/000.*train it again"):
        evaluate([ModelPolicy(out)], root, "sp", sessions=1, episodes=2)
    # A checkpoint of one split is not resumed on another.
    original = {"train": ["Single-Strawberry/000"], "test": ["Single-Strawberry/001"]}
    splits.write_text(json.dumps({**json.loads(splits.read_text()), **original}))
    with pytest.raises(KeyboardInterrupt):
        train_a2c(
            root, "sp", total_timesteps=100, seed=1, out_path=tmp_path / "b.zip", **TINY_RUN, callback=KillAfter(50)
        )
    swapped = {"train": ["Single-Strawberry/001"], "test": ["Single-Strawberry/000"]}
    splits.write_text(json.dumps({**json.loads(splits.read_text()), **swapped}))
    with pytest.raises(UserError, match="another train split"):
        train_a2c(root, "sp", total_timesteps=100, seed=1, out_path=tmp_path / "b.zip", **TINY_RUN)


def test_a_model_is_never_scored_on_another_split_rules_test_split(tmp_path: Path, one_thread: None) -> None:
    """Issue 59: under --split-rule starts a model trains on 70 % of every scene's starts, so the
    scenes rule's test scenes hold starts it learnt from, and the scenes rule's train scenes hold
    the starts rule's test starts: each is refused, in one line, on the other's test split."""
    from davis_ag.benchmark import evaluate
    from davis_ag.benchmark.policies import ModelPolicy

    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    train_a2c(root, "sp", total_timesteps=40, seed=1, out_path=out, split_rule="starts", **TINY_RUN)
    record_file = training_record_path(out)
    record = json.loads(record_file.read_text())
    assert record["split_rule"] == "starts"
    assert record["train_scenes"] == ["Single-Strawberry/000", "Single-Strawberry/001"]  # both sides' scenes
    scored = evaluate([ModelPolicy(out)], root, "sp", sessions=1, episodes=2, split_rule="starts")
    assert scored.protocol.split_rule == "starts"
    with pytest.raises(UserError, match=r"trained under --split-rule starts.*evaluate it with --split-rule starts"):
        evaluate([ModelPolicy(out)], root, "sp", sessions=1, episodes=2)
    # The same model as a scenes run records it (no rule: runs from before the rules resume).
    record_file.write_text(json.dumps({k: v for k, v in record.items() if k != "split_rule"}))
    with pytest.raises(UserError, match=r"^A2C: trained under --split-rule scenes, whose train side overlaps"):
        evaluate([ModelPolicy(out)], root, "sp", sessions=1, episodes=2, split_rule="starts")
    assert evaluate([ModelPolicy(out)], root, "sp", split="train", sessions=1, episodes=2, split_rule="starts")
    # A checkpoint of one rule is not resumed under another, and says so.
    with pytest.raises(KeyboardInterrupt):
        train_a2c(
            root,
            "sp",
            total_timesteps=80,
            out_path=tmp_path / "b",
            split_rule="starts",
            callback=KillAfter(30),
            **TINY_RUN,
        )
    with pytest.raises(UserError, match=r"checkpoint of another run \(split rule 'starts', not 'scenes'\)"):
        train_a2c(root, "sp", total_timesteps=80, out_path=tmp_path / "b", **TINY_RUN)
    with pytest.raises(UserError, match="--split-rule starts splits TVM-v0's starts; mapping splits by scenes"):
        from davis_ag.mapping.training import mapping_task

        train_a2c(root, "sp", total_timesteps=40, out_path=out, split_rule="starts", task=mapping_task(None, 0.5))


def test_runs_of_different_seeds_share_no_episode_stream(tmp_path: Path) -> None:
    """SB3 seeds environment i with seed + i, so environment 1 of a seed-0 run replayed the starts
    of environment 0 of a seed-1 run: runs meant as independent seeds shared 7 of 8 streams."""
    from davis_ag.benchmark.training import make_vec_tvm

    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)

    def states(seed: int, scheme: str) -> list[dict]:
        env = make_vec_tvm(root, "sp", 3, seed, "all", env_seeds=scheme)
        env.reset()
        return [each.unwrapped.np_random.bit_generator.state for each in env.envs]

    old = {seed: states(seed, "seed+i") for seed in (0, 1)}
    assert old[0][1] == old[1][0]  # the overlap, kept for runs begun before the streams
    new = {seed: states(seed, "streams") for seed in (0, 1)}
    assert not any(a == b for a in new[0] for b in new[1])
    assert new[0] == states(0, "streams")  # and each run as reproducible as before


@pytest.mark.parametrize("algo", ["a2c", "ppo"])
def test_a_seed_makes_the_same_model_bit_for_bit_and_another_seed_another(
    algo: str, tmp_path: Path, one_thread: None
) -> None:
    """Every random choice of a training run flows from its seed: two uninterrupted runs of the
    same seed on the same machine keep the same snapshot with the same weights (what lets a
    reproduce run's learner rows be made again), and another seed trains another model."""
    from davis_ag.benchmark.sb3_models import load_model
    from davis_ag.benchmark.training import train_agent

    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=3)
    settings = "ours" if algo == "a2c" else {"n_steps": 16, "batch_size": 32}

    def weights(seed: int, name: str) -> list[np.ndarray]:
        out = train_agent(
            root,
            "sp",
            total_timesteps=192,
            seed=seed,
            out_path=tmp_path / name,
            n_envs=2,
            arch="pooled",
            device="cpu",
            algo=algo,
            settings=settings,
            select_every=96,
            progress=False,
        )
        model = load_model(out)
        return [p.detach().numpy().copy() for p in model.policy.parameters()]

    first, again, other = weights(0, "first"), weights(0, "again"), weights(1, "other")
    assert all(np.array_equal(a, b) for a, b in zip(first, again, strict=True))
    assert not all(np.array_equal(a, b) for a, b in zip(first, other, strict=True))


def test_other_settings_never_resume_a_checkpoint(
    tmp_path: Path, one_thread: None, capsys: pytest.CaptureFixture[str]
) -> None:
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    with pytest.raises(KeyboardInterrupt):
        train_a2c(
            root,
            "sp",
            total_timesteps=200,
            seed=1,
            out_path=out,
            **TINY_RUN,
            callback=KillAfter(60),
        )
    with pytest.raises(UserError, match="seed 1, not 2"):
        train_a2c(
            root,
            "sp",
            total_timesteps=100,
            seed=2,
            out_path=out,
            **TINY_RUN,
        )
    path = train_a2c(
        root,
        "sp",
        total_timesteps=100,
        seed=2,
        out_path=out,
        **TINY_RUN,
        force=True,
    )
    assert "resuming" not in capsys.readouterr().out
    assert A2C.load(path, device="cpu").num_timesteps == 100


def test_the_record_keeps_the_settings_and_a_learning_curve_across_sittings(
    tmp_path: Path, one_thread: None, monkeypatch: pytest.MonkeyPatch
) -> None:
    import davis_ag.benchmark.training as training

    monkeypatch.setattr(training, "CURVE_EVERY", 20)
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    kwargs = dict(total_timesteps=240, seed=1, out_path=out, n_envs=2, arch="pooled", device="cpu", checkpoint_every=40)
    with pytest.raises(KeyboardInterrupt):
        train_a2c(root, "sp", callback=KillAfter(130), **kwargs)
    first = json.loads(checkpoint_paths(out)[1].read_text())["curve"]
    train_a2c(root, "sp", **kwargs)
    record = json.loads(training_record_path(out).read_text())
    assert record["a2c_settings"] == A2C_SETTINGS and record["start_rule"] == "pairs"
    curve = record["curve"]
    steps = [p["step"] for p in curve]
    assert steps == sorted(set(steps)) and steps[-1] == 240
    assert curve[: len(first)] == first and len(curve) > len(first)  # the first sitting's points kept
    # tau = 3 steps at most, so 240 steps end about 80 episodes or more (those in flight at a
    # kill are lost); each point's reward is section V-C's, within [0, 1].
    assert sum(p["episodes"] for p in curve) >= 240 // 3 - 2
    assert all(0 <= p["reward"] <= 1 and 1 <= p["length"] <= 3 for p in curve)
    model = A2C.load(out, device="cpu")
    assert model.ent_coef == A2C_SETTINGS["ent_coef"]
    assert model.normalize_advantage == A2C_SETTINGS["normalize_advantage"]


def test_settings_choose_the_sb3_defaults_or_refuse_unknown_ones(
    tmp_path: Path, one_thread: None, capsys: pytest.CaptureFixture[str]
) -> None:
    from davis_ag.benchmark.algorithms import SB3_DEFAULT_SETTINGS

    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    with pytest.raises(UserError, match="learning_rat"):
        train_a2c(root, "sp", total_timesteps=20, out_path=out, arch="pooled", settings={"learning_rat": 1})
    with pytest.raises(UserError, match="unknown A2C settings"):
        train_a2c(root, "sp", total_timesteps=20, out_path=out, arch="pooled", settings="fast")
    # A checkpoint from before settings were recorded was trained with SB3's defaults on starts
    # drawn scene first: today's runs never resume it.
    with pytest.raises(KeyboardInterrupt):
        train_a2c(
            root,
            "sp",
            total_timesteps=200,
            seed=1,
            out_path=out,
            **TINY_RUN,
            callback=KillAfter(60),
            settings="sb3",
        )
    settings_file = checkpoint_paths(out)[1]
    saved = json.loads(settings_file.read_text())
    assert saved["a2c_settings"] == SB3_DEFAULT_SETTINGS
    del saved["a2c_settings"], saved["start_rule"]
    settings_file.write_text(json.dumps(saved))
    train_a2c(
        root,
        "sp",
        total_timesteps=200,
        seed=1,
        out_path=out,
        n_envs=2,
        arch="pooled",
        device="cpu",
        checkpoint_every=0,
        settings="ours",
        force=True,
    )
    assert "resuming" not in capsys.readouterr().out


def test_a_damaged_checkpoint_offers_both_ways_on(tmp_path: Path, one_thread: None) -> None:
    """Issue 33 case 4: a checkpoint that is no zip ended in a chained traceback."""
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    kwargs = dict(
        total_timesteps=60,
        seed=1,
        out_path=out,
        **TINY_RUN,
        keep="last",
    )
    with pytest.raises(KeyboardInterrupt):
        train_a2c(root, "sp", callback=KillAfter(40), **kwargs)
    model_file = checkpoint_paths(out)[0]
    model_file.write_bytes(model_file.read_bytes()[:100])  # cut short, as a full disk or a bad copy leaves it
    with pytest.raises(UserError) as refused:
        train_a2c(root, "sp", **kwargs)
    line = str(refused.value)
    assert "\n" not in line and "damaged" in line and "--force" in line and "stop here" in line
    assert model_file.read_bytes()[:2] == b"PK"  # left as it was
    assert train_a2c(root, "sp", force=True, **kwargs) == out and A2C.load(out, device="cpu").num_timesteps == 60


@pytest.mark.parametrize("keep", ["best-train", "last"])
def test_a_full_disk_at_the_end_never_loses_the_model(
    tmp_path: Path, one_thread: None, keep: str, monkeypatch: pytest.MonkeyPatch
) -> None:
    """Issue 33 case 3: with --keep best-train a full disk at the final write kept no model anywhere,
    though the line said nothing finished was lost. Every write after the disk fills fails
    (``os.fsync``, as a write-back of a full disk does); the line names a file that holds a model."""
    import errno
    import os

    from stable_baselines3.common.callbacks import BaseCallback

    import davis_ag.atomic_files as atomic_files

    monkeypatch.setenv("XDG_CACHE_HOME", str(tmp_path / "cache"))
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "a2c.zip"
    full = {"now": False}
    real_fsync = os.fsync

    def fsync(fd: int) -> None:
        if full["now"]:
            raise OSError(errno.ENOSPC, os.strerror(errno.ENOSPC))
        real_fsync(fd)

    class DiskFillsAt(BaseCallback):
        def _on_step(self) -> bool:
            full["now"] = full["now"] or self.model.num_timesteps >= 50
            return True

    monkeypatch.setattr(atomic_files.os, "fsync", fsync)
    with pytest.raises(MachineError) as stopped:
        train_a2c(
            root,
            "sp",
            total_timesteps=60,
            seed=1,
            out_path=out,
            **TINY_RUN,
            keep=keep,
            select_every=20,
            callback=DiskFillsAt(),
        )
    line = str(stopped.value)
    assert "No space left on device" in line and "\n" not in line and "is kept in" in line
    kept = Path(line.split("is kept in ")[1].split(":")[0])
    assert kept.is_file() and A2C.load(kept, device="cpu").num_timesteps in (20, 40)
    if keep == "best-train":
        assert kept == snapshot_path(out, A2C.load(kept, device="cpu").num_timesteps)


def test_a_cuda_device_the_machine_lacks_is_refused() -> None:
    """Issue 33 case 9: --device cuda:7 trained on the CPU without a word."""
    import torch

    count = torch.cuda.device_count() if torch.cuda.is_available() else 0
    with pytest.raises(UserError, match=f"--device cuda:{count + 6}: this machine has"):
        check_device(f"cuda:{count + 6}")
    check_device("cpu")


@pytest.mark.parametrize("algo", ["ppo", "dqn"])
def test_ppo_and_dqn_train_resume_and_keep_the_best(
    algo: str,
    sp_root: Path,
    tmp_path: Path,
    one_thread: None,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    """The same record, checkpoints, resume and keep-best-train rule as A2C, for each algorithm;
    progress goes to the log as lines (not a terminal here)."""
    import stable_baselines3

    from davis_ag.benchmark import algorithms, progress, training
    from davis_ag.benchmark.sb3_models import model_algorithm

    out = tmp_path / algo
    short = {"ppo": {"n_steps": 20, "batch_size": 20}, "dqn": {"learning_starts": 40}}[
        algo
    ]  # SB3's: 4,096-step rollouts
    kwargs = dict(
        total_timesteps=240,
        seed=1,
        out_path=out,
        n_envs=2,
        arch="pooled",
        device="cpu",
        checkpoint_every=80,
        select_every=120,
        algo=algo,
        settings=short,
    )
    with pytest.raises(KeyboardInterrupt):
        training.train_agent(sp_root, "sp", callback=KillAfter(170), **kwargs)
    assert json.loads(checkpoint_paths(out)[1].read_text())["timesteps_done"] == 160
    monkeypatch.setattr(progress, "PROGRESS_EVERY_S", 0.0)  # a log line per step, not one a minute
    path = training.train_agent(sp_root, "sp", **kwargs)
    printed = capsys.readouterr()
    assert f"resuming {algo}.zip from its checkpoint at 160 of 240 steps" in printed.out
    assert f"{algo.upper()} sp: 100%" in printed.err and "step/s" in printed.err and "train OER_tau" in printed.err
    assert model_algorithm(path) == algo.upper()
    model = getattr(stable_baselines3, algo.upper()).load(path, device="cpu")
    record = json.loads(training_record_path(out).read_text())
    assert record["algorithm"] == algo.upper() and record["sb3_settings"] == {**algorithms.SB3_SETTINGS[algo], **short}
    assert [(s["from_step"], s["to_step"]) for s in record["sittings"]] == [(0, 160), (160, 240)]
    kept = record["selection"]
    assert kept["kept_step"] == max(kept["scores"], key=lambda s: (s["oer_tau"], -s["step"]))["step"]
    assert model.num_timesteps == kept["kept_step"]
    if algo == "ppo":  # the zoo's lin_ schedules survive the checkpoint: 2.5e-4 falling to 0
        assert model.lr_schedule(1.0) == pytest.approx(2.5e-4) and model.lr_schedule(0.0) == 0.0


class _SavesInTwoWrites:
    """A model whose save is cut by a stop (Ctrl-C) between its two writes, as a signal may cut
    torch's zip writer."""

    def save(self, handle) -> None:  # type: ignore[no-untyped-def]
        import signal

        from davis_ag.errors import stop

        handle.write(b"first half,")
        stop(signal.SIGINT)
        handle.write(b" second half")


def test_a_stop_while_a_model_saves_waits_for_the_whole_file(tmp_path: Path) -> None:
    """Ctrl-C during a checkpoint's save: the stop comes once the file is whole, never as torch's
    error from a half-written zip (a CI run caught ``train`` exiting 1 with that traceback)."""
    from davis_ag.benchmark.checkpoints import save_model
    from davis_ag.errors import Stopped

    path = tmp_path / "a2c.checkpoint.zip"
    with pytest.raises(Stopped):
        save_model(_SavesInTwoWrites(), path)
    assert path.read_bytes() == b"first half, second half"


class _FirstObservation(BaseCallback):
    """What a sitting starts from: its environments' first observations and torch's seed."""

    def __init__(self) -> None:
        super().__init__()
        self.seen: list[tuple] = []

    def _on_training_start(self) -> None:
        self.seen.append((self.model._last_obs.copy(), torch.initial_seed()))

    def _on_step(self) -> bool:
        return True


def test_a_resumed_sitting_draws_its_own_episodes(tmp_path: Path, one_thread: None) -> None:
    """SB3's load seeds everything with the run's seed, as at step 0: a resumed sitting replayed
    the first one's episode starts and action draws. It draws from its own stream now."""
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    kwargs = dict(total_timesteps=240, seed=1, out_path=tmp_path / "a2c", keep="last", **TINY_RUN)
    first = _FirstObservation()
    with pytest.raises(KeyboardInterrupt):
        train_a2c(root, "sp", callback=CallbackList([first, KillAfter(130)]), **kwargs)
    done = json.loads(checkpoint_paths(tmp_path / "a2c")[1].read_text())["timesteps_done"]
    second = _FirstObservation()
    train_a2c(root, "sp", callback=second, **kwargs)
    (obs_1, torch_1), (obs_2, torch_2) = first.seen[0], second.seen[0]
    assert torch_1 == 1 and torch_2 == resumed_training_seed(1, done)
    assert not np.array_equal(obs_1, obs_2)  # other starts, not sitting 1's again


def test_a_checkpoint_whose_record_lags_its_model_keeps_the_budget(tmp_path: Path, one_thread: None) -> None:
    """A stop between the checkpoint's zip and its record left the record a checkpoint behind;
    counting from it trained past the budget (the record said 260 of 240 steps)."""
    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    kwargs = dict(total_timesteps=240, seed=1, out_path=tmp_path / "a2c", keep="last", **TINY_RUN)
    with pytest.raises(KeyboardInterrupt):
        train_a2c(root, "sp", callback=KillAfter(130), **kwargs)
    settings_file = checkpoint_paths(tmp_path / "a2c")[1]
    saved = json.loads(settings_file.read_text())
    done = saved["timesteps_done"]
    settings_file.write_text(json.dumps({**saved, "timesteps_done": done - 20}))  # the zip is 20 steps ahead
    path = train_a2c(root, "sp", **kwargs)
    record = json.loads(training_record_path(path).read_text())
    assert A2C.load(path, device="cpu").num_timesteps == 240 and record["timesteps"] == 240
    assert [(s["from_step"], s["to_step"]) for s in record["sittings"]] == [(0, done), (done, 240)]  # no gap


def test_the_zoos_atari_preset_trains_16_environments_with_tf_like_rmsprop(
    tmp_path: Path, one_thread: None, capsys: pytest.CaptureFixture[str]
) -> None:
    """``davis-ag train --a2c-settings zoo-atari``: the preset's 16 environments and optimiser are
    the model's, and the record names both; ``--n-envs`` given over it is what trains and is recorded."""
    from stable_baselines3.common.sb2_compat.rmsprop_tf_like import RMSpropTFLike

    from davis_ag import cli

    root = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2)
    out = tmp_path / "zoo.zip"
    argv = ["train", "--dataset", str(root), "--scenario", "sp", "--timesteps", "80", "--arch", "pooled"]
    argv += ["--device", "cpu", "--checkpoint-every", "0", "--keep", "last", "--verbose", "0"]
    assert cli.main([*argv, "--a2c-settings", "zoo-atari", "--out", str(out)]) == 0
    model = A2C.load(out, device="cpu")
    assert model.n_envs == 16 and model.vf_coef == 0.25 and model.ent_coef == 0.01
    assert isinstance(model.policy.optimizer, RMSpropTFLike)
    assert model.policy.optimizer.defaults["eps"] == 1e-5
    record = json.loads(training_record_path(out).read_text())
    assert record["n_envs"] == 16 and record["a2c_settings"]["n_envs"] == 16
    assert record["a2c_settings"]["policy_kwargs"]["optimizer_class"] == "RMSpropTFLike"
    fewer = tmp_path / "fewer.zip"
    assert cli.main([*argv, "--a2c-settings", "zoo-atari", "--n-envs", "2", "--out", str(fewer)]) == 0
    record = json.loads(training_record_path(fewer).read_text())
    assert A2C.load(fewer, device="cpu").n_envs == 2 and record["n_envs"] == 2 and record["a2c_settings"]["n_envs"] == 2
    assert isinstance(A2C.load(fewer, device="cpu").policy.optimizer, RMSpropTFLike)

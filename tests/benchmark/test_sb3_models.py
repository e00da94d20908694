"""Every Stable-Baselines3 and sb3-contrib model: the algorithm read from the zip, recurrent
policies with their memory, MaskablePPO with the environment's mask, all scored and replayed."""

from __future__ import annotations

import json
import sys
import zipfile
from pathlib import Path

import pytest

from davis_ag.benchmark import TVMEnv
from davis_ag.benchmark.evaluation import evaluate, play_episodes, run_episode
from davis_ag.benchmark.policies import ModelPolicy, prepare
from davis_ag.benchmark.replay import replay_grid
from davis_ag.benchmark.sb3_models import model_algorithm
from davis_ag.errors import UserError
from davis_ag.mapping.env import RowMappingEnv
from layout_factory import write_tiny_dataset

sb3_contrib = pytest.importorskip("sb3_contrib")


@pytest.fixture(scope="module")
def root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_tiny_dataset(tmp_path_factory.mktemp("sp"), "sp", "strawberry", scenes=2)


def _kwargs() -> dict:
    from davis_ag.benchmark.networks import PooledFeatures

    return {"features_extractor_class": PooledFeatures}


@pytest.fixture(scope="module")
def models(root: Path, tmp_path_factory: pytest.TempPathFactory) -> dict[str, Path]:
    """A RecurrentPPO, a QR-DQN, a TRPO and a MaskablePPO, each trained a few hundred steps."""
    folder = tmp_path_factory.mktemp("models")
    env = TVMEnv(root, "sp", split="train")
    made = {
        "RecurrentPPO": sb3_contrib.RecurrentPPO(
            "CnnLstmPolicy", env, n_steps=32, batch_size=32, policy_kwargs={**_kwargs(), "lstm_hidden_size": 16}, seed=0
        ),
        "QRDQN": sb3_contrib.QRDQN(
            "CnnPolicy", env, buffer_size=500, learning_starts=50, policy_kwargs=_kwargs(), seed=0
        ),
        "TRPO": sb3_contrib.TRPO("CnnPolicy", env, n_steps=64, batch_size=32, policy_kwargs=_kwargs(), seed=0),
        "MaskablePPO": sb3_contrib.MaskablePPO(
            "CnnPolicy", env, n_steps=32, batch_size=32, policy_kwargs=_kwargs(), seed=0
        ),
    }
    paths = {}
    for name, model in made.items():
        model.learn(128 if name != "QRDQN" else 100)
        model.save(folder / f"{name}.zip")
        paths[name] = folder / f"{name}.zip"
    return paths


def test_the_algorithm_is_read_from_the_zip(models: dict[str, Path]) -> None:
    for name, path in models.items():
        assert model_algorithm(path) == name


def test_each_model_is_scored_beside_the_baselines_and_replays_sound(root: Path, models: dict[str, Path]) -> None:
    results = evaluate(
        [str(p) for p in models.values()], root, "sp", "test", sessions=1, episodes=6, baselines=["Rand"]
    )
    assert {"RecurrentPPO", "QRDQN", "TRPO", "MaskablePPO", "Rand"} <= set(results.policies)
    assert results.policies["QRDQN"].play == "deterministic"  # a Q-learner plays its greedy action
    assert replay_grid(results, root, "models.json").sound


def test_a_recurrent_model_plays_the_same_episodes_batched_and_alone(root: Path, models: dict[str, Path]) -> None:
    env = TVMEnv(root, "sp", split="test")
    policy = ModelPolicy(models["RecurrentPPO"])
    assert policy.recurrent and policy.batches
    prepare(policy, env)
    resets, draws = list(range(10, 22)), list(range(100, 112))
    batched = play_episodes(env, policy, resets, draws)
    alone = [run_episode(env, policy, r, d, prepared=True) for r, d in zip(resets, draws)]
    assert [b["actions"] for b in batched] == [a["actions"] for a in alone]
    first = evaluate([str(models["RecurrentPPO"])], root, "sp", "test", sessions=1, episodes=5, baselines=False)
    second = evaluate([str(models["RecurrentPPO"])], root, "sp", "test", sessions=1, episodes=5, baselines=False)
    assert first.policies == second.policies  # a sampled play, deterministic for a seed


def test_the_memory_starts_afresh_each_episode(root: Path, models: dict[str, Path]) -> None:
    env = TVMEnv(root, "sp", split="test")
    policy = ModelPolicy(models["RecurrentPPO"], deterministic=True)
    prepare(policy, env)
    a = run_episode(env, policy, 3, 0, prepared=True)
    run_episode(env, policy, 4, 0, prepared=True)  # another episode between: its memory must not leak
    assert run_episode(env, policy, 3, 0, prepared=True)["actions"] == a["actions"]


def test_maskable_ppo_never_plays_a_refused_move(root: Path, models: dict[str, Path]) -> None:
    env = TVMEnv(root, "sp", split="test", tau=8)
    policy = ModelPolicy(models["MaskablePPO"])
    assert not policy.batches
    prepare(policy, env)
    for seed in range(8):
        obs, info = env.reset(seed=seed)
        policy.reset(seed)
        over = False
        while not over:
            masks = env.action_masks()
            action = int(policy.act(obs, info))
            assert masks[action]
            obs, _, over, _, info = env.step(action)
    mapping = RowMappingEnv(root, "sp", split="test")
    mapping.reset(seed=0)
    assert mapping.action_masks().shape == (mapping.action_space.n,)


def test_a_zip_that_is_not_a_model_and_an_unknown_algorithm_are_one_line(
    tmp_path: Path, models: dict[str, Path]
) -> None:
    junk = tmp_path / "junk.zip"
    with zipfile.ZipFile(junk, "w") as archive:
        archive.writestr("readme.txt", "not a model")
    with pytest.raises(UserError, match="not a Stable-Baselines3 model"):
        model_algorithm(junk)
    other = tmp_path / "other.zip"
    with zipfile.ZipFile(models["TRPO"]) as source, zipfile.ZipFile(other, "w") as archive:
        for item in source.namelist():
            body = source.read(item)
            if item == "data":
                data = json.loads(body)
                data["policy_class"]["__module__"] = "someone_elses_rl.policies"
                body = json.dumps(data).encode()
            archive.writestr(item, body)
    with pytest.raises(UserError, match="an algorithm davis-ag does not play; it plays A2C"):
        model_algorithm(other)


def test_a_contrib_model_without_sb3_contrib_names_the_extra(
    models: dict[str, Path], monkeypatch: pytest.MonkeyPatch
) -> None:
    monkeypatch.setitem(sys.modules, "sb3_contrib", None)  # import sb3_contrib now fails
    with pytest.raises(UserError, match=r"needs sb3-contrib.*davis-ag\[contrib\]"):
        ModelPolicy(models["QRDQN"])


@pytest.mark.parametrize(
    ("algo", "settings"),
    [
        ("recurrentppo", {"n_steps": 16, "batch_size": 32}),
        ("qrdqn", {"learning_starts": 16, "buffer_size": 200}),
        ("trpo", {"n_steps": 16, "batch_size": 32}),
        ("maskableppo", {"n_steps": 16, "batch_size": 32}),
    ],
)
def test_train_trains_each_contrib_algorithm(root: Path, tmp_path: Path, algo: str, settings: dict) -> None:
    from davis_ag.benchmark.training import train_agent, training_record_path

    out = train_agent(
        root, "sp", total_timesteps=64, n_envs=2, arch="pooled", out_path=tmp_path / f"{algo}.zip",
        checkpoint_every=0, select_every=32, progress=False, algo=algo, settings=settings,
    )  # fmt: skip
    record = json.loads(training_record_path(out).read_text())
    assert model_algorithm(out) == record["algorithm"] and record["selection"]["scores"]
    results = evaluate([str(out)], root, "sp", "test", sessions=1, episodes=3, baselines=False)
    assert replay_grid(results, root, f"{algo}.json").sound

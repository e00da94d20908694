"""TVMContinuous-v0: the checkers, the rules of a move, seeding, the reward; its policies, a
brief PPO run and `davis-ag evaluate --env continuous`."""

from __future__ import annotations

import json
import tempfile
from dataclasses import replace
from pathlib import Path

import gymnasium
import numpy as np
import pytest

from davis_ag import cli
from davis_ag.benchmark import CONTINUOUS_ID
from davis_ag.benchmark.evaluation import evaluate_policies
from davis_ag.benchmark.policies import ModelPolicy
from davis_ag.errors import UserError
from davis_ag.figures.result_charts import plot_training_curve
from davis_ag.live.policies import Greedy, RandomAxes, build_policies
from davis_ag.live.scene import LiveScene
from davis_ag.live.training import train_continuous
from davis_ag.live.tvm_continuous import TVMContinuousEnv
from davis_ag.scene.specs import SLIP_SIGMA, with_strawberry_altitudes
from davis_ag.workflows.bench.run import steps_per_second


@pytest.fixture(scope="module")
def env(live_scene_dir: Path) -> TVMContinuousEnv:
    """The registered environment on the test scene, aimed at the plant (the SP default)."""
    made = gymnasium.make(CONTINUOUS_ID, dataset=str(live_scene_dir), scenario="sp")
    yield made.unwrapped
    made.close()


@pytest.fixture(scope="module")
def free_env(live_scene_dir: Path) -> TVMContinuousEnv:
    """Free yaw and pitch, long moves (to cross the exclusion zone in one move)."""
    made = TVMContinuousEnv(live_scene_dir, "sp", aim="free", max_move=3.0, max_turn=180.0)
    yield made
    made.close()


def test_gymnasium_and_sb3_checkers_pass(env: TVMContinuousEnv) -> None:
    from gymnasium.utils.env_checker import check_env
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    check_env(env, skip_render_check=True)
    sb3_check_env(env)
    assert env.observation_space.shape == (224, 224, 4) and env.action_space.shape == (3,)


def test_a_full_action_follows_each_scene_s_own_grid(live_scene_dir: Path) -> None:
    """One grid step, half the altitude span and one heading's turn, of the scene being played:
    the scales were the first scene's for every scene (a tomato scene climbed strawberry's span)
    and the turn was fixed at 30 degrees whatever the grid's headings."""
    with TVMContinuousEnv(live_scene_dir, "sp", aim="free") as made:
        settings = made.scenes[0].settings
        altitudes = [settings.crop.altitudes[i] for i in settings.scenario.altitude_levels]
        assert made.max_move == settings.scenario.step == 0.5
        assert made.max_climb == pytest.approx((max(altitudes) - min(altitudes)) / 2)
        assert made.max_turn == 30.0  # one heading: the MP grid's turn
        # Another scene of the split on a reduced grid of four headings, a longer step and the
        # readme's altitudes: its own scales once it is the one played.
        other = replace(
            settings,
            scenario=replace(settings.scenario, step=1.0, headings=4),
            crop=with_strawberry_altitudes(settings.crop, "readme"),
        )
        made.scenes.append(LiveScene(other, made.scenes[0].assets))
        made._scene = 1
        assert (made.max_move, made.max_turn) == (1.0, 90.0)
        assert made.max_climb == pytest.approx((0.75 - 0.50) / 2)  # levels 0 and 1 of 0.50/0.75/1.00 m
        made.scenes.pop()
    with TVMContinuousEnv(live_scene_dir, "sp", max_move=0.3, max_climb=0.1, max_turn=10.0) as given:
        assert (given.max_move, given.max_climb, given.max_turn) == (0.3, 0.1, 10.0)


def test_reset_options_choose_the_scene_or_are_refused(env: TVMContinuousEnv) -> None:
    """{"scene": i} without a pose was ignored (a random scene was drawn); unknown keys too."""
    _, info = env.reset(seed=1, options={"scene": 0})
    assert info["scene"] == env.scenes[0].settings.metadata.scene
    for bad in ({"scene": 5}, {"scene": "0"}, {"target_fruit": 3}, {"target": 3}):
        with pytest.raises(UserError, match="reset options"):
            env.reset(seed=1, options=bad)


def test_a_seed_fixes_the_start_and_the_slip(env: TVMContinuousEnv) -> None:
    def episode(seed: int) -> tuple[np.ndarray, list]:
        obs, info = env.reset(seed=seed)
        for action in ([0.7, 0.2, 0.5], [-0.3, -0.9, 0.0], [0.0, 0.0, 0.0]):
            _last, _, _, _, info = env.step(np.array(action, dtype=np.float32))
        return obs, info["path"]

    first, again, other = episode(3), episode(3), episode(4)
    assert np.array_equal(first[0], again[0]) and first[1] == again[1]
    assert first[1] != other[1]


def test_the_observation_is_the_view_and_the_targets_box(env: TVMContinuousEnv) -> None:
    obs, info = env.reset(seed=0)
    x0, y0, w, h = env._labels.box(env.target)[:4]
    box = np.zeros((224, 224), bool)
    box[y0 : y0 + h, x0 : x0 + w] = True
    assert np.array_equal(obs[..., 3] == 255, box) and set(np.unique(obs[..., 3])) == {0, 255}
    assert np.array_equal(obs[..., :3], env._labels.colour)
    assert info["oer_0"] < 0.4  # section V-D's start condition
    assert info["oer_0"] == pytest.approx((env._labels.segmentation[box] == env.target).sum() / box.sum())


def test_reward_is_the_squared_oer_gain_at_the_end(env: TVMContinuousEnv) -> None:
    for seed in range(3):
        _, info = env.reset(seed=seed)
        rewards = []
        for t in range(env.tau):
            _, reward, terminated, truncated, info = env.step(env.action_space.sample())
            rewards.append(reward)
            assert terminated == (t == env.tau - 1) and not truncated
        assert rewards[:-1] == [0.0] * (env.tau - 1)
        assert rewards[-1] == pytest.approx(max(info["oer_t"] - info["oer_0"], 0.0) ** 2)
    with pytest.raises(UserError, match="reset"):
        env.step(env.action_space.sample())
    env.reset(seed=0)
    with pytest.raises(UserError, match="3 finite numbers"):
        env.step(np.array([np.nan, 0, 0]))


def _start(env: TVMContinuousEnv, x: float, y: float, z: float, yaw: float = 0.0) -> dict:
    """Reset at a pose aimed at the plant, targeting its best-boxed fruit."""
    view = env.scenes[0].aimed_pose(x, y, z)
    labels = env.scenes[0].render(view, 224, 224, antialiasing="none", fractions=False, fast_ground=True)
    target = max(labels.oer, key=lambda f: labels.visible_pixels[f])
    _, info = env.reset(
        seed=0, options={"pose": [x, y, z, view.yaw if yaw == 0 else yaw, view.pitch], "target": target}
    )
    return info


def test_the_rate_counts_the_views_the_episodes_draw(env: TVMContinuousEnv) -> None:
    """steps_per_second's draw counts are those of the same seeded episodes played again: one view
    per random start tried, one per step whose move is not refused before drawing."""
    steps = 8
    rate = steps_per_second(env, n=steps, seed=5)
    actions = np.random.default_rng(5).uniform(-1, 1, size=(steps, 3)).astype(np.float32)
    env.reset(seed=5)
    first = env.draws
    drawn_moves = reset_draws = resets = 0
    for action in actions:
        _, _, terminated, _, info = env.step(action)
        drawn_moves += info["refused"] not in ("bounds", "collision")
        if terminated:
            before = env.draws
            env.reset()
            reset_draws, resets = reset_draws + env.draws - before, resets + 1
    assert env.draws - first == drawn_moves + reset_draws
    assert rate["draws_per_step"] == pytest.approx((env.draws - first) / steps)
    assert rate["resets"] == resets == 2 and rate["draws_per_reset"] == pytest.approx(reset_draws / resets)
    assert reset_draws >= resets  # every start is drawn at least once


def test_moves_out_of_the_grid_or_through_the_plant_are_refused(free_env: TVMContinuousEnv) -> None:
    info = _start(free_env, -1.2, 0.1, 0.3)
    start = info["path"][0]
    # Through the plant's exclusion zone (0.75 m for strawberry) to the other side: a collision.
    _, _, _, _, info = free_env.step(np.array([0.8, 0.0, 0.0, 0.0, 0.0], dtype=np.float32))
    assert info["refused"] == "collision" and info["path"][-1] == start
    # Out of the grid's 1 m depth.
    _, _, _, _, info = free_env.step(np.array([0.0, 1.0, 0.0, 0.0, 0.0], dtype=np.float32))
    assert info["refused"] == "bounds" and info["path"][-1] == start
    # Turning away from the plant loses the target: refused as section V-D refuses such moves.
    _, _, _, _, info = free_env.step(np.array([0.0, 0.0, 0.0, 1.0, 0.0], dtype=np.float32))
    assert info["refused"] == "target lost" and info["path"][-1] == start


def test_moves_slip_and_turns_do_not(free_env: TVMContinuousEnv) -> None:
    info = _start(free_env, -1.2, 0.0, 0.3)
    x, y, z, yaw, _pitch = info["path"][0]
    _, _, _, _, info = free_env.step(np.array([0.0, 0.0, 0.0, 0.05, 0.0], dtype=np.float32))  # 9 degrees
    assert info["refused"] == "" and info["path"][-1][:3] == [x, y, z]
    assert info["path"][-1][3] == pytest.approx(yaw + 9.0, abs=1e-3)
    _, _, _, _, info = free_env.step(np.array([0.0, 0.05, 0.0, 0.0, 0.0], dtype=np.float32))  # 15 cm north
    if info["refused"] == "":
        nx, ny = info["path"][-1][:2]
        assert (nx, ny) != (x, y + 0.15) and np.hypot(nx - x, ny - y - 0.15) < 6 * SLIP_SIGMA


def test_policies_play_the_same_starts(env: TVMContinuousEnv, tmp_path: Path) -> None:
    lr = RandomAxes("LR", (0,), seed=1)
    lr.prepare(env)
    assert np.count_nonzero(lr.act(None, {})[1:]) == 0
    results = evaluate_policies(env, [lr, Greedy(candidates=4)], episodes=3, sessions=1, keep_episodes=True).as_json()
    starts = [[e["oer_0"] for e in results["policies"][name]["episodes"]] for name in ("LR", "Greedy")]
    assert starts[0] == starts[1]
    assert results["policies"]["Greedy"]["oer_tau"]["mean"] >= min(starts[0])
    with pytest.raises(UserError, match="unknown continuous policy"):
        build_policies(["Oracle"])


def test_ppo_trains_briefly_and_plays(
    live_scene_dir: Path,
    env: TVMContinuousEnv,
    tmp_path: Path,
    capsys: pytest.CaptureFixture[str],
    monkeypatch: pytest.MonkeyPatch,
) -> None:
    system_tmp = tmp_path / "system-tmp"
    system_tmp.mkdir()
    monkeypatch.setattr(tempfile, "tempdir", str(system_tmp))
    path, records = train_continuous(
        live_scene_dir,
        "sp",
        total_timesteps=48,
        seed=0,
        out_path=tmp_path / "ppo",
        arch="pooled",
        n_steps=24,
        batch_size=12,
        progress_every=24,
        verbose=1,
    )
    assert path.suffix == ".zip" and path.is_file()
    printed = capsys.readouterr().out
    assert "PPO: 48/48 steps" in printed and "| rollout/" in printed  # SB3's table, as --verbose 1 asks
    assert list(system_tmp.glob("SB3-*")) == []  # SB3 leaves no empty /tmp/SB3-<time> folder behind
    assert len(records) >= 48 // env.tau - 1 and all(r["reward"] >= 0 for r in records)
    assert plot_training_curve(records, tmp_path / "curve.png", "PPO", window=4).stat().st_size > 0
    agent = ModelPolicy(path)
    results = evaluate_policies(env, [agent], episodes=2, sessions=1).as_json()
    assert results["policies"]["PPO"]["length"]["mean"] == env.tau


def test_evaluate_command_takes_the_continuous_environment(
    live_root: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]
) -> None:
    monkeypatch.chdir(tmp_path)
    args = [
        "evaluate",
        "--env",
        "continuous",
        "--dataset",
        str(live_root),
        "--scenario",
        "sp",
        "--split",
        "all",
        "--episodes",
        "2",
        "--sessions",
        "1",
        "--out",
        "r.json",
        "--policies",
        "LR,Rand",
    ]
    assert cli.main(args) == 0
    results = json.loads(Path("r.json").read_text())
    assert results["protocol"]["environment"] == CONTINUOUS_ID and set(results["policies"]) == {"LR", "Rand"}
    assert Path("r.png").is_file()
    assert cli.main([*args[:-1], "Oracle"]) == 2
    assert "not a baseline of --env continuous" in capsys.readouterr().err
    # A policy file written with the grid's move names plays here too (named moves are unit moves).
    Path("mine.py").write_text("def climb(observation, info):\n    return 'up' if info['steps'] < 2 else 'done'\n")
    assert cli.main([*args[:-2], "--policies", "Rand", "--policy", "mine.py:climb", "--force"]) == 0
    mine = json.loads(Path("r.json").read_text())["policies"]["climb"]
    assert mine["mean_abs_action"]["dz"] == pytest.approx(2 / 3, abs=1e-4) and mine["mean_abs_action"]["dx"] == 0
    assert "Rand" in mine["paired"]


def test_the_docs_policy_file_runs_on_the_continuous_environment(
    live_root: Path, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    """docs/benchmark-your-method.md says its policy file scores here too."""
    from test_benchmark_your_method import PAGE, blocks  # tests/ is on the path, as for layout_factory

    monkeypatch.chdir(tmp_path)
    name, body = next((n, b) for _, n, b in blocks(PAGE.read_text()) if n)
    Path(name).write_text(body)
    assert (
        cli.main(
            [
                "evaluate",
                "--env",
                "continuous",
                "--dataset",
                str(live_root),
                "--scenario",
                "sp",
                "--split",
                "all",
                "--episodes",
                "2",
                "--sessions",
                "1",
                "--policies",
                "Rand",
                "--out",
                "r.json",
                "--policy",
                f"{name}:toward_target",
            ]
        )
        == 0
    )
    assert json.loads(Path("r.json").read_text())["policies"]["toward_target"]["length"]["mean"] == 3

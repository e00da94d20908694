"""TVM-v0 with a robot, on a real Helios scene: only reachable views, forward kinematics of every
step's info["robot"] on the URDF alone, symmetric seconds, a budget, evaluate and verify."""

from __future__ import annotations

import json
import math
import subprocess
import sys
from pathlib import Path

import numpy as np
import pinocchio as pin
import pytest

from davis_ag.benchmark import TVMEnv
from davis_ag.data.reader import open_dataset
from davis_ag.errors import UserError
from davis_ag.robot import reach as reach_module
from davis_ag.robot.model import camera_rotation
from davis_ag.robot.reach import load_reach
from real_scenes import ROBOT_VINE, generate_config

pytestmark = pytest.mark.slow


@pytest.fixture(scope="module")
def root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return generate_config(tmp_path_factory, "vine", ROBOT_VINE)


def _robot_yaml(name: str) -> str:
    """A built-in robot's YAML, to write a changed copy of."""
    return (Path(__file__).parents[2] / f"src/davis_ag/robot/robots/{name}.yaml").read_text()


def _evaluate(root: Path) -> list[str]:
    """``evaluate`` on the vine scene's train split (its one scene)."""
    return ["evaluate", "--dataset", str(root), "--scenario", "sp", "--split", "train"]


def _cli(*args: str) -> subprocess.CompletedProcess[str]:
    return subprocess.run([sys.executable, "-m", "davis_ag.cli", *args], capture_output=True, text=True, check=False)


def test_a_bigger_arm_on_a_lift_reaches_more_and_the_reach_is_cached(
    root: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    scene = open_dataset(root).scene("Single-Vine/000")
    ur5, ur10 = (load_reach(scene, root, name) for name in ("ur5-trolley", "ur10-lift"))
    assert 0.0 < ur5.share < 1.0
    assert ur10.share > ur5.share
    assert ur5.obstacle_points > 0  # the vine's trunk and cordons
    reached = np.flatnonzero(ur5.reachable)
    assert np.all(np.isfinite(ur5.q[reached])) and np.all(np.isnan(ur5.q[~ur5.reachable]))
    cached = list((root / ".davis_ag_cache" / ".reach").rglob("*.npz"))
    assert len(cached) == 2 and not list((root / "Single-Vine" / "000").rglob("*.npz"))

    def never(*_: object, **__: object) -> None:
        raise AssertionError("the reach was computed again")

    monkeypatch.setattr(reach_module, "compute_reach", never)
    again = load_reach(scene, root, "ur5-trolley")
    assert np.array_equal(again.reachable, ur5.reachable)


def test_moves_cost_positive_symmetric_seconds(root: Path) -> None:
    scene = open_dataset(root).scene("Single-Vine/000")
    reach = load_reach(scene, root, "ur10-lift")
    pointers = reach_module.pointer_table(scene)
    pairs = 0
    for i, j in zip(*np.nonzero(np.isfinite(reach.seconds))):
        there = reach.seconds[i, j]
        back = reach.seconds[pointers[i, j]][pointers[pointers[i, j]] == i]
        assert there > 0 and np.allclose(back, there, rtol=0.05)
        pairs += 1
    assert pairs > 50


def test_the_robot_never_leaves_its_reach_and_its_info_is_the_view_by_forward_kinematics(root: Path) -> None:
    import example_robot_data

    env = TVMEnv(root, scenario="sp", split="all", robot="ur5-trolley", max_start_oer=1.01)
    free = TVMEnv(root, scenario="sp", split="all", max_start_oer=1.01)
    reach = env.robot.reaches[0]
    reachable = {name for name, ok in zip(reach.view_names, reach.reachable) if ok}
    assert 0 < len(env.starts) < len(free.starts)
    poses = {view.name: view.pose for view in env.scenes[0]}
    urdf = "ur_description/urdf/ur5_robot.urdf"
    model = pin.buildModelFromUrdf(str(Path(example_robot_data.getModelPath(urdf)) / urdf))
    data = model.createData()
    rng = np.random.default_rng(0)
    steps = 0
    for episode in range(40):
        _, info = env.reset(seed=episode)
        while True:
            robot = info["robot"]
            assert robot["urdf"] == "example-robot-data:ur5" and info["path"][-1] in reachable
            pin.framesForwardKinematics(model, data, np.array(robot["q"]))
            tool = data.oMf[model.getFrameId(robot["tool_frame"])].homogeneous
            camera = np.array(robot["mount"]) @ tool @ np.array(robot["camera_in_tool"])
            pose = poses[info["path"][-1]]
            assert np.linalg.norm(camera[:3, 3] - pose[:3]) < 0.01
            cosine = (np.trace(camera_rotation(pose[3], pose[4]).T @ camera[:3, :3]) - 1) / 2
            assert math.degrees(math.acos(min(1.0, cosine))) < 1.0
            assert robot["seconds"] >= 0
            if len(info["path"]) > 1 and info["path"][-1] != info["path"][-2]:
                assert robot["seconds"] > 0
            steps += 1
            _, _, over, _, info = env.step(int(rng.integers(env.done_action)))
            if over:
                break
    assert steps > 100


def test_a_budget_of_seconds_ends_the_episode(root: Path) -> None:
    env = TVMEnv(root, scenario="sp", split="all", robot="ur10-lift", budget_s=2.0, max_start_oer=1.01)
    assert env.tau == 100
    rng = np.random.default_rng(1)
    for episode in range(10):
        env.reset(seed=episode)
        over, info = False, {}
        while not over:
            _, _, over, _, info = env.step(int(rng.integers(env.done_action)))
        assert info["robot"]["seconds_total"] <= 2.0
        assert info["steps"] < 100
    with pytest.raises(UserError, match="needs a robot"):
        TVMEnv(root, scenario="sp", split="all", budget_s=2.0)


def test_a_robot_that_reaches_no_start_is_one_line_naming_what_it_reaches(root: Path, tmp_path: Path) -> None:
    text = _robot_yaml("ur5-trolley")
    tall = tmp_path / "tall.yaml"
    tall.write_text(
        text.replace("name: ur5-trolley", "name: tall").replace("mount_height_m: 0.69", "mount_height_m: 4.0")
    )
    with pytest.raises(UserError, match=r"reaches no eligible start .* no view at all"):
        TVMEnv(root, scenario="sp", split="all", robot=str(tall), cache_dir=tmp_path / "cache")


def test_evaluate_with_a_robot_records_it_and_its_seconds_and_verify_replays_it(root: Path, tmp_path: Path) -> None:
    out = tmp_path / "robot.json"
    done = _cli(*_evaluate(root), "--robot", "ur10-lift", "--episodes", "20", "--sessions", "2", "--out", str(out))
    assert done.returncode == 0, done.stderr
    results = json.loads(out.read_text())
    assert results["protocol"]["robot"]["name"] == "ur10-lift"
    assert results["protocol"]["robot"]["urdf"] == "example-robot-data:ur10"
    oracle, rand = results["policies"]["Oracle"], results["policies"]["Rand"]
    assert oracle["seconds"]["mean"] > 0 and oracle["oer_tau"]["mean"] >= rand["oer_tau"]["mean"]
    verified = _cli("verify", str(out), "--dataset", str(root))
    assert verified.returncode == 0, verified.stdout + verified.stderr
    assert "sound" in verified.stdout
    # The same file replayed with another robot is not the file's: refused, nothing ranked.
    other = tmp_path / "other.yaml"
    text = _robot_yaml("ur10-lift")
    other.write_text(text.replace("lift_m: [0.0, 1.5]", "lift_m: [0.0, 1.0]"))
    refused = _cli("verify", str(out), "--dataset", str(root), "--robot", str(other))
    assert refused.returncode == 1
    assert "robot" in refused.stdout + refused.stderr
    assert "Traceback" not in refused.stderr


def test_an_unknown_robot_is_one_line(root: Path, tmp_path: Path) -> None:
    done = _cli(*_evaluate(root), "--robot", "ur7", "--out", str(tmp_path / "r.json"))
    assert done.returncode != 0 and "Traceback" not in done.stderr
    assert "ur10-lift" in done.stderr and not (tmp_path / "r.json").exists()


def test_a_learner_trains_under_a_robot_and_compare_keeps_robots_apart(root: Path, tmp_path: Path) -> None:
    from davis_ag.benchmark.training import train_agent, training_record_path

    model = train_agent(
        root,
        "sp",
        total_timesteps=40,
        n_envs=2,
        out_path=tmp_path / "a2c.zip",
        arch="pooled",
        keep="last",
        robot="ur10-lift",
        progress=False,
        checkpoint_every=0,
        device="cpu",
    )
    record = json.loads(training_record_path(model).read_text())
    assert record["robot"]["name"] == "ur10-lift"
    common = [*_evaluate(root)[1:], "--episodes", "10", "--sessions", "1"]
    with_robot, without = tmp_path / "robot.json", tmp_path / "free.json"
    done = _cli("evaluate", *common, "--policy", str(model), "--robot", "ur10-lift", "--out", str(with_robot))
    assert done.returncode == 0, done.stderr
    rows = json.loads(with_robot.read_text())["policies"]
    assert all(row["seconds"]["mean"] >= 0 for row in rows.values()) and len(rows) == 6  # the model and five baselines
    assert _cli("evaluate", *common, "--policies", "Rand", "--out", str(without)).returncode == 0
    refused = _cli("compare", str(with_robot), str(without))
    assert refused.returncode != 0 and "robot" in refused.stderr and "Traceback" not in refused.stderr


def test_reach_draws_the_grid_and_the_robots_episode_and_writes_its_table(root: Path, tmp_path: Path) -> None:
    page = tmp_path / "robot.md"
    page.write_text("<!-- reach-ur10-lift:start -->\nold\n<!-- reach-ur10-lift:end -->\n")
    out = tmp_path / "pictures"
    done = _cli("reach", str(root), "--robot", "ur10-lift", "--out", str(out), "--episode", "0", "--doc", str(page))
    assert done.returncode == 0, done.stderr
    assert (out / "Single-Vine-000-ur10-lift.png").stat().st_size > 10_000
    assert (out / "Single-Vine-000-ur10-lift-episode-0.png").stat().st_size > 10_000
    assert "old" not in page.read_text() and "| Single-Vine | 0.5 |" in page.read_text()


def test_the_robot_is_drawn_into_its_scene_and_an_unreached_view_is_refused(root: Path) -> None:
    from davis_ag.live.robot_pictures import robot_frames

    reach = load_reach(open_dataset(root).scene("Single-Vine/000"), root, "ur5-trolley")
    reached = [n for n, ok in zip(reach.view_names, reach.reachable) if ok]
    missed = [n for n, ok in zip(reach.view_names, reach.reachable) if not ok]
    (frame,) = robot_frames(root / "Single-Vine/000", "ur5-trolley", reached[:1], size=(160, 90))
    assert frame.onlooker.shape == (90, 160, 3) and frame.camera.shape == (72, 128, 3)
    # The arm is grey-white and the platform blue: both are in the picture.
    blue = (frame.onlooker[..., 2] > 120) & (frame.onlooker[..., 0] < 90)
    assert blue.sum() > 20
    with pytest.raises(UserError, match="does not reach it"):
        robot_frames(root / "Single-Vine/000", "ur5-trolley", missed[:1], size=(160, 90))

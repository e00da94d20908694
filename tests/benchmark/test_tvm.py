"""The TVM environment: API conformance, determinism, rules of section V-D, reward, speed."""

from __future__ import annotations

from pathlib import Path

import gymnasium
import numpy as np
import pytest
from gymnasium.utils.env_checker import check_env
from PIL import Image

import davis_ag  # noqa: F401 - registers the environments
from davis_ag.benchmark import CONTINUOUS_ID, TVMEnv
from davis_ag.environments import MAPPING_ID
from davis_ag.errors import UserError
from layout_factory import write_original_style_dataset

#: Every grid environment registered; TVMContinuous-v0 renders scenes of ours, so it is checked
#: on a generated scene in tests/live/test_tvm_continuous.py, not on these tiny layout datasets.
# TVM-v0's ids: the continuous environment and row mapping have tests of their own (tests/live, tests/mapping).
ENV_IDS = sorted(i for i in gymnasium.registry if i.startswith("davis_ag/") and i not in (CONTINUOUS_ID, MAPPING_ID))


def _episode(env: gymnasium.Env, seed: int, actions: list[int]) -> list:
    obs, info = env.reset(seed=seed)
    trace = [(obs, info)]
    for a in actions:
        obs, reward, terminated, truncated, info = env.step(a)
        trace.append((obs, reward, terminated, truncated, info))
        if terminated or truncated:
            break
    return trace


def test_registered() -> None:
    assert "davis_ag/TVM-v0" in ENV_IDS and CONTINUOUS_ID in gymnasium.registry


@pytest.mark.parametrize("env_id", ENV_IDS)
@pytest.mark.parametrize("scenario", ["sp", "mp"])
def test_env_checker(env_id: str, scenario: str, sp_root: Path, mp_root: Path) -> None:
    root = sp_root if scenario == "sp" else mp_root
    env = gymnasium.make(env_id, dataset=root, scenario=scenario, split="all")
    check_env(env.unwrapped, skip_render_check=False)
    obs, _ = env.reset(seed=0)
    assert obs.shape == (224, 224, 4) and obs.dtype == np.uint8
    assert set(np.unique(obs[..., 3])) <= {0, 255} and obs[..., 3].max() == 255
    assert env.action_space.n == (7 if scenario == "sp" else 9)
    assert env.unwrapped.action_names[-1] == "done"
    if scenario == "mp":
        assert env.unwrapped.action_names[6:8] == ("rotate_cw", "rotate_ccw")


@pytest.mark.parametrize("env_id", ENV_IDS)
def test_seeded_determinism(env_id: str, sp_root: Path) -> None:
    a = gymnasium.make(env_id, dataset=sp_root, scenario="sp", split="all")
    b = gymnasium.make(env_id, dataset=sp_root, scenario="sp", split="all")
    actions = [0, 2, 4, 1]
    for seed in (0, 7, 123):
        ta, tb = _episode(a, seed, actions), _episode(b, seed, actions)
        assert len(ta) == len(tb)
        for sa, sb in zip(ta, tb):
            np.testing.assert_array_equal(sa[0], sb[0])
            assert sa[1:] == sb[1:]
    starts = {
        (
            _episode(a, s, [])[0][1]["scene"],
            _episode(a, s, [])[0][1]["path"][0],
            _episode(a, s, [])[0][1]["target_fruit"],
        )
        for s in range(40)
    }
    assert len(starts) > 1  # the seed does matter


def test_starts_follow_section_vc(sp_root: Path) -> None:
    env = TVMEnv(sp_root, "sp", split="train")
    for seed in range(50):
        _, info = env.reset(seed=seed)
        assert info["oer_0"] < 0.4 and info["steps"] == 0
        assert info["scene"] == "Single-Strawberry/000"  # splits.json: 000 trains
    assert TVMEnv(sp_root, "sp", split="test").reset(seed=0)[1]["scene"] == "Single-Strawberry/001"


def _oer_from_files(root: Path, scene: str, view: str, fruit: int) -> float:
    """Equation (1) computed by hand from the files, independent of the environment."""
    import json

    boxes = json.loads((root / scene / "annotations.json").read_text())[view]["bounding_boxes"]
    x, y, w, h = next(b[:4] for b in boxes if b[4] == fruit)
    mask = np.asarray(Image.open(root / scene / "images" / view.replace(".jpeg", "_seg.png")))
    return float(np.count_nonzero(mask[y : y + h, x : x + w] == fruit)) / (w * h)


def test_reward_formula() -> None:
    assert TVMEnv.reward(0.2, 0.5) == pytest.approx(0.09)
    assert TVMEnv.reward(0.35, 0.35) == 0.0
    assert TVMEnv.reward(0.5, 0.2) == 0.0  # worse views are not punished
    assert TVMEnv.reward(0.0, 1.0) == pytest.approx(1.0)


def test_reward_on_episodes(sp_root: Path) -> None:
    env = TVMEnv(sp_root, "sp", split="all")
    seen_positive = seen_zero = False
    for seed in range(30):
        for first in range(6):
            _, _info = env.reset(seed=seed)
            trace = _episode(env, seed, [first, 3, 2])
            final = trace[-1]
            assert [step[1] for step in trace[1:-1]] == [0.0] * (len(trace) - 2)
            scene, path, fruit = final[4]["scene"], final[4]["path"], final[4]["target_fruit"]
            oer_0 = _oer_from_files(sp_root, scene, path[0], fruit)
            oer_t = _oer_from_files(sp_root, scene, path[-1], fruit)
            assert final[4]["oer_0"] == pytest.approx(oer_0, abs=1e-6)
            assert final[4]["oer_t"] == pytest.approx(oer_t, abs=1e-6)
            assert final[1] == pytest.approx(max(oer_t - oer_0, 0.0) ** 2, abs=1e-6)
            seen_positive |= final[1] > 0
            seen_zero |= final[1] == 0
    assert seen_positive and seen_zero


def test_done_and_tau_end_the_episode(sp_root: Path) -> None:
    env = TVMEnv(sp_root, "sp", split="all")
    trace = _episode(env, 0, [env.done_action])
    assert len(trace) == 2 and trace[1][2] is True and trace[1][3] is False
    assert trace[1][1] == 0.0 and trace[1][4]["steps"] == 1  # done counts as a step
    trace = _episode(env, 0, [0, 1, 0, 1, 0])
    assert len(trace) == 4 and trace[-1][2] is True and trace[-1][4]["steps"] == env.tau == 3
    with pytest.raises(UserError, match="reset"):
        env.step(0)


def _find(env: TVMEnv, kind: str) -> tuple[str, str, int, int]:
    """A start (scene, view, fruit) and a move that is "" (kind="empty") or loses the target."""
    for scene, cache in zip(env.scenes, env.caches):
        for b in range(len(cache.box_view)):
            view, fruit = int(cache.box_view[b]), int(cache.box_fruit[b])
            for a, column in enumerate(env._columns):
                nxt = int(cache.pointers[view, column])
                hit = nxt < 0 if kind == "empty" else nxt >= 0 and cache.box_index[nxt, fruit] < 0
                if hit:
                    return scene.id, cache.view_names[view], int(cache.fruit_ids[fruit]), a
    raise AssertionError(f"the tiny dataset has no {kind} move")


@pytest.mark.parametrize("kind", ["empty", "target_lost"])
def test_refused_moves_stay_and_cost_a_step(sp_root: Path, kind: str) -> None:
    env = TVMEnv(sp_root, "sp", split="all")
    scene, view, fruit, action = _find(env, kind)
    obs, info = env.reset(options={"start": (scene, view, fruit)})
    obs2, reward, terminated, _truncated, info2 = env.step(action)
    np.testing.assert_array_equal(obs, obs2)
    assert info2["path"] == [view, view] and info2["steps"] == 1
    assert not terminated and reward == 0.0 and info2["oer_t"] == info["oer_0"]
    env.step(action)
    _, reward, terminated, _, info3 = env.step(action)
    assert terminated and info3["steps"] == 3 and reward == 0.0


@pytest.mark.parametrize("bad", [7, -1, 2.5, "left", None, np.array([1, 2])])
def test_invalid_action_is_a_user_error(sp_root: Path, bad: object) -> None:
    env = TVMEnv(sp_root, "sp", split="all")
    env.reset(seed=0)
    with pytest.raises(UserError, match="invalid action"):
        env.step(bad)
    env.step(np.int64(0))  # NumPy integers (what SB3 passes) are fine
    env.step(np.array([1]))


def test_bad_inputs_are_user_errors(sp_root: Path, tmp_path: Path) -> None:
    with pytest.raises(UserError, match="not a DAVIS-Ag dataset"):
        TVMEnv(tmp_path, "sp")
    with pytest.raises(UserError, match="no eligible start"):
        TVMEnv(sp_root, "sp", split="train", max_start_oer=0.0)
    with pytest.raises(UserError, match="no mp"):
        TVMEnv(sp_root, "mp")
    with pytest.raises(UserError, match="split"):
        TVMEnv(sp_root, "sp", split="valid")
    for error in (TVMEnv(sp_root, "sp", split="all"),):
        with pytest.raises(UserError, match="no box"):
            error.reset(options={"start": ("Single-Strawberry/000", "0001.jpeg", 999)})


def test_original_layout_without_splits(tmp_path: Path) -> None:
    root = write_original_style_dataset(tmp_path / "orig", "sp", "strawberry", scenes=2)
    train, test = TVMEnv(root, "sp", "train"), TVMEnv(root, "sp", "test")
    assert {s.id for s in train.scenes}.isdisjoint({s.id for s in test.scenes})
    assert len(train.scenes) == len(test.scenes) == 1
    missing = write_original_style_dataset(tmp_path / "nomask", "sp", scenes=1, missing_mask=True)
    with pytest.raises(UserError, match="mask"):
        TVMEnv(missing, "sp", "all")


def test_a_dataset_without_splits_json_splits_as_the_generator_would(sp_root: Path, tmp_path: Path) -> None:
    """One split rule: the benchmark's fallback is the generator's, with dataset.json's seed."""
    import shutil

    from davis_ag.benchmark.splits import dataset_splits, select_scenes
    from davis_ag.data.reader import open_dataset
    from davis_ag.formats.splits import split_scenes

    ids = [f"Single-Tomato/{i:03d}" for i in range(10)] + [f"Multi-Vine/{i:03d}" for i in range(4)]
    split = split_scenes(list(reversed(ids)), 0)
    assert split == split_scenes(ids, 0)  # order of discovery does not matter
    assert sum(s.startswith("Single") for s in split["train"]) == 7 and len(split["test"]) == 3 + 1
    assert sorted(split["train"] + split["test"]) == sorted(ids)

    root = tmp_path / "copy"
    shutil.copytree(sp_root, root)
    (root / "splits.json").unlink(missing_ok=True)
    data = open_dataset(root)
    every = [s.id for s in data.scenes]
    assert dataset_splits(data) == split_scenes(every, 0)
    (root / "dataset.json").write_text('{"seed": 5}')
    assert dataset_splits(open_dataset(root)) == split_scenes(every, 5)
    assert [s.id for s in select_scenes(open_dataset(root), "sp", "test")] == split_scenes(every, 5)["test"]


def test_stable_baselines3_accepts_the_env(sp_root: Path) -> None:
    from stable_baselines3.common.env_checker import check_env as sb3_check_env

    sb3_check_env(TVMEnv(sp_root, "sp", split="all"), warn=True)

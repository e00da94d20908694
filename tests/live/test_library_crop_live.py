"""TVMContinuous-v0 on a plant-library crop's single plant: the scene regrows from its scene.json
exactly (the live reopen checks every fruit), and the environment passes the checkers."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import gymnasium
import pytest

from davis_ag.benchmark import CONTINUOUS_ID
from davis_ag.generate.one_scene import SceneRequest, generate_scene
from davis_ag.live.scene import open_live_scene
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CROPS, scenario_spec

pytestmark = pytest.mark.slow

CROP = CROPS["capsicum"]
#: The capsicum's own SP grid at one altitude and a coarse step (a few dozen views), tiny frames.
SCENARIO = replace(scenario_spec("sp", CROP), step=2 * scenario_spec("sp", CROP).step, altitude_levels=(1,))


@pytest.fixture(scope="module")
def scene_dir(tmp_path_factory: pytest.TempPathFactory) -> Path:
    request = SceneRequest(SCENARIO, CROP, index=0, dataset_seed=4, camera=Camera(96, 54))
    folder, _ = generate_scene(request, tmp_path_factory.mktemp("capsicum"))
    return folder


def test_the_scene_regrows_live_from_its_record(scene_dir: Path) -> None:
    with open_live_scene(scene_dir) as scene:
        assert not scene.assets.from_cache  # grown again from scene.json and checked against it
        assert scene.settings.crop.name == "capsicum"


def test_the_continuous_environment_plays_the_library_crop(scene_dir: Path) -> None:
    from gymnasium.utils.env_checker import check_env

    made = gymnasium.make(CONTINUOUS_ID, dataset=str(scene_dir), scenario="sp")
    try:
        check_env(made.unwrapped, skip_render_check=True)
        observation, _info = made.reset(seed=1)
        assert observation.shape == (224, 224, 4)
        _, reward, _, _, _info = made.step(made.action_space.sample())
        assert reward >= 0.0
    finally:
        made.close()

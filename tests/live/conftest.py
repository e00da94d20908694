"""One small generated scene for every live test: grown and drawn once, then reopened live once
(the regrow, which writes the geometry cache); the tests reopen it from that cache."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from davis_ag.generate.one_scene import SceneRequest, draw_scene, grow_scene
from davis_ag.live.scene import LiveScene, open_live_scene
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CROPS, SCENARIOS

#: Single-plant strawberry on a 3 m x 1 m grid with 50 cm steps at two altitudes (22 views), tiny
#: frames: the scene of tests/generate/test_one_scene.py.
SCENARIO = replace(SCENARIOS["sp"], extent=(3.0, 1.0), step=0.5, altitude_levels=(0, 1))
REQUEST = SceneRequest(SCENARIO, CROPS["strawberry"], index=0, dataset_seed=0, camera=Camera(96, 54))


@pytest.fixture(scope="session")
def live_request() -> SceneRequest:
    """What made the scene."""
    return REQUEST


@pytest.fixture(scope="session")
def grown() -> tuple:
    """The scene as the generator grew it: its model and grid (real Helios plants)."""
    return grow_scene(REQUEST)


@pytest.fixture(scope="session")
def live_root(tmp_path_factory: pytest.TempPathFactory, grown: tuple) -> Path:
    """A dataset root holding the scene, its geometry cache already written by a regrow."""
    root = tmp_path_factory.mktemp("live")
    scene_dir, _ = draw_scene(REQUEST, *grown, root)  # generate_scene's two halves
    with open_live_scene(scene_dir) as scene:
        assert not scene.assets.from_cache  # grown again from scene.json, checked, cached
    return root


@pytest.fixture(scope="session")
def live_scene_dir(live_root: Path) -> Path:
    """The scene folder."""
    return live_root / REQUEST.folder


@pytest.fixture(scope="session")
def live_scene(live_scene_dir: Path) -> LiveScene:
    """The scene reopened from its cache (shared: its renderers take seconds to set up)."""
    with open_live_scene(live_scene_dir) as scene:
        yield scene

"""One small real scene for the 3-D exports' tests: a multi-plant strawberry row generated with
Helios once per session (tests/real_scenes.py), its geometry cached by the first reopening."""

from __future__ import annotations

from pathlib import Path

import pytest

from real_scenes import generate_config

#: Multi-plant strawberry (several plants, each with fruit) on a 3 m x 2 m grid with 1 m steps and four headings (72 views),
#: small frames with depth and class images.
WORLD_ROW = """\
seed: 3
image_size: 160x90
grid: {extent: [3.0, 2.0], step: 1.0, headings: 4}
groups:
  - {scenario: mp, crop: strawberry, scenes: 1}
"""


@pytest.fixture(scope="session")
def world_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """The dataset root; its scene's geometry cache written by a first (regrowing) reopening."""
    from davis_ag.generate.recorded_settings import read_settings
    from davis_ag.live.reopen import reopen_assets

    root = generate_config(tmp_path_factory, "worlds", WORLD_ROW)
    for scene_dir in sorted(root.glob("*/[0-9][0-9][0-9]")):
        assert not reopen_assets(read_settings(scene_dir), labelled=True).from_cache
    return root


@pytest.fixture(scope="session")
def world_scene_dir(world_root: Path) -> Path:
    """The scene folder."""
    (scene_dir,) = sorted(world_root.glob("*/[0-9][0-9][0-9]"))
    return scene_dir

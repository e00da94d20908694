"""davis-ag preview: the views generate would write, for every option that shapes them."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from davis_ag import cli
from davis_ag.figures.label_pictures import class_colours
from davis_ag.generate.one_scene import SceneRequest, generate_scene
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import crop_spec, scenario_spec, with_strawberry_altitudes


@pytest.mark.slow
def test_preview_draws_the_view_generate_writes_with_its_appearance_and_altitudes(tmp_path: Path) -> None:
    """preview grew plants without the appearance (the paper's soil and light always) and took
    no --strawberry-altitudes, so it could not show the scene such a generate run makes."""
    options = ["--appearance", "random", "--strawberry-altitudes", "readme", "--classes"]
    assert cli.main(["preview", "--views", "5,200", "--size", "96x54", *options, "--out", str(tmp_path / "p")]) == 0
    crop = with_strawberry_altitudes(crop_spec("strawberry"), "readme")
    request = SceneRequest(scenario_spec("sp", crop), crop, 0, 0, Camera(96, 54), appearance="random")
    scene_dir, _ = generate_scene(request, tmp_path / "data")
    for number in (5, 200):
        previewed = np.asarray(Image.open(tmp_path / "p" / f"strawberry-sp-000-{number:04d}.jpeg"))
        written = np.asarray(Image.open(scene_dir / "images" / f"{number:04d}.jpeg"))
        assert np.array_equal(previewed, written)  # the same pixels, encoded alike
        # --classes: the class image generate writes, in the colours of its legend.
        classes = np.asarray(Image.open(scene_dir / "images" / f"{number:04d}_class.png"))
        coloured = np.asarray(Image.open(tmp_path / "p" / f"strawberry-sp-000-{number:04d}-classes.png"))
        assert np.array_equal(coloured, class_colours(classes))
    plain = tmp_path / "plain"
    assert cli.main(["preview", "--views", "5", "--size", "96x54", "--out", str(plain)]) == 0
    # The output rule: earlier pictures are replaced only with --force, never written into a dataset.
    assert cli.main(["preview", "--views", "5", "--size", "96x54", "--out", str(plain)]) == 2
    assert cli.main(["preview", "--views", "5", "--size", "96x54", "--out", str(plain), "--force"]) == 0
    assert cli.main(["preview", "--views", "5", "--size", "96x54", "--out", str(scene_dir)]) == 2
    paper = np.asarray(Image.open(plain / "strawberry-sp-000-0005.jpeg")).astype(np.int64)
    assert np.abs(paper - np.asarray(Image.open(tmp_path / "p" / "strawberry-sp-000-0005.jpeg"))).mean() > 8

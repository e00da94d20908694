"""What a scene's scene.json says about how it was made, read back as the request that makes it.

``davis-ag generate`` records every setting a scene was made with (grid, altitudes, camera,
renderer, plants, appearance, seeds) in scene.json. :func:`read_settings` reads them back and
checks them, so a scene can be made again (:mod:`davis_ag.generate.regenerate`) or regrown
(:mod:`davis_ag.live.reopen`) exactly as it was.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from pathlib import Path
from typing import Any, TypeVar

from davis_ag.errors import UserError
from davis_ag.formats.layout import SCENE_METADATA
from davis_ag.formats.scene_file import SCENE_FORMAT, SceneFile, read_scene_file
from davis_ag.generate.one_scene import SceneRequest
from davis_ag.render.backends import antialiasing_of
from davis_ag.scene.appearance import DEFAULT_APPEARANCE, resolve_appearance
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import (
    DEFAULT_PLANTS,
    STRAWBERRY_ALTITUDES,
    CropSpec,
    ScenarioSpec,
    crop_spec,
    regrowing_plants,
    scenario_spec,
    with_strawberry_altitudes,
)
from davis_ag.scene.structures import check_structures

T = TypeVar("T")


@dataclass
class RecordedSettings:
    """What scene.json says about how a scene was made.

    Attributes:
        folder: The scene folder.
        metadata: scene.json as read.
        scenario, crop: The scene's grid (as generated, reduced grids included) and crop.
        index, seed, dataset_seed: Which scene.
        camera: The camera its views were drawn with.
        renderer, look, antialiasing: How its views were drawn.
        plants: The plant generator (scenes from before the choice grew ``architecture`` plants).
        appearance: ``paper`` or ``random`` (soil, sun, sky, exposure and noise drawn from the seed).
        structures: ``default`` where scene.json records a structure, else ``none`` (scenes from
            before structures, and scenes without one).
    """

    folder: Path
    metadata: SceneFile
    scenario: ScenarioSpec
    crop: CropSpec
    index: int
    seed: int
    dataset_seed: int
    camera: Camera
    renderer: str
    look: str
    antialiasing: str
    plants: str = DEFAULT_PLANTS
    appearance: str = DEFAULT_APPEARANCE
    structures: str = "none"

    def request(self, **drawing: Any) -> SceneRequest:
        """The generate request these settings describe; ``drawing`` adds what only drawing and
        writing need (``depth``, ``antialiasing``, ``classes``)."""
        return SceneRequest(
            self.scenario,
            self.crop,
            self.index,
            self.dataset_seed,
            self.camera,
            renderer=self.renderer,
            look=self.look,
            plants=self.plants,
            appearance=self.appearance,
            structures=self.structures,
            **drawing,
        )


def _crop_with_altitudes(crop: CropSpec, altitudes: list[float], scenario: str) -> tuple[CropSpec, tuple[int, ...]]:
    """The crop whose camera altitudes hold the recorded ones (strawberry has two choices,
    ``--strawberry-altitudes``), and the levels they are: the crop's, or in a ``row`` scene its
    row's (:func:`davis_ag.scene.specs.camera_altitudes`).

    Raises:
        ValueError: when no choice holds them.
    """
    for choice in (None, *STRAWBERRY_ALTITUDES):
        candidate = crop if choice is None else with_strawberry_altitudes(crop, choice)
        heights = candidate.row.altitudes if scenario == "row" and candidate.row is not None else candidate.altitudes
        if all(a in heights for a in altitudes):
            return candidate, tuple(heights.index(a) for a in altitudes)
    raise ValueError(f"grid.altitudes_m {altitudes} are not {crop.name}'s camera altitudes {list(crop.altitudes)}")


def _needed(value: T | None, key: str) -> T:
    """``value``, or a ValueError naming the scene.json key it should have come from."""
    if value is None:
        raise ValueError(f"no {key}")
    return value


def read_settings(scene_dir: str | Path) -> RecordedSettings:
    """Read and check a scene's scene.json.

    Raises:
        UserError: when the folder holds no scene made by davis-ag generate, or scene.json is damaged.
    """
    folder = Path(scene_dir)
    path = folder / SCENE_METADATA
    if not path.is_file():
        raise UserError(f"{path}: missing; only scenes made by `davis-ag generate` can be regrown")
    metadata = read_scene_file(path)
    if not metadata.ours:
        raise UserError(
            f"{path}: not a scene.json written by `davis-ag generate` ({SCENE_FORMAT}); "
            "only our own scenes can be regrown"
        )
    try:
        grid, renderer = _needed(metadata.grid, "grid"), _needed(metadata.renderer, "renderer")
        crop, levels = _crop_with_altitudes(
            crop_spec(_needed(metadata.crop, "crop")),
            _needed(grid.altitudes_m, "grid.altitudes_m"),
            _needed(metadata.scenario, "scenario"),
        )
        scenario = scenario_spec(_needed(metadata.scenario, "scenario"), crop)
        extent_x, extent_y = _needed(grid.extent_m, "grid.extent_m")
        scenario = replace(
            scenario,
            extent=(extent_x, extent_y),
            step=float(_needed(grid.step_m, "grid.step_m")),
            altitude_levels=levels,
            headings=int(grid.headings or scenario.headings),  # reduced grids may have fewer
        )
        width, height = _needed(metadata.image_size(), "camera.width and height")
        assert metadata.camera is not None  # image_size() read the size from it
        camera = Camera(width, height, float(_needed(metadata.camera.vfov_deg, "camera.vfov_deg")))
        settings = RecordedSettings(
            folder,
            metadata,
            scenario,
            crop,
            _needed(metadata.index, "scene"),
            _needed(metadata.seed, "seed"),
            _needed(metadata.dataset_seed, "dataset_seed"),
            camera,
            str(renderer.name),
            str(renderer.look),
            antialiasing_of(renderer),
            regrowing_plants(metadata.plant_generator),
            resolve_appearance((metadata.appearance or {}).get("mode", "paper")),
            check_structures(metadata.structures or "none"),
        )
    except (ValueError, TypeError, UserError, AttributeError) as error:
        raise UserError(
            f"{path}: lacks or mangles a setting needed to regrow the scene ({error}); generate the scene again"
        ) from None
    return settings

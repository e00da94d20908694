"""The pydantic model of a scene's ``scene.json``: what our generator records beside annotations.json.

:func:`davis_ag.generate.one_scene.scene_metadata` builds a :class:`SceneFile`, the scene writer
dumps it, and every reader (the dataset reader's ``Scene.metadata``, the validator, the live
scenes, the exports and figures) reads it back through :func:`read_scene_file`, so a key is spelled
once. Every field is optional: scenes written before a field existed (and the test layouts, which
record less) still read; unknown keys are kept (``extra="allow"``), so a record dumps back as it
was read (:meth:`SceneFile.as_written`). Numbers that may be whole stay as written (``int | float``),
so a dumped record hashes like the file (the live geometry cache keys on it).
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ConfigDict, Field, ValidationError

from davis_ag.errors import UserError
from davis_ag.formats.models import one_line

#: The ``format`` of a scene.json our generator writes.
SCENE_FORMAT = "davis-ag-scene/1"
#: A number as written: a whole number stays an int, so a record dumps back byte for byte.
Number = int | float


class _Record(BaseModel):
    model_config = ConfigDict(extra="allow")

    def as_written(self) -> dict[str, Any]:
        """The record as JSON, with only the keys the file had (or the writer set)."""
        return self.model_dump(mode="json", exclude_unset=True)


class GeneratorRecord(_Record):
    """Which code wrote the scene."""

    name: str | None = Field(default=None, description="davis-ag for our generator")
    version: str | None = Field(default=None, description="davis-ag's version and git commit")
    pyhelios3d: str | None = Field(default=None, description="the pyhelios3d version that grew the plants")
    python: str | None = None
    gl_renderer: str | None = Field(
        default=None,
        description="GL_RENDERER of the OpenGL implementation our renderer drew the views with (llvmpipe: "
        "Mesa on the CPU; not recorded for Helios's renderer); another one draws other pixels from the "
        "same records",
    )


class CameraRecord(_Record):
    """The pinhole the views were drawn with (OpenCV convention, pixel centres at +0.5)."""

    model: str | None = None
    #: Image size, pixels.
    width: int | None = None
    height: int | None = None
    #: Focal lengths and principal point, pixels.
    fx: Number | None = None
    fy: Number | None = None
    cx: Number | None = None
    cy: Number | None = None
    #: Fields of view, degrees.
    vfov_deg: Number | None = None
    hfov_deg: Number | None = None
    #: OpenCV's k1, k2, p1, p2, k3: all 0 for our pinhole.
    distortion: list[Number] | None = None


class RendererRecord(_Record):
    """How the views were drawn (:mod:`davis_ag.render.backends`' names)."""

    name: str | None = Field(default=None, description="opengl (ours) or helios")
    look: str | None = Field(default=None, description="default or helios")
    antialiasing: str | None = Field(default=None, description="the mode's description (ANTIALIASING_DESCRIPTIONS)")


class GridRecord(_Record):
    """The grid the scene's views lie on, as generated (reduced grids included)."""

    extent_m: list[Number] | None = None
    step_m: Number | None = None
    altitudes_m: list[Number] | None = None
    #: Camera headings per position (1: always aimed at the plant).
    headings: int | None = None
    exclusion_radius_m: Number | None = None
    aim_height_m: Number | None = None
    #: Views on the grid.
    views: int | None = None


class PlantRecord(_Record):
    """One grown plant (:meth:`davis_ag.scene.plants.GrownPlant.summary`)."""

    index: int | None = None
    seed: int | None = None
    position: list[Number] | None = None
    #: Table 1's phenotype drawn for the plant, and the one measured on it, metres.
    phenotype_target: dict[str, Any] | None = None
    phenotype_measured: dict[str, Any] | None = None
    fruit_count: int | None = None
    #: Builds it took (regrowths for too few fruit included).
    builds: int | None = None


class FruitRecord(_Record):
    """One fruit (:meth:`davis_ag.scene.build.Fruit.summary`): its id, plant and 3-D extent."""

    id: int | None = Field(default=None, description="the fruit id of the masks and boxes")
    plant: int | None = Field(default=None, description="the index of the plant bearing it")
    center: list[Number] | None = Field(default=None, description="world x, y, z, metres")
    size: list[Number] | None = Field(default=None, description="extent along x, y, z, metres")


class ViewPlace(_Record):
    """A view's place on the grid and its pose before slip."""

    grid: list[int] | None = Field(default=None, description="column, row, altitude level, heading")
    nominal: list[Number] | None = Field(default=None, description="the pose before slip")


class SceneFile(_Record):
    """``scene.json``: everything the published annotations leave out.

    Attributes:
        format: :data:`SCENE_FORMAT` for scenes our generator wrote.
        seed, dataset_seed: The scene's seed and the dataset seed it follows from.
        scenario, crop, scene: Which scene (``scene`` is ``Group/NNN``).
        plant_generator: ``canopy`` or ``architecture``, ``library`` for a plant-library crop;
            scenes from before the choice lack it.
        structures: The structures setting that built the scene's trellis, stakes or strings
            (``default``); absent where the scene has none (read as ``none``).
        depth, classes: What the depth and class images hold; ``None`` where not written.
        min_fruit_pixels: The box threshold the scene's labels were made with, at its own size.
        visible_fraction: Per view name, per fruit id (text), the fruit's visible fraction.
        timing_s: Seconds spent growing and drawing.
    """

    format: str | None = None
    generator: GeneratorRecord | None = None
    seed: int | None = None
    dataset_seed: int | None = None
    scenario: str | None = None
    crop: str | None = None
    scene: str | None = None
    plant_generator: str | None = None
    structures: str | None = None
    #: Units, frames and encodings in words.
    conventions: dict[str, Any] | None = None
    #: How the views were drawn.
    camera: CameraRecord | None = None
    renderer: RendererRecord | None = None
    depth: dict[str, Any] | None = None
    classes: dict[str, Any] | None = None
    #: The scene's look: soil, sun, sky, exposure, white balance.
    appearance: dict[str, Any] | None = None
    lighting: dict[str, Any] | None = None
    grid: GridRecord | None = None
    min_fruit_pixels: int | None = None
    plants: list[PlantRecord] = []
    fruits: list[FruitRecord] = []
    views: dict[str, ViewPlace] | None = None
    visible_fraction: dict[str, dict[str, Number]] = {}
    timing_s: dict[str, Any] | None = None

    @property
    def ours(self) -> bool:
        """Whether ``davis-ag generate`` wrote it (only those scenes can be regrown)."""
        return self.format == SCENE_FORMAT and self.generator is not None and self.generator.name == "davis-ag"

    @property
    def index(self) -> int | None:
        """The scene's number within its group (``NNN`` of ``scene``)."""
        try:
            return int((self.scene or "").rsplit("/", 1)[1])
        except (IndexError, ValueError):
            return None

    def image_size(self) -> tuple[int, int] | None:
        """``(width, height)`` the views were drawn at, or None when the camera is not recorded."""
        if self.camera is None or self.camera.width is None or self.camera.height is None:
            return None
        return self.camera.width, self.camera.height

    def visible_in(self, view_name: str) -> dict[str, Number]:
        """Each boxed fruit's visible fraction in one view, keyed by fruit id as text."""
        return self.visible_fraction.get(view_name, {})


def scene_file_from(data: Any) -> SceneFile:
    """Check a parsed scene.json.

    Raises:
        ValueError: one line (without the file's name) when it does not fit the model.
    """
    if not isinstance(data, dict):
        raise ValueError(f"must hold a JSON object, got {type(data).__name__}")
    try:
        return SceneFile.model_validate(data)
    except ValidationError as error:
        raise ValueError(one_line(error)) from None


def parse_scene_file(data: Any, source: str | Path) -> SceneFile:
    """Check a parsed scene.json read from ``source``.

    Raises:
        UserError: one line naming the file and the field when it does not fit the model.
    """
    try:
        return scene_file_from(data)
    except ValueError as error:
        raise UserError(f"{source}: {error}; regenerate the scene") from None


def read_scene_file(path: str | Path) -> SceneFile:
    """Read a scene.json.

    Raises:
        UserError: one line when it cannot be read, is no JSON object or does not fit the model.
    """
    try:
        data = json.loads(Path(path).read_text())
    except (OSError, ValueError) as error:
        raise UserError(f"{path}: cannot be read ({error}); regenerate the scene") from None
    return parse_scene_file(data, path)


def read_scene_file_or_empty(path: str | Path) -> SceneFile:
    """A scene.json, or an empty record where it is missing or damaged (for summaries that say
    "unrecorded" rather than stop)."""
    try:
        return read_scene_file(path)
    except UserError:
        return SceneFile()

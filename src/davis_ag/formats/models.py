"""pydantic models of the dataset config and of every JSON file of a dataset, with the one seed and
image-size rule.

- :class:`DatasetConfigFile`: a dataset config (YAML), as ``davis-ag generate --config`` reads it;
- :class:`DatasetFile`: ``dataset.json``, what every scene of a folder shares;
- :class:`SplitsFile`: ``splits.json``, the train/test split by scene;
- :class:`AnnotationEntry`: one entry of ``annotations.json`` as we write it (the reader of
  :mod:`davis_ag.data.reader` stays tolerant of the original download's variations).

The writer builds these files through the models and the reader and validator read them back
through the same models, so a field's type and limits are written once. A bad value becomes one
line naming the field's path (``groups.0.crop``) and what is allowed (:func:`one_line`).
"""

from __future__ import annotations

import math
import re
from typing import Annotated, Any, Literal

from pydantic import (
    AfterValidator,
    BaseModel,
    BeforeValidator,
    ConfigDict,
    Field,
    StrictBool,
    StrictInt,
    TypeAdapter,
    ValidationError,
    ValidationInfo,
    field_validator,
    model_validator,
)

from davis_ag.errors import UserError
from davis_ag.formats.masks import MAX_FRUIT_ID as _MAX_MASK_FRUIT_ID
from davis_ag.scene.appearance import DEFAULT_APPEARANCE, AppearanceMode
from davis_ag.scene.specs import ALL_ACTIONS, DEFAULT_PLANTS, PlantGenerator, crop_spec, group_name, scenario_spec
from davis_ag.scene.structures import DEFAULT_STRUCTURES, StructureSetting

#: Largest seed: NumPy's legacy seeding, Gymnasium and Stable-Baselines3 take 32-bit seeds.
MAX_SEED = 2**32 - 1
#: Smallest image side, pixels: below it no fruit passes a box threshold.
MIN_IMAGE_SIDE = 16
#: Largest image side, pixels. Mesa's llvmpipe (GL_MAX_RENDERBUFFER_SIZE) and current GPUs draw at
#: most 16384 a side, but at that size one frame's colour, id, depth and multisampled buffers take
#: about 7 GB; at 8192 under 2 GB, and 8192 is 6.4 times the paper's 1280.
MAX_IMAGE_SIDE = 8192
#: Scene folders are numbered NNN.
MAX_SCENES = 1000
#: Most views one scene may have: four times the paper's largest grid (MP, 7 x 3 m at 0.5 m, two
#: altitudes, 12 headings: 2,520 views). A step of 1e-9 m would ask for 10^19 views and grow until
#: the machine kills the run; the bound refuses it in one line before anything is written.
MAX_VIEWS_PER_SCENE = 10_000
#: Largest grid side, m (the paper's grids are at most 7 m).
MAX_GRID_EXTENT = 100.0
#: Fruit ids fit a 16-bit mask, whose 65535 means no fruit (a scene of at most 255 fruit keeps
#: them to 0..254 in its uint8 mask: :mod:`davis_ag.formats.masks`).
MAX_FRUIT_ID = _MAX_MASK_FRUIT_ID


def in_range(low: int, high: int) -> AfterValidator:
    """The check of a whole number from ``low`` to ``high``, whose error names the range: a field
    ``Annotated[StrictInt, in_range(low, high)]`` holds such a number."""

    def check(value: int) -> int:
        if not low <= value <= high:
            raise ValueError(f"must be a whole number from {low} to {high}, not {value}")
        return value

    return AfterValidator(check)


Seed = Annotated[StrictInt, in_range(0, MAX_SEED)]


def _size_from_text(value: Any) -> Any:
    """``"1280x720"`` -> ``(1280, 720)``; anything else is left to the tuple's own checks."""
    if isinstance(value, str):
        match = re.fullmatch(r"\s*(\d+)\s*x\s*(\d+)\s*", value)
        if not match:
            raise ValueError(f"must be WIDTHxHEIGHT like 1280x720, not {value!r}")
        return int(match[1]), int(match[2])
    if not (isinstance(value, (list, tuple)) and len(value) == 2):
        raise ValueError(f"must be WIDTHxHEIGHT like 1280x720 or [WIDTH, HEIGHT], not {value!r}")
    return value


def _drawable(size: tuple[int, int]) -> tuple[int, int]:
    if not all(MIN_IMAGE_SIDE <= side <= MAX_IMAGE_SIDE for side in size):
        raise ValueError(
            f"{size[0]}x{size[1]}: each side must be from {MIN_IMAGE_SIDE} to {MAX_IMAGE_SIDE} "
            "pixels (the renderer's limit)"
        )
    return size


ImageSize = Annotated[tuple[StrictInt, StrictInt], BeforeValidator(_size_from_text), AfterValidator(_drawable)]
_SEED = TypeAdapter(Seed)
_IMAGE_SIZE = TypeAdapter(ImageSize)


#: pydantic's wording where ours says more.
_MESSAGES = {
    "missing": "missing",
    "extra_forbidden": "unknown key",
    "int_type": "must be a whole number",
    "bool_type": "must be true or false",
    "float_type": "must be a number",
    "float_parsing": "must be a number",
    "string_type": "must be a text",
}


def one_line(error: ValidationError, source: str = "") -> str:
    """A pydantic error as one line: ``source: field.path: what is wrong (what is allowed)``.

    Args:
        error: The validation error.
        source: Where the data came from (a file, ``--seed``); empty for none.

    Returns:
        The first problem, with a count of the others.
    """
    problems = error.errors(include_url=False)
    first = problems[0]
    path = ".".join(str(part) for part in first["loc"])
    message = str(first["msg"]).removeprefix("Value error, ").removeprefix("Assertion failed, ")
    message = _MESSAGES.get(first["type"], message).replace("Input should be", "must be")
    # Our own checks name the value already; a missing or unknown key has none worth showing.
    if (
        first["type"] not in ("missing", "extra_forbidden", "value_error", "assertion_error")
        and "input" in first
        and not isinstance(first["input"], (dict, list))
    ):
        message = f"{message}, not {first['input']!r}"
    more = f" (and {len(problems) - 1} more problem{'s' if len(problems) > 2 else ''})" if len(problems) > 1 else ""
    return ": ".join(part for part in (source, path, message) if part) + more


def check_seed(value: Any, source: str = "seed") -> int:
    """The one seed rule: a whole number from 0 to :data:`MAX_SEED`.

    Raises:
        UserError: one line naming ``source``.
    """
    try:
        return _SEED.validate_python(value)
    except ValidationError as error:
        raise UserError(one_line(error, source)) from None


def check_image_size(value: Any, source: str = "image size") -> tuple[int, int]:
    """The one image-size rule: ``WIDTHxHEIGHT`` or ``[WIDTH, HEIGHT]``, each side from
    :data:`MIN_IMAGE_SIDE` to :data:`MAX_IMAGE_SIDE` pixels.

    Raises:
        UserError: one line naming ``source`` and the allowed sides.
    """
    try:
        return _IMAGE_SIZE.validate_python(value)
    except ValidationError as error:
        raise UserError(one_line(error, source)) from None


class _Model(BaseModel):
    model_config = ConfigDict(extra="forbid", frozen=True)

    def to_json(self) -> dict[str, Any]:
        """The JSON-ready dict, without unset optional keys."""
        return self.model_dump(mode="json", exclude_none=True)


# ---------------------------------------------------------------------------------------------
# The dataset config


class GridOverride(_Model):
    """A change to the scenario's Table 2 grid (smaller scenes for quick looks and tests)."""

    extent: (
        tuple[
            Annotated[float, Field(gt=0, le=MAX_GRID_EXTENT, allow_inf_nan=False)],
            Annotated[float, Field(gt=0, le=MAX_GRID_EXTENT, allow_inf_nan=False)],
        ]
        | None
    ) = None
    step: Annotated[float, Field(gt=0, le=MAX_GRID_EXTENT, allow_inf_nan=False)] | None = None
    altitude_levels: list[Literal[0, 1, 2]] | None = None
    headings: Annotated[StrictInt, in_range(1, 360)] | None = None

    @field_validator("altitude_levels")
    @classmethod
    def _distinct_increasing(cls, levels: list[int] | None) -> list[int] | None:
        if levels is not None and (not levels or levels != sorted(set(levels))):
            raise ValueError(f"must list distinct levels from 0 (low) to 2 (high) in increasing order, not {levels}")
        return levels

    @field_validator("headings")
    @classmethod
    def _no_diagonal(cls, headings: int | None) -> int | None:
        # Forward moves along the grid axis nearest the heading: a diagonal would be a tie.
        if (
            headings is not None
            and headings > 1
            and (360 % headings or any(math.isclose((k * 360 / headings) % 90, 45) for k in range(headings)))
        ):
            raise ValueError(f"{headings} does not work for multi plant: use 2, 3, 4, 6 or 12 (1 for single plant)")
        return headings

    def changes(self) -> dict[str, Any]:
        """The set fields, as :class:`~davis_ag.scene.specs.ScenarioSpec` takes them."""
        return {
            k: tuple(v) if isinstance(v, (list, tuple)) else v for k, v in self.model_dump(exclude_none=True).items()
        }


class GroupEntry(_Model):
    """One ``groups`` entry: a published folder such as ``Single-Strawberry``."""

    scenario: str
    crop: str
    scenes: Annotated[StrictInt, in_range(1, MAX_SCENES)]
    first: Annotated[StrictInt, in_range(0, MAX_SCENES - 1)] = 0
    grid: GridOverride | None = None

    @field_validator("scenario", "crop")
    @classmethod
    def _known_name(cls, name: str, info: ValidationInfo) -> str:
        """The canonical name (``single`` -> ``sp``, ``grape`` -> ``vine``); the error lists the choices."""
        try:
            return (scenario_spec if info.field_name == "scenario" else crop_spec)(name).name
        except UserError as error:
            raise ValueError(str(error)) from None

    @model_validator(mode="after")
    def _fits_the_numbering(self) -> GroupEntry:
        if self.first + self.scenes > MAX_SCENES:
            raise ValueError(f"scenes {self.first}..{self.first + self.scenes - 1} do not fit 000..{MAX_SCENES - 1}")
        return self


def _antialiasing(value: Any) -> Any:
    """Earlier versions took samples per pixel: 4 and 1 still mean ``msaa`` and ``none``."""
    if isinstance(value, bool):
        return value
    return {"4": "msaa", "1": "none"}.get(str(value).strip().lower(), value) if value is not None else "fxaa"


class DatasetConfigFile(_Model):
    """A dataset config: groups of scenes and what they share (``davis-ag generate --config``)."""

    name: Annotated[str, Field(min_length=1)] | None = None
    seed: Seed = 0
    image_size: ImageSize = (1280, 720)
    renderer: Literal["opengl", "helios"] = "opengl"
    look: Literal["default", "helios"] | None = None
    depth: StrictBool = True
    antialiasing: Annotated[Literal["fxaa", "msaa", "none"], BeforeValidator(_antialiasing)] = "fxaa"
    plants: PlantGenerator = DEFAULT_PLANTS
    appearance: AppearanceMode = DEFAULT_APPEARANCE
    structures: StructureSetting = DEFAULT_STRUCTURES
    strawberry_altitudes: Literal["table1", "readme"] = "table1"
    grid: GridOverride | None = None
    groups: list[GroupEntry]

    @field_validator("groups")
    @classmethod
    def _some_group(cls, groups: list[GroupEntry]) -> list[GroupEntry]:
        if not groups:
            raise ValueError("must be a non-empty list of {scenario, crop, scenes} entries")
        return groups

    @model_validator(mode="after")
    def _each_group_once(self) -> DatasetConfigFile:
        seen: dict[tuple[str, str], int] = {}
        for position, group in enumerate(self.groups):
            key = (group.scenario, group.crop)
            if key in seen:
                name = group_name(scenario_spec(group.scenario), crop_spec(group.crop))
                raise ValueError(
                    f"groups.{position}: {name} is already groups.{seen[key]}: give each scenario and crop once"
                )
            seen[key] = position
        if self.renderer == "helios" and self.look == "default":
            raise ValueError("look: the helios renderer has only the helios look (the default look is ours)")
        return self


# ---------------------------------------------------------------------------------------------
# dataset.json and splits.json


class GridSettings(_Model):
    """A group's viewpoint grid as recorded in dataset.json."""

    model_config = ConfigDict(extra="allow", frozen=True)
    extent: tuple[float, float]
    step: Annotated[float, Field(gt=0)]
    altitude_levels: list[Literal[0, 1, 2]]
    headings: Annotated[StrictInt, in_range(1, 360)]
    altitudes_m: list[float] | None = None


class DatasetGroup(_Model):
    """One group's entry in dataset.json."""

    model_config = ConfigDict(extra="allow", frozen=True)
    grid: GridSettings


class OrganClass(_Model):
    """One row of dataset.json's organ class table: a value of NNNN_class.png and what it covers."""

    value: Annotated[StrictInt, in_range(0, 255)]
    name: str
    covers: str


class DatasetFile(_Model):
    """``dataset.json``: the settings every scene of one folder shares; a later run with other
    settings is refused before anything is written. Keys of later versions are kept."""

    model_config = ConfigDict(extra="allow", frozen=True)
    format: str = "davis-ag-dataset/1"
    seed: Seed
    image_size: ImageSize
    vfov_deg: Annotated[float, Field(gt=0, lt=180)]
    # Datasets from before the choice of renderer were drawn by Helios.
    renderer: Literal["opengl", "helios"] = "helios"
    look: Literal["default", "helios"] = "helios"
    # Datasets from before the choice of plants grew PlantArchitecture plants.
    plants: PlantGenerator = "architecture"
    # ... and before randomised appearance, the paper's.
    appearance: AppearanceMode = "paper"
    #: The organ class table of NNNN_class.png, where the scenes have them.
    classes: list[OrganClass] | None = None
    groups: dict[str, DatasetGroup]


class SplitsFile(_Model):
    """``splits.json``: the train/test split by scene (section V-D); ``seed`` where we drew it."""

    model_config = ConfigDict(extra="ignore", frozen=True)
    seed: Seed | None = None
    train: list[str]
    test: list[str]

    def in_both(self) -> list[str]:
        """Scene ids listed for train and for test (a damaged file; the validator reports them)."""
        return sorted(set(self.train) & set(self.test))


# ---------------------------------------------------------------------------------------------
# annotations.json


ViewName = Annotated[str, Field(pattern=r"^(\d{4,}\.jpeg)?$")]
BoxList = tuple[
    Annotated[StrictInt, Field(ge=0)],
    Annotated[StrictInt, Field(ge=0)],
    Annotated[StrictInt, Field(ge=1)],
    Annotated[StrictInt, Field(ge=1)],
    Annotated[StrictInt, Field(ge=0, le=MAX_FRUIT_ID)],
    Literal[0],
]


class AnnotationEntry(_Model):
    """One view's entry in annotations.json as we write it: boxes ``[xmin, ymin, width, height,
    fruit_id, 0]`` (inclusive pixel extent), the pose ``[x, y, z, yaw, pitch]`` (metres,
    degrees) and the image each action leads to (``""`` where the move is invalid)."""

    bounding_boxes: list[BoxList]
    pose: tuple[float, float, float, float, float]
    forward: ViewName | None = None
    backward: ViewName | None = None
    left: ViewName | None = None
    right: ViewName | None = None
    up: ViewName | None = None
    down: ViewName | None = None
    rotate_cw: ViewName | None = None
    rotate_ccw: ViewName | None = None

    @model_validator(mode="after")
    def _one_box_per_fruit(self) -> AnnotationEntry:
        ids = [box[4] for box in self.bounding_boxes]
        if len(ids) != len(set(ids)):
            raise ValueError("a fruit has two boxes in this view")
        return self


assert set(AnnotationEntry.model_fields) - {"bounding_boxes", "pose"} == set(ALL_ACTIONS), "an action without a field"

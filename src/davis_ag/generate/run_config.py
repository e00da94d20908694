"""Dataset config files: a whole dataset (groups of scenes, image size, seed) in one YAML file.

Format (every key but ``groups`` is optional)::

    name: paper                  # a label; defaults to the file name
    seed: 0                      # dataset seed, a whole number from 0 to 2**32 - 1 (default 0)
    image_size: 1280x720         # WIDTHxHEIGHT or [WIDTH, HEIGHT], 16 to 8192 a side (default 1280x720)
    renderer: opengl             # opengl (ours, default) or helios (pyhelios's Visualizer)
    look: default                # default or helios (Helios's texture handling); helios renderer: helios
    depth: true                  # write images/NNNN_depth.png (uint16 mm) for every view
    antialiasing: fxaa           # our renderer's: fxaa (default), msaa (4x samples, slower) or none
    plants: canopy               # canopy (Helios's Canopy Generator, default) or architecture
    appearance: paper            # paper (default) or random: sun, sky, soil, exposure, noise per scene
    structures: default          # default: row scenes get their crop's trellis, stakes or strings; none: bare rows
    strawberry_altitudes: table1 # table1 (25/40/55 cm, default) or readme (0.50/0.75/1.00 m)
    grid:                        # overrides the scenario's Table 2 grid for every group
      extent: [3.0, 3.0]         #   grid size along x and y, m
      step: 0.5                  #   distance between positions, m
      altitude_levels: [0, 2]    #   which of the crop's three altitudes (0 low .. 2 high)
      headings: 12               #   multi plant only: headings per position
    groups:
      - scenario: sp             # sp / single or mp / multi
        crop: strawberry         # strawberry, tomato or vine
        scenes: 86               # how many scenes
        first: 0                 # index of the first scene (default 0)
        grid: {step: 1.0}        # per-group override, merged over the top-level one

A ``grid`` override makes scenes smaller than the paper's (quick looks, tests); scenes keep their
seeds (the seed depends on the scenario and crop names and the index only), and the grid used is
recorded in every scene.json and in the dataset's dataset.json.

Presets ship in ``davis_ag/generate/presets``: ``paper`` (Table 3's scene counts) and ``mini`` (two small
single-plant scenes, minutes on a laptop). ``--config`` takes a preset name or a file path.
"""

from __future__ import annotations

import dataclasses
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from davis_ag.errors import UserError, yaml_problem
from davis_ag.formats.models import (
    MAX_SCENES,
    MAX_VIEWS_PER_SCENE,
    DatasetConfigFile,
    check_image_size,
    check_seed,
    one_line,
)
from davis_ag.generate.one_scene import SceneRequest, SceneSettings
from davis_ag.render.backends import DEFAULT_RENDERER, resolve_look
from davis_ag.scene.appearance import resolve_appearance
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import (
    DEFAULT_PLANTS,
    CropSpec,
    ScenarioSpec,
    camera_altitudes,
    check_plants,
    crop_spec,
    group_name,
    scenario_spec,
    with_strawberry_altitudes,
)
from davis_ag.scene.structures import DEFAULT_STRUCTURES, check_structures
from davis_ag.scene.view_grid import lattice_shape


@dataclass(frozen=True)
class GroupConfig:
    """One group of scenes (a published folder such as ``Single-Strawberry``).

    Attributes:
        scenario: The scenario, with any grid override applied.
        crop: The crop.
        scenes: How many scenes.
        first: Index of the first scene.
    """

    scenario: ScenarioSpec
    crop: CropSpec
    scenes: int
    first: int = 0

    @property
    def name(self) -> str:
        """The group's folder name."""
        return group_name(self.scenario, self.crop)

    @property
    def indices(self) -> range:
        """The scene indices of the group."""
        return range(self.first, self.first + self.scenes)


@dataclass(frozen=True)
class DatasetConfig(SceneSettings):
    """A whole dataset: its groups, and how every scene is made (the :class:`SceneSettings`, by
    keyword).

    Attributes:
        name: A label (the preset or file name by default).
        seed: The dataset seed every scene seed derives from.
        camera: Image size and field of view.
        groups: The groups, in file order.
        source: Where it was read from (for messages).
    """

    name: str
    seed: int
    camera: Camera
    groups: tuple[GroupConfig, ...]
    source: str = "<config>"

    def requests(self, only: list[str] | None = None) -> list[SceneRequest]:
        """Every scene to make, in group order, optionally narrowed to some groups or scenes.

        Args:
            only: Scene ids (``Single-Strawberry/003``) or group names (``Single-Strawberry``);
                ``None`` or empty keeps everything.

        Returns:
            The scene requests.

        Raises:
            UserError: when an ``only`` entry names nothing of this dataset.
        """
        settings = {**self.scene_settings(), "look": resolve_look(self.renderer, self.look)}
        everything = [
            SceneRequest(g.scenario, g.crop, i, self.seed, self.camera, **settings)
            for g in self.groups
            for i in g.indices
        ]
        if not only:
            return everything
        wanted: set[str] = set()
        for item in only:
            key = _normalise_scene_id(item)
            matches = {r.folder for r in everything if r.folder == key or r.folder.split("/")[0] == key}
            if not matches:
                groups = ", ".join(f"{g.name}/{g.first:03d}..{g.first + g.scenes - 1:03d}" for g in self.groups)
                raise UserError(f"--only {item!r}: not a scene or group of {self.source} (it has {groups})")
            wanted |= matches
        return [r for r in everything if r.folder in wanted]


def _normalise_scene_id(text: str) -> str:
    """``single-strawberry/3`` and ``Single-Strawberry/003/`` both become ``Single-Strawberry/003``."""
    group, _, index = text.strip().strip("/").replace("\\", "/").partition("/")
    titled = "-".join(part.capitalize() for part in group.split("-"))
    if index.isascii() and index.isdigit():
        return f"{titled}/{int(index):03d}"
    return titled if not index else f"{titled}/{index}"


def single_group_config(
    scenario: str,
    crop: str,
    scenes: int,
    first: int,
    seed: int,
    size: tuple[int, int],
    renderer: str = DEFAULT_RENDERER,
    look: str | None = None,
    depth: bool = True,
    antialiasing: str = "fxaa",
    plants: str = DEFAULT_PLANTS,
    appearance: str = "paper",
    structures: str = DEFAULT_STRUCTURES,
) -> DatasetConfig:
    """The dataset the classic flags (--scenario --crop --scenes --first) describe.

    Returns:
        A one-group :class:`DatasetConfig`.

    Raises:
        UserError: for unknown names or indices outside 000..999.
    """
    crop_settings = crop_spec(crop)
    group = GroupConfig(scenario_spec(scenario, crop_settings), crop_settings, scenes, first)
    if first < 0 or first + scenes > MAX_SCENES:
        raise UserError(f"scene indices {first}..{first + scenes - 1} do not fit 000..{MAX_SCENES - 1}")
    check_seed(seed, "--seed")
    size = check_image_size(size, "--size")
    resolve_look(renderer, look)
    return DatasetConfig(
        "command line",
        seed,
        Camera(*size),
        (group,),
        "the command line",
        renderer=renderer,
        look=look,
        depth=depth,
        antialiasing=antialiasing,
        plants=check_plants(plants),
        appearance=resolve_appearance(appearance),
        structures=check_structures(structures),
    )


# ---------------------------------------------------------------------------------------------
# Loading


def preset_names() -> list[str]:
    """Names of the presets shipped with the package."""
    folder = resources.files("davis_ag") / "generate" / "presets"
    return sorted(p.name[:-5] for p in folder.iterdir() if p.name.endswith(".yaml"))


def load_dataset_config(name_or_path: str | Path) -> DatasetConfig:
    """Read a dataset config from a file, or a preset by name.

    Args:
        name_or_path: A path to a YAML file, or a preset name (``paper``, ``mini``).

    Returns:
        The validated config.

    Raises:
        UserError: when the file is missing or unreadable, or anything in it is wrong (the
            message names the file, the key and what is wrong).
    """
    path = Path(name_or_path).expanduser()
    text_name = str(name_or_path)
    if path.is_file():
        try:
            text = path.read_text()
        except (OSError, UnicodeDecodeError) as error:
            raise UserError(f"{path}: cannot read it ({error})") from None
        return parse_dataset_config(text, str(path), default_name=path.stem)
    presets = preset_names()
    if text_name in presets:
        text = (resources.files("davis_ag") / "generate" / "presets" / f"{text_name}.yaml").read_text()
        return parse_dataset_config(text, f"preset {text_name}", default_name=text_name)
    if path.is_dir():
        raise UserError(f"{path} is a folder: give a YAML file or a preset ({', '.join(presets)})")
    if path.exists():  # a device such as /dev/zero, a pipe or a socket: never read it
        raise UserError(
            f"{path} is not a regular file (a device, pipe or socket): give a YAML file or a "
            f"preset ({', '.join(presets)})"
        )
    raise UserError(
        f"no config file {text_name!r} and no preset of that name: give a YAML file "
        f"or one of the presets {', '.join(presets)}"
    )


def parse_dataset_config(text: str, source: str, default_name: str = "dataset") -> DatasetConfig:
    """Validate the YAML text of a dataset config (:class:`~davis_ag.formats.models.DatasetConfigFile`).

    Args:
        text: The YAML.
        source: Where it came from, for messages.
        default_name: The name when the file gives none.

    Returns:
        The config.

    Raises:
        UserError: one line naming the source, the key's path (``groups.0.crop``) and what is
            allowed.
    """
    import yaml

    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as error:
        raise UserError(f"{source}: {yaml_problem(error)}") from None
    if not isinstance(data, dict):
        raise UserError(f"{source}: must be a mapping with at least a 'groups' list")
    try:
        model = DatasetConfigFile.model_validate(data)
    except ValidationError as error:
        raise UserError(one_line(error, source)) from None
    groups = []
    for position, entry in enumerate(model.groups):
        crop = with_strawberry_altitudes(crop_spec(entry.crop), model.strawberry_altitudes)
        scenario = scenario_spec(entry.scenario, crop)  # the crop's grid (Table 3's counts)
        where = f"{source}: groups.{position}.grid" if entry.grid else f"{source}: grid"
        changes = {**(model.grid.changes() if model.grid else {}), **(entry.grid.changes() if entry.grid else {})}
        groups.append(GroupConfig(apply_grid(scenario, changes, where), crop, entry.scenes, entry.first))
    return DatasetConfig(
        (model.name or default_name).strip(),
        model.seed,
        Camera(*model.image_size),
        tuple(groups),
        source,
        renderer=model.renderer,
        look=model.look,
        depth=model.depth,
        antialiasing=model.antialiasing,
        plants=model.plants,
        appearance=model.appearance,
        structures=model.structures,
    )


def use_strawberry_altitudes(config: DatasetConfig, choice: str) -> DatasetConfig:
    """The config with every strawberry group photographed at the chosen altitudes.

    Args:
        config: A dataset config.
        choice: ``table1`` (25/40/55 cm) or ``readme`` (0.50/0.75/1.00 m).

    Returns:
        The changed config.

    Raises:
        UserError: for an unknown choice.
    """
    groups = tuple(dataclasses.replace(g, crop=with_strawberry_altitudes(g.crop, choice)) for g in config.groups)
    return dataclasses.replace(config, groups=groups)


def apply_grid(scenario: ScenarioSpec, changes: dict[str, Any], where: str) -> ScenarioSpec:
    """The scenario with a grid override (already checked field by field) applied, and checked
    against the scenario.

    Raises:
        UserError: ``where`` and what does not fit.
    """
    if not changes:
        return scenario
    extent, step = changes.get("extent", scenario.extent), changes.get("step", scenario.step)
    if min(extent) < step:
        raise UserError(f"{where}: step {step} m is larger than the extent {list(extent)}: no position fits")
    if scenario.headings == 1 and changes.get("headings", 1) != 1:
        raise UserError(f"{where}.headings: the single-plant camera always faces the plant: only 1")
    if scenario.headings > 1 and changes.get("headings", 2) < 2:
        raise UserError(f"{where}.headings: multi plant needs 2, 3, 4, 6 or 12")
    changed = dataclasses.replace(scenario, **changes)
    nx, ny = lattice_shape(changed)  # counted, not built: a tiny step must not fill the memory first
    views = nx * ny * len(changed.altitude_levels) * changed.headings
    if views > MAX_VIEWS_PER_SCENE:
        raise UserError(
            f"{where}: step {step} m over {list(extent)} m gives up to {views:,} views a scene, more "
            f"than {MAX_VIEWS_PER_SCENE:,} (the paper's largest grid has 2,520): use a larger step "
            "or a smaller extent"
        )
    return changed


def grid_settings(scenario: ScenarioSpec, crop: CropSpec | None = None) -> dict[str, Any]:
    """The grid a scenario spec describes, JSON-ready (recorded in dataset.json).

    Args:
        scenario: The scenario's grid.
        crop: When given, its camera altitudes in metres are recorded too (strawberry has two
            choices, see ``specs.STRAWBERRY_ALTITUDES``).

    Returns:
        The settings.
    """
    settings = {
        "extent": list(scenario.extent),
        "step": scenario.step,
        "altitude_levels": list(scenario.altitude_levels),
        "headings": scenario.headings,
    }
    if crop is not None:
        settings["altitudes_m"] = camera_altitudes(scenario, crop)
    return settings

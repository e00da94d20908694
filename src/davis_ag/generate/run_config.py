"""Dataset config files: a whole dataset (groups of scenes, image size, seed) in one YAML file.

Format (every key but ``groups`` is optional)::

    name: paper                  # a label; defaults to the file name
    seed: 0                      # dataset seed, a whole number from 0 (default 0)
    image_size: 1280x720         # WIDTHxHEIGHT or [WIDTH, HEIGHT] (default 1280x720)
    renderer: opengl             # opengl (ours, default) or helios (pyhelios's Visualizer)
    look: default                # default or helios (Helios's texture handling); helios renderer: helios
    depth: true                  # write images/NNNN_depth.png (uint16 mm) for every view
    antialiasing: fxaa           # our renderer's: fxaa (default), msaa (4x samples, slower) or none
    plants: canopy               # canopy (Helios's Canopy Generator, default) or architecture
    appearance: paper            # paper (default) or random: sun, sky, soil, exposure, noise per scene
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
import math
import re
from dataclasses import dataclass
from importlib import resources
from pathlib import Path
from typing import Any

from davis_ag.errors import UserError
from davis_ag.generate.one_scene import SceneRequest
from davis_ag.render.backends import DEFAULT_RENDERER, resolve_antialiasing, resolve_look
from davis_ag.scene.appearance import resolve_appearance
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import (
    DEFAULT_PLANTS,
    PLANT_GENERATORS,
    check_plants,
    CropSpec,
    ScenarioSpec,
    crop_spec,
    group_name,
    scenario_spec,
    with_strawberry_altitudes,
)

#: Smallest image side accepted, pixels.
MIN_IMAGE_SIDE = 16
#: Scene folders are numbered NNN.
MAX_SCENES = 1000
TOP_KEYS = ("name", "seed", "image_size", "renderer", "look", "depth", "antialiasing", "plants", "appearance",
            "strawberry_altitudes",
            "grid", "groups")
GROUP_KEYS = ("scenario", "crop", "scenes", "first", "grid")
GRID_KEYS = ("extent", "step", "altitude_levels", "headings")


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
class DatasetConfig:
    """A whole dataset.

    Attributes:
        name: A label (the preset or file name by default).
        seed: The dataset seed every scene seed derives from.
        camera: Image size and field of view.
        groups: The groups, in file order.
        source: Where it was read from (for messages).
        renderer: ``opengl`` or ``helios``.
        look: ``default`` or ``helios``; None for the renderer's own.
        depth: Whether every view gets a depth image.
        antialiasing: Our renderer's antialiasing: ``fxaa``, ``msaa`` or ``none``.
        plants: The plant generator: ``canopy`` (default) or ``architecture``.
        appearance: ``paper`` or ``random`` (:mod:`davis_ag.scene.appearance`).
    """

    name: str
    seed: int
    camera: Camera
    groups: tuple[GroupConfig, ...]
    source: str = "<config>"
    renderer: str = DEFAULT_RENDERER
    look: str | None = None
    depth: bool = True
    antialiasing: str = "fxaa"
    plants: str = DEFAULT_PLANTS
    appearance: str = "paper"

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
        look = resolve_look(self.renderer, self.look)
        everything = [SceneRequest(g.scenario, g.crop, i, self.seed, self.camera, self.renderer, look, self.depth,
                                   self.antialiasing, self.plants, self.appearance)
                      for g in self.groups for i in g.indices]
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
    if index.isdigit():
        return f"{titled}/{int(index):03d}"
    return titled if not index else f"{titled}/{index}"


def single_group_config(scenario: str, crop: str, scenes: int, first: int, seed: int,
                        size: tuple[int, int], renderer: str = DEFAULT_RENDERER, look: str | None = None,
                        depth: bool = True, antialiasing: str = "fxaa", plants: str = DEFAULT_PLANTS,
                        appearance: str = "paper") -> DatasetConfig:
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
    if seed < 0:
        raise UserError(f"--seed {seed} is negative: use a whole number from 0")
    resolve_look(renderer, look)
    return DatasetConfig("command line", seed, Camera(*size), (group,), "the command line", renderer, look, depth,
                         antialiasing, check_plants(plants), resolve_appearance(appearance))


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
    if path.exists():
        raise UserError(f"{path} is a folder: give a YAML file or a preset ({', '.join(presets)})")
    raise UserError(f"no config file {text_name!r} and no preset of that name: give a YAML file "
                    f"or one of the presets {', '.join(presets)}")


def parse_dataset_config(text: str, source: str, default_name: str = "dataset") -> DatasetConfig:
    """Validate the YAML text of a dataset config.

    Args:
        text: The YAML.
        source: Where it came from, for messages.
        default_name: The name when the file gives none.

    Returns:
        The config.

    Raises:
        UserError: naming the source, the key and what is wrong.
    """
    import yaml

    try:
        data = yaml.safe_load(text)
    except yaml.YAMLError as error:
        mark = getattr(error, "problem_mark", None)
        where = f" at line {mark.line + 1}, column {mark.column + 1}" if mark else ""
        problem = getattr(error, "problem", None) or "not valid YAML"
        raise UserError(f"{source}: not valid YAML{where}: {problem}") from None
    check = _Checker(source)
    if not isinstance(data, dict):
        check.fail("", "must be a mapping with at least a 'groups' list")
    check.keys(data, "", TOP_KEYS)
    name = data.get("name", default_name)
    if not isinstance(name, str) or not name.strip():
        check.fail("name", f"must be a non-empty text, not {name!r}")
    seed = check.whole(data.get("seed", 0), "seed", minimum=0)
    camera = Camera(*check.image_size(data.get("image_size", "1280x720"), "image_size"))
    renderer, look = data.get("renderer", DEFAULT_RENDERER), data.get("look")
    try:
        resolve_look(renderer, look)
    except UserError as error:
        check.fail("renderer" if renderer not in ("opengl", "helios") else "look", str(error))
    depth = data.get("depth", True)
    if not isinstance(depth, bool):
        check.fail("depth", f"must be true or false, not {depth!r}")
    try:
        antialiasing = resolve_antialiasing(data.get("antialiasing"))
    except UserError as error:
        check.fail("antialiasing", str(error))
    plants = data.get("plants", DEFAULT_PLANTS)
    if plants not in PLANT_GENERATORS:
        check.fail("plants", f"must be {' or '.join(PLANT_GENERATORS)}, not {plants!r}")
    try:
        appearance = resolve_appearance(data.get("appearance"))
    except UserError as error:
        check.fail("appearance", str(error))
    top_grid = check.grid_mapping(data.get("grid", {}), "grid")
    groups_data = data.get("groups")
    if not isinstance(groups_data, list) or not groups_data:
        check.fail("groups", "must be a non-empty list of {scenario, crop, scenes} entries")
    groups: list[GroupConfig] = []
    for position, item in enumerate(groups_data):
        groups.append(check.group(item, f"groups[{position}]", top_grid))
    seen: dict[str, int] = {}
    for position, group in enumerate(groups):
        if group.name in seen:
            check.fail(f"groups[{position}]", f"{group.name} is already groups[{seen[group.name]}]: "
                                              "give each scenario and crop once")
        seen[group.name] = position
    altitudes = data.get("strawberry_altitudes", "table1")
    try:
        groups = [dataclasses.replace(g, crop=with_strawberry_altitudes(g.crop, str(altitudes))) for g in groups]
    except UserError as error:
        check.fail("strawberry_altitudes", str(error))
    return DatasetConfig(name.strip(), seed, camera, tuple(groups), source, renderer, look, depth, antialiasing,
                         plants, appearance)


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


class _Checker:
    """Raises UserErrors that name the file and the key."""

    def __init__(self, source: str) -> None:
        self.source = source

    def fail(self, key: str, what: str) -> None:
        """Raise the error for ``key``."""
        raise UserError(f"{self.source}: {key + ': ' if key else ''}{what}")

    def keys(self, data: dict, where: str, known: tuple[str, ...]) -> None:
        """Reject keys this format does not know (a typo would otherwise be silently ignored)."""
        for key in data:
            if key not in known:
                self.fail(f"{where}.{key}".lstrip("."), f"unknown key (known: {', '.join(known)})")

    def whole(self, value: Any, key: str, minimum: int, maximum: int | None = None) -> int:
        """A whole number in range."""
        if isinstance(value, bool) or not isinstance(value, int):
            self.fail(key, f"must be a whole number, not {value!r}")
        if value < minimum or (maximum is not None and value > maximum):
            upper = f" to {maximum}" if maximum is not None else ""
            self.fail(key, f"must be from {minimum}{upper}, not {value}")
        return value

    def number(self, value: Any, key: str) -> float:
        """A positive finite number."""
        if isinstance(value, bool) or not isinstance(value, (int, float)) or not math.isfinite(value) \
                or value <= 0:
            self.fail(key, f"must be a positive number (metres), not {value!r}")
        return float(value)

    def image_size(self, value: Any, key: str) -> tuple[int, int]:
        """``WIDTHxHEIGHT`` or ``[WIDTH, HEIGHT]``."""
        if isinstance(value, str) and (match := re.fullmatch(r"\s*(\d+)\s*x\s*(\d+)\s*", value)):
            size = (int(match[1]), int(match[2]))
        elif isinstance(value, list) and len(value) == 2 and all(
                isinstance(v, int) and not isinstance(v, bool) for v in value):
            size = (value[0], value[1])
        else:
            self.fail(key, f"must be WIDTHxHEIGHT like 1280x720, not {value!r}")
        if min(size) < MIN_IMAGE_SIDE:
            self.fail(key, f"{size[0]}x{size[1]} is too small: {MIN_IMAGE_SIDE} pixels a side at least")
        return size

    def grid_mapping(self, value: Any, key: str) -> dict[str, Any]:
        """A grid override's raw mapping (checked against the scenario later)."""
        if value is None:
            return {}
        if not isinstance(value, dict):
            self.fail(key, f"must be a mapping of {', '.join(GRID_KEYS)}, not {value!r}")
        self.keys(value, key, GRID_KEYS)
        return dict(value)

    def group(self, item: Any, where: str, top_grid: dict[str, Any]) -> GroupConfig:
        """One groups[] entry."""
        if not isinstance(item, dict):
            self.fail(where, f"must be a mapping with scenario, crop and scenes, not {item!r}")
        self.keys(item, where, GROUP_KEYS)
        for key in ("scenario", "crop", "scenes"):
            if key not in item:
                self.fail(f"{where}.{key}", "missing")
        specs: list[Any] = []
        for key, lookup in (("scenario", scenario_spec), ("crop", crop_spec)):
            if not isinstance(item[key], str):
                self.fail(f"{where}.{key}", f"must be a name, not {item[key]!r}")
            try:
                specs.append(lookup(item[key]))
            except UserError as error:
                self.fail(f"{where}.{key}", str(error))
        scenario, crop = specs
        scenario = scenario_spec(scenario.name, crop)  # the crop's grid (Table 3's counts)
        scenes = self.whole(item["scenes"], f"{where}.scenes", minimum=1, maximum=MAX_SCENES)
        first = self.whole(item.get("first", 0), f"{where}.first", minimum=0, maximum=MAX_SCENES - 1)
        if first + scenes > MAX_SCENES:
            self.fail(where, f"scenes {first}..{first + scenes - 1} do not fit 000..{MAX_SCENES - 1}")
        grid = {**top_grid, **self.grid_mapping(item.get("grid", {}), f"{where}.grid")}
        scenario = self.apply_grid(scenario, grid, f"{where}.grid" if item.get("grid") else "grid")
        return GroupConfig(scenario, crop, scenes, first)

    def apply_grid(self, scenario: ScenarioSpec, grid: dict[str, Any], where: str) -> ScenarioSpec:
        """The scenario with a grid override applied and checked."""
        if not grid:
            return scenario
        changes: dict[str, Any] = {}
        if "extent" in grid:
            extent = grid["extent"]
            if not isinstance(extent, list) or len(extent) != 2:
                self.fail(f"{where}.extent", f"must be [x, y] in metres, not {extent!r}")
            changes["extent"] = tuple(self.number(v, f"{where}.extent") for v in extent)
        if "step" in grid:
            changes["step"] = self.number(grid["step"], f"{where}.step")
        extent, step = changes.get("extent", scenario.extent), changes.get("step", scenario.step)
        if min(extent) < step:
            self.fail(where, f"step {step} m is larger than the extent {list(extent)}: no position fits")
        if "altitude_levels" in grid:
            levels = grid["altitude_levels"]
            if not isinstance(levels, list) or not levels or any(
                    isinstance(v, bool) or v not in (0, 1, 2) for v in levels) or levels != sorted(set(levels)):
                self.fail(f"{where}.altitude_levels",
                          f"must list distinct levels from 0 (low) to 2 (high) in increasing order, not {levels!r}")
            changes["altitude_levels"] = tuple(levels)
        if "headings" in grid:
            headings = self.whole(grid["headings"], f"{where}.headings", minimum=1, maximum=360)
            if scenario.headings == 1 and headings != 1:
                self.fail(f"{where}.headings", "the single-plant camera always faces the plant: only 1")
            # Forward moves along the grid axis nearest the heading: a diagonal would be a tie.
            diagonal = any(math.isclose((k * 360 / headings) % 90, 45) for k in range(headings))
            if scenario.headings > 1 and (headings < 2 or diagonal or 360 % headings):
                self.fail(f"{where}.headings", f"{headings} does not work for multi plant: use 2, 3, 4, 6 or 12")
            changes["headings"] = headings
        return dataclasses.replace(scenario, **changes)


def grid_settings(scenario: ScenarioSpec, crop: CropSpec | None = None) -> dict[str, Any]:
    """The grid a scenario spec describes, JSON-ready (recorded in dataset.json).

    Args:
        scenario: The scenario's grid.
        crop: When given, its camera altitudes in metres are recorded too (strawberry has two
            choices, see ``specs.STRAWBERRY_ALTITUDES``).

    Returns:
        The settings.
    """
    settings = {"extent": list(scenario.extent), "step": scenario.step,
                "altitude_levels": list(scenario.altitude_levels), "headings": scenario.headings}
    if crop is not None:
        settings["altitudes_m"] = [crop.altitudes[i] for i in scenario.altitude_levels]
    return settings


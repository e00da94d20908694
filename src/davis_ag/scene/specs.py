"""What a DAVIS-Ag scene is made of: the paper's crop (Table 1) and scenario (Table 2) settings.

Everything here is plain data. Lengths are metres, angles degrees.
"""

from __future__ import annotations

from dataclasses import dataclass, replace
from typing import Final, Literal, get_args

from davis_ag.errors import UserError
from davis_ag.scene.crop_spec import PAPER_IMAGE_SIZE, PAPER_PIXELS, CropSpec, RowSpec  # noqa: F401 - re-exported
from davis_ag.scene.library_crops import LIBRARY_CROPS

#: Actions of the single-plant scenario, in the order the environment numbers them.
SP_ACTIONS: tuple[str, ...] = ("forward", "backward", "left", "right", "up", "down")
#: Multi-plant adds the two rotations of 30 degrees.
MP_ACTIONS: tuple[str, ...] = (*SP_ACTIONS, "rotate_cw", "rotate_ccw")
#: Every pointer key an annotations.json entry may carry.
ALL_ACTIONS: tuple[str, ...] = MP_ACTIONS

#: Each action's inverse: applying both (when both are valid) returns to the start.
INVERSE_ACTION: dict[str, str] = {
    "forward": "backward",
    "backward": "forward",
    "left": "right",
    "right": "left",
    "up": "down",
    "down": "up",
    "rotate_cw": "rotate_ccw",
    "rotate_ccw": "rotate_cw",
}


#: Table 3 of the paper: (scenario, crop) -> (scenes, images).
PAPER_TABLE3: dict[tuple[str, str], tuple[int, int]] = {
    ("sp", "strawberry"): (86, 24_510),
    ("mp", "strawberry"): (77, 86_856),
    ("sp", "tomato"): (130, 45_240),
    ("mp", "tomato"): (113, 203_400),
    ("sp", "vine"): (182, 63_336),
    ("mp", "vine"): (44, 79_200),
}


# Why the grids differ by crop. Section III-B gives 3 x 3 m (SP) and 7 x 3 m (MP) grids, but Table 3's
# images per scene are exact (SP strawberry 285, tomato and vine 348; MP strawberry 1,128, tomato
# and vine 1,800). On the staggered lattice of view_grid, tomato and vine fit 3 x 3 m (13 x 13
# positions, 116 kept x 3 altitudes) and 7 x 3 m with three plants 2 m apart (15 x 7, 75 kept x 24
# views). Strawberry does not: its single-plant grid is 2.5 x 2.5 m (11 x 11, 95 kept x 3), as
# the original's Fig. 2 shows (-1.25..1.25 m); no 7 x 3 m lattice leaves 47 positions around five
# plants with a 0.75 m exclusion radius, a 4 x 3 m one (9 x 7) around plants 0.3 m apart does.
# These are inferences from the counts and the figure (docs/dataset-format.md), not the paper's.
CROPS: dict[str, CropSpec] = {
    "strawberry": CropSpec(
        name="strawberry",
        title="Strawberry",
        plant_height=0.40,
        fruit_radius=0.025,
        leaf_length=0.10,
        altitudes=(0.25, 0.40, 0.55),
        min_fruit_pixels=210,
        exclusion_radius=0.75,
        centre_height=0.20,
        mp_plants=5,
        mp_spacing=0.30,
        min_fruit=4,
        helios_model="strawberry",
        age_days=90.0,
        sp_extent=(2.5, 2.5),
        mp_extent=(4.0, 3.0),
        fruit_size_per_radius=(0.5 + 0.5 + 0.55) / 3,
        primitives_per_plant=17_000,
        row=RowSpec(
            system="hill system beds",
            in_row_spacing=0.30,
            row_spacing=1.20,
            plants=10,
            standoff=0.375,
            altitudes=(0.25, 0.40, 0.55),
            source="Sunset, 'Planting strawberries': hills 12-14 in apart, rows 48 in apart "
            "(http://www.sunset.com/garden/fruits-veggies/tip-from-test-garden)",
            step=0.25,
        ),
    ),
    "tomato": CropSpec(
        name="tomato",
        title="Tomato",
        plant_height=1.00,
        fruit_radius=0.030,
        leaf_length=0.20,
        altitudes=(0.70, 1.10, 1.50),
        min_fruit_pixels=240,
        exclusion_radius=1.00,
        centre_height=0.50,
        mp_plants=3,
        mp_spacing=2.00,
        min_fruit=4,
        helios_model="tomato",
        age_days=100.0,
        primitives_per_plant=10_000,
        row=RowSpec(
            system="staked rows",
            in_row_spacing=0.50,
            row_spacing=1.50,
            plants=8,
            standoff=0.50,
            altitudes=(0.70, 1.10, 1.50),
            source="tomatocultivation.com, 'Tomato crop spacing': rows 5 ft apart, 18-24 in in the row "
            "(https://tomatocultivation.com/Tomato-Crop-Spacing.html)",
            step=0.25,
        ),
    ),
    "vine": CropSpec(
        name="vine",
        title="Vine",
        plant_height=0.70,
        fruit_radius=0.0075,
        leaf_length=0.18,
        altitudes=(0.50, 0.75, 1.00),
        min_fruit_pixels=700,
        exclusion_radius=1.00,
        centre_height=1.00,
        mp_plants=3,
        mp_spacing=2.00,
        min_fruit=4,
        helios_model="grapevine_VSP",
        age_days=95.0,
        primitives_per_plant=241_000,
        row=RowSpec(
            system="head-trained (goblet) vineyard",
            in_row_spacing=2.00,
            row_spacing=3.00,
            plants=3,
            standoff=1.00,
            altitudes=(0.50, 0.75, 1.00),
            source="vineyardpost.com: vines 1.8-2 m apart along the row, rows 3-3.5 m apart "
            "(https://vineyardpost.com/simple-overturn/)",
        ),
    ),
    **LIBRARY_CROPS,
}

#: Visible pixels (at 1280x720) from which Helios's Synthetic Annotation plug-in, which labelled
#: the original, boxes a fruit: its ``labelminpixels``, fixed at 10 in ``render()``. The paper then
#: dropped boxes below ``min_fruit_pixels`` (section III-C). Its Fig. 2 counts "visible
#: strawberries" at positions up to 1.8 m from the plant, where a whole Table 1 strawberry (2.5 cm
#: wide) covers about 110 pixels, so those counts cannot be of 210-pixel boxes: we read them as
#: the plug-in's boxes, of at least this many pixels (our inference, not the paper's words).
SEEABLE_FRUIT_PIXELS = 10

#: Strawberry camera altitudes, m. The paper disagrees with itself: Table 1 gives 25/40/55 cm (our
#: default), the Fig. 2 caption and the dataset's README 0.50/0.75/1.00 m.
STRAWBERRY_ALTITUDES: dict[str, tuple[float, float, float]] = {
    "table1": (0.25, 0.40, 0.55),
    "readme": (0.50, 0.75, 1.00),
}


def with_strawberry_altitudes(crop: CropSpec, choice: str) -> CropSpec:
    """The crop with the chosen strawberry altitudes; other crops come back unchanged.

    Args:
        crop: Any crop.
        choice: A key of :data:`STRAWBERRY_ALTITUDES` (``table1`` or ``readme``).

    Returns:
        The crop, its altitudes replaced when it is the strawberry.

    Raises:
        UserError: for an unknown choice.
    """
    if choice not in STRAWBERRY_ALTITUDES:
        raise UserError(
            f"unknown strawberry altitudes {choice!r}: choose {' or '.join(STRAWBERRY_ALTITUDES)} "
            "(Table 1's 25/40/55 cm, or the README's 0.50/0.75/1.00 m)"
        )
    return replace(crop, altitudes=STRAWBERRY_ALTITUDES[choice]) if crop.name == "strawberry" else crop


#: Plant generators: ``canopy`` (the default) rebuilds Helios's Canopy Generator, which grew the
#: paper's plants (section III-A); ``architecture`` grows pyhelios3d's PlantArchitecture models,
#: bent towards the paper by recipes (the generator before 2026-11-24).
PlantGenerator = Literal["canopy", "architecture"]
PLANT_GENERATORS: tuple[str, ...] = get_args(PlantGenerator)
DEFAULT_PLANTS: Final = "canopy"


#: What scene.json records as the plant generator of a plant-library crop's scene: its plants
#: grow from the library whatever ``--plants`` says.
LIBRARY_PLANTS = "library"


def regrowing_plants(recorded: str | None) -> str:
    """The ``plants`` setting that grows a scene again as scene.json records it was grown.

    Args:
        recorded: Its ``plant_generator``: ``canopy``, ``architecture``, ``library`` or none
            (scenes from before the choice, grown with PlantArchitecture).

    Raises:
        UserError: for an unknown generator.
    """
    if recorded == LIBRARY_PLANTS:
        return DEFAULT_PLANTS  # not read: a plant-library crop grows from the library
    return check_plants(recorded or "architecture")


def check_plants(name: str) -> str:
    """The plant generator's name, checked.

    Raises:
        UserError: for an unknown generator.
    """
    if name not in PLANT_GENERATORS:
        raise UserError(f"unknown plant generator {name!r}: choose {' or '.join(PLANT_GENERATORS)}")
    return name


#: Relative spread of the phenotype around Table 1, uniform (section III-A).
PHENOTYPE_SPREAD: dict[str, float] = {"plant_height": 0.15, "fruit_radius": 0.20, "leaf_length": 0.20}


@dataclass(frozen=True)
class ScenarioSpec:
    """One scenario's Table 2 settings.

    Attributes:
        name: ``sp`` (single plant) or ``mp`` (multi plant).
        title: Prefix of published folder names (``Single``, ``Multi``).
        extent: Grid size along x and y, m: the lattice's first and last positions along each
            axis (odd rows reach half a step further along +x; view_grid).
        step: Distance between neighbouring grid positions, m.
        altitude_levels: Which of the crop's three altitudes are used (indices, low to high).
        headings: Camera headings per position (1 means: always aimed at the plant).
        actions: The pointer keys every view carries.
        tau: Steps per episode in the benchmark (section V-D).

    The ``row`` scenario is ours: a crop's commercial row (:class:`RowSpec`), cameras in its alleys
    with MP's headings, actions and tau; its extent and step come from the crop's row.
    """

    name: str
    title: str
    extent: tuple[float, float]
    step: float
    altitude_levels: tuple[int, ...]
    headings: int
    actions: tuple[str, ...]
    tau: int


SCENARIOS: dict[str, ScenarioSpec] = {
    "sp": ScenarioSpec(
        name="sp",
        title="Single",
        extent=(3.0, 3.0),
        step=0.25,
        altitude_levels=(0, 1, 2),
        headings=1,
        actions=SP_ACTIONS,
        tau=3,
    ),
    "mp": ScenarioSpec(
        name="mp",
        title="Multi",
        extent=(7.0, 3.0),
        step=0.50,
        altitude_levels=(0, 2),
        headings=12,
        actions=MP_ACTIONS,
        tau=5,
    ),
    "row": ScenarioSpec(
        name="row",
        title="Row",
        extent=(7.0, 3.0),
        step=0.50,
        altitude_levels=(0, 2),
        headings=12,
        actions=MP_ACTIONS,
        tau=5,
    ),
}

#: Standard deviation of the Gaussian "slip" added to each camera x and y (section III-B), m.
SLIP_SIGMA = 0.025

#: Value of a segmentation pixel that shows no fruit in the published layout's uint8 masks (scenes
#: of at most 255 fruit); 16-bit masks use 65535. The rule is :mod:`davis_ag.formats.masks`'s.
NO_FRUIT = 255
#: The most fruit a scene holds: ids 0..65534 of a 16-bit mask (:mod:`davis_ag.formats.masks`).
MAX_FRUIT = 65535


#: Other names a crop is known by on the command line.
CROP_ALIASES = {
    "grape": "vine",
    "goblet": "vine",
    "goblet_vine": "vine",
    "apple_wall": "apple-wall",
    "apple_fruitingwall": "apple-wall",
    "pepper": "capsicum",
    "sweet-pepper": "capsicum",
    "cherrytomato": "cherry-tomato",
    "cherry_tomato": "cherry-tomato",
    "grapevine_vsp": "vsp-vine",
    "vsp_vine": "vsp-vine",
    "grapevine_wye": "wye-vine",
    "wye_vine": "wye-vine",
}


def crop_spec(name: str) -> CropSpec:
    """Look a crop up by name.

    Args:
        name: One of :data:`CROPS` (``grape`` and ``goblet`` are accepted for ``vine``, and
            the library models' own names, e.g. ``apple_fruitingwall``, for theirs).

    Returns:
        The crop's spec (:class:`CropSpec`).

    Raises:
        UserError: for any other name.
    """
    key = CROP_ALIASES.get(name.lower(), name.lower())
    if key not in CROPS:
        raise UserError(f"unknown crop {name!r}: choose one of {', '.join(CROPS)}")
    return CROPS[key]


def scenario_spec(name: str, crop: CropSpec | None = None) -> ScenarioSpec:
    """Look a scenario up by name (``sp``/``single``, ``mp``/``multi`` or ``row``).

    Args:
        name: The scenario's name.
        crop: When given, the grid is that crop's (``sp_extent`` / ``mp_extent``, which give
            Table 3's images per scene, or its row's extent and step); without it, section
            III-B's nominal 3 x 3 m / 7 x 3 m (the row's: MP's).

    Returns:
        The scenario's spec (:class:`ScenarioSpec`).

    Raises:
        UserError: for any other name, or ``row`` for a crop without a row.
    """
    key = {"single": "sp", "multi": "mp"}.get(name.lower(), name.lower())
    if key not in SCENARIOS:
        raise UserError(
            f"unknown scenario {name!r}: choose sp (single plant), mp (multi plant) or row (an orchard row)"
        )
    scenario = SCENARIOS[key]
    if crop is None:
        return scenario
    if key == "row":
        if crop.row is None:
            raise UserError(f"{crop.name} has no row scenario: choose sp or mp")
        return replace(scenario, extent=crop.row.extent, step=crop.row.step)
    return replace(
        scenario, extent=crop.sp_extent if key == "sp" else crop.mp_extent, step=scenario.step * crop.grid_scale
    )


def camera_altitudes(scenario: ScenarioSpec, crop: CropSpec) -> list[float]:
    """The camera heights of a scenario's altitude levels, m: the crop's (Table 1), or its row's."""
    heights = crop.row.altitudes if scenario.name == "row" and crop.row is not None else crop.altitudes
    return [heights[level] for level in scenario.altitude_levels]


def group_name(scenario: ScenarioSpec, crop: CropSpec) -> str:
    """The published folder name of a scenario and crop, e.g. ``Single-Strawberry``."""
    return f"{scenario.title}-{crop.title}"


def scene_folder(scenario: ScenarioSpec, crop: CropSpec, index: int) -> str:
    """The published folder of a scene below the dataset root, e.g. ``Single-Strawberry/003``."""
    return f"{group_name(scenario, crop)}/{index:03d}"


def parse_group_name(name: str) -> tuple[ScenarioSpec, CropSpec] | None:
    """Invert :func:`group_name`; ``None`` for a folder that is not a DAVIS-Ag group."""
    scenario_title, _, crop_title = name.partition("-")
    scenarios = {s.title: s for s in SCENARIOS.values()}
    crops = {c.title: c for c in CROPS.values()}
    if scenario_title in scenarios and crop_title in crops:
        return scenarios[scenario_title], crops[crop_title]
    return None


def plant_positions(scenario: ScenarioSpec, crop: CropSpec) -> list[tuple[float, float]]:
    """Stem positions (x, y): the origin for a single plant, a row along x centred on it for
    multi plant, the crop's row and its two neighbours for ``row`` (:meth:`RowSpec.stems`)."""
    if scenario.name == "row":
        if crop.row is None:
            raise UserError(f"{crop.name} has no row scenario: choose sp or mp")
        return crop.row.stems()
    count = 1 if scenario.name == "sp" else crop.mp_plants
    offset = (count - 1) / 2
    return [((i - offset) * crop.mp_spacing, 0.0) for i in range(count)]


def plant_centres(scenario: ScenarioSpec, crop: CropSpec) -> list[tuple[float, float, float]]:
    """Nominal plant centres: what cameras aim at and keep away from."""
    return [(x, y, crop.centre_height) for x, y in plant_positions(scenario, crop)]

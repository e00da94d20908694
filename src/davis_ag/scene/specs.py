"""What a DAVIS-Ag scene is made of: the paper's crop (Table 1) and scenario (Table 2) settings.

Everything here is plain data. Lengths are metres, angles degrees.
"""

from __future__ import annotations

from dataclasses import dataclass, replace

from davis_ag.errors import UserError

#: Actions of the single-plant scenario, in the order the environment numbers them.
SP_ACTIONS: tuple[str, ...] = ("forward", "backward", "left", "right", "up", "down")
#: Multi-plant adds the two rotations of 30 degrees.
MP_ACTIONS: tuple[str, ...] = SP_ACTIONS + ("rotate_cw", "rotate_ccw")
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


#: The paper's image size (section III-C), at which the crops' box thresholds are given.
PAPER_IMAGE_SIZE = (1280, 720)
PAPER_PIXELS = PAPER_IMAGE_SIZE[0] * PAPER_IMAGE_SIZE[1]
#: Table 3 of the paper: (scenario, crop) -> (scenes, images).
PAPER_TABLE3: dict[tuple[str, str], tuple[int, int]] = {
    ("sp", "strawberry"): (86, 24_510),
    ("mp", "strawberry"): (77, 86_856),
    ("sp", "tomato"): (130, 45_240),
    ("mp", "tomato"): (113, 203_400),
    ("sp", "vine"): (182, 63_336),
    ("mp", "vine"): (44, 79_200),
}


@dataclass(frozen=True)
class CropSpec:
    """One crop's Table 1 defaults and the settings that follow from them.

    Attributes:
        name: Short name used on the command line (``strawberry``, ``tomato``, ``vine``).
        title: Capitalised name in published folder names (``Strawberry``...).
        plant_height: Plant height, or trunk height for the vine (Table 1), m.
        fruit_radius: Fruit radius, or single-berry radius for the vine (Table 1), m: the Canopy
            Generator's ``fruit_radius`` parameter, whose defaults Table 1 lists.
        fruit_size_per_radius: Half the mean principal extent of a fruit body (what
            :mod:`davis_ag.scene.plants` measures) per unit of ``fruit_radius``, as the Canopy
            Generator builds it. Its tomato fruit and grape berries are spheres of that radius
            (1.0); its strawberry is a tube whose widest radius is half ``fruit_radius`` and whose
            length is 1.1 ``fruit_radius``, so (0.5 + 0.5 + 0.55) / 3 (``strawberry.cpp`` of
            Helios's canopygenerator plug-in): Table 1's 2.5 cm makes a strawberry 2.5 cm wide.
        leaf_length: Leaf length (Table 1), m.
        altitudes: The three camera altitudes, low to high (Table 1), m.
        min_fruit_pixels: Visible pixels a fruit needs to get a box (section III-C), at the paper's
            1280x720 (:meth:`min_fruit_pixels_at` scales it to another size).
        exclusion_radius: Cameras at most this far from a plant's stem, measured horizontally,
            are not placed, m (section III-C: "<75cm for strawberry and <100cm for others").
        centre_height: Height of the plant's centre, which single-plant cameras aim at: half
            the plant, or the middle of the vine's canopy, m.
        mp_plants: Plants in the multi-plant row.
        mp_spacing: Distance between neighbouring plants in the multi-plant row, m.
        sp_extent: The single-plant grid's size along x and y, m (the comment above ``CROPS`` says why).
        mp_extent: The multi-plant grid's size along x and y, m.
        min_fruit: A plant with fewer fruit is regrown from the next seed.
        helios_model: The pyhelios3d PlantArchitecture model the plant starts from.
        age_days: Age the plant is grown to: old enough to bear fruit.
    """

    name: str
    title: str
    plant_height: float
    fruit_radius: float
    leaf_length: float
    altitudes: tuple[float, float, float]
    min_fruit_pixels: int
    exclusion_radius: float
    centre_height: float
    mp_plants: int
    mp_spacing: float
    min_fruit: int
    helios_model: str
    age_days: float
    sp_extent: tuple[float, float] = (3.0, 3.0)
    mp_extent: tuple[float, float] = (7.0, 3.0)
    fruit_size_per_radius: float = 1.0

    def min_fruit_pixels_at(self, width: int, height: int) -> int:
        """The box threshold at an image size: :attr:`min_fruit_pixels` scaled by the image area
        over the paper's 1280x720, at least 1 pixel."""
        return max(1, round(self.min_fruit_pixels * width * height / PAPER_PIXELS))


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
    ),
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
PLANT_GENERATORS: tuple[str, ...] = ("canopy", "architecture")
DEFAULT_PLANTS = "canopy"


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
}

#: Standard deviation of the Gaussian "slip" added to each camera x and y (section III-B), m.
SLIP_SIGMA = 0.025

#: Value of a segmentation pixel that shows no fruit (the published layout's uint8 masks).
NO_FRUIT = 255
#: Fruit ids are uint8 values below NO_FRUIT, so a scene holds at most this many fruit.
MAX_FRUIT = NO_FRUIT


def crop_spec(name: str) -> CropSpec:
    """Look a crop up by name.

    Args:
        name: ``strawberry``, ``tomato`` or ``vine`` (``grape`` and ``goblet`` are accepted too).

    Returns:
        Its :class:`CropSpec`.

    Raises:
        UserError: for any other name.
    """
    key = {"grape": "vine", "goblet": "vine", "goblet_vine": "vine"}.get(name.lower(), name.lower())
    if key not in CROPS:
        raise UserError(f"unknown crop {name!r}: choose one of {', '.join(CROPS)}")
    return CROPS[key]


def scenario_spec(name: str, crop: CropSpec | None = None) -> ScenarioSpec:
    """Look a scenario up by name (``sp``/``single`` or ``mp``/``multi``).

    Args:
        name: The scenario's name.
        crop: When given, the grid is that crop's (``sp_extent`` / ``mp_extent``), which gives
            Table 3's images per scene; without it, section III-B's nominal 3 x 3 m / 7 x 3 m.

    Returns:
        Its :class:`ScenarioSpec`.

    Raises:
        UserError: for any other name.
    """
    key = {"single": "sp", "multi": "mp"}.get(name.lower(), name.lower())
    if key not in SCENARIOS:
        raise UserError(f"unknown scenario {name!r}: choose sp (single plant) or mp (multi plant)")
    scenario = SCENARIOS[key]
    if crop is None:
        return scenario
    return replace(scenario, extent=crop.sp_extent if key == "sp" else crop.mp_extent)


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
    """Stem positions (x, y): the origin for a single plant, else a row along x centred on it."""
    count = 1 if scenario.name == "sp" else crop.mp_plants
    offset = (count - 1) / 2
    return [((i - offset) * crop.mp_spacing, 0.0) for i in range(count)]


def plant_centres(scenario: ScenarioSpec, crop: CropSpec) -> list[tuple[float, float, float]]:
    """Nominal plant centres: what cameras aim at and keep away from."""
    return [(x, y, crop.centre_height) for x, y in plant_positions(scenario, crop)]

"""The crops grown from Helios's plant library (PlantArchitecture): what each is and how it is grown.

The paper's three crops come from Helios's Canopy Generator (Table 1). The crops here come from
pyhelios3d's plant library as its models grow, to the day their fruit are ripe on the plant:
the library's phenology decides when fruit set and ripen, so each :class:`LibraryRecipe` names the
age at which the model's fruit are at full size with its leaves still on, and the few shoot
parameters changed where the model's fruit load falls short of the crop's
(docs/crops.md gives the literature and the measurements behind every number).

Grids: a library crop's single-plant and multi-plant grids are the tomato's (Table 1 and 2: a
1 m plant, 3 x 3 m and 7 x 3 m grids, 25 and 50 cm steps, cameras at 0.7/1.1/1.5 m, 1 m
exclusion) scaled by the plant's height over the tomato's (:func:`scaled_crop`), so every crop
has the tomato's 348 SP and 1,800 MP views a scene. Box thresholds scale the tomato's 240 pixels
by the fruit's projected area at that distance. The ``row`` scenario uses the crop's commercial
row (:class:`~davis_ag.scene.crop_spec.RowSpec`).

Lengths are metres.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from davis_ag.scene.crop_spec import CropSpec, RowSpec

#: The tomato's Table 1 and 2 grid, which the library crops' grids scale: plant height, camera
#: altitudes, exclusion radius, box threshold and fruit radius (m, pixels).
TOMATO_HEIGHT = 1.0
TOMATO_ALTITUDES = (0.70, 1.10, 1.50)
TOMATO_EXCLUSION = 1.0
TOMATO_MIN_PIXELS = 240
TOMATO_FRUIT_RADIUS = 0.030
#: A box needs at least Helios's own labelling threshold (``specs.SEEABLE_FRUIT_PIXELS``).
MIN_BOX_PIXELS = 10


@dataclass(frozen=True)
class LibraryRecipe:
    """How one crop is grown from the plant library.

    Attributes:
        model: The library model (``PlantArchitecture.getAvailablePlantModels``).
        age_days: Age the plant is built at (``buildPlantInstanceFromLibrary``): its fruit at full
            size with its leaves on (the library's phenology: docs/crops.md).
        shoot_changes: ``(shoot type or "*", dotted parameter path, value)``: shoot parameters set
            before every build where the model's fruit load or fruit differ from the crop's (a
            ``value`` is a RandomParameter spec ``{"distribution", "parameters"}`` or a number).
        fruit_scale: Factor on every shoot type's ``fruit_prototype_scale`` (fruit size is linear in
            it), where the model's fruit are larger or smaller than the crop's.
        build_parameters: The model's build parameters (e.g. a vine's ``vine_spacing``), or none.
        woody_shoots: Shoot types whose internodes are wood (organ class ``trunk``); ``("*",)``:
            every internode (the trees, whose shoots are all barked).
        fruit_range: Fewest and most fruit a plant may bear; a plant outside is grown again from
            the next seed.
        primitives: Primitives of a typical plant (measured), for the scene-size check.
        yaw_deg: Turn of the built plant about its stem, degrees counter-clockwise: the library
            trains its fruiting wall and its grapevines' cordons along y, where our rows run along x.
    """

    model: str
    age_days: float
    shoot_changes: tuple[tuple[str, str, Any], ...]
    woody_shoots: tuple[str, ...]
    fruit_range: tuple[int, int]
    primitives: int
    fruit_scale: float = 1.0
    build_parameters: dict[str, float] | None = None
    yaw_deg: float = 0.0


def scaled_crop(
    name: str,
    title: str,
    recipe: LibraryRecipe,
    plant_height: float,
    fruit_radius: float,
    leaf_length: float,
    row: RowSpec,
) -> CropSpec:
    """A library crop's settings: the tomato's grids scaled to its plant (the module docstring).

    Args:
        name, title: Its command-line name and published folder title.
        recipe: How it grows.
        plant_height, fruit_radius, leaf_length: The nominal plant as the recipe grows it
            (measured), m: the scale of its grids and the centre of its variation.
        row: Its commercial row.

    Returns:
        The crop's :class:`CropSpec`.
    """
    scale = round(plant_height / TOMATO_HEIGHT, 2)
    low, middle, high = TOMATO_ALTITUDES
    fruit_area = (fruit_radius / TOMATO_FRUIT_RADIUS) ** 2 / scale**2
    return CropSpec(
        name=name,
        title=title,
        plant_height=plant_height,
        fruit_radius=fruit_radius,
        leaf_length=leaf_length,
        altitudes=(round(low * scale, 3), round(middle * scale, 3), round(high * scale, 3)),
        min_fruit_pixels=max(MIN_BOX_PIXELS, round(TOMATO_MIN_PIXELS * fruit_area)),
        exclusion_radius=round(TOMATO_EXCLUSION * scale, 3),
        centre_height=round(plant_height / 2, 3),
        mp_plants=3,
        mp_spacing=round(2.0 * scale, 3),
        min_fruit=recipe.fruit_range[0],
        helios_model=recipe.model,
        age_days=recipe.age_days,
        sp_extent=(3.0 * scale, 3.0 * scale),
        mp_extent=(7.0 * scale, 3.0 * scale),
        row=row,
        primitives_per_plant=recipe.primitives,
        grid_scale=scale,
        source="library",
    )


def _constant(value: float) -> dict[str, Any]:
    """A RandomParameter spec of one value."""
    return {"distribution": "constant", "parameters": [float(value)]}


def _one_fruit_per_bud(shoots: tuple[str, ...], fruit_set: float) -> tuple[tuple[str, str, Any], ...]:
    """Shoot changes that thin an apple's flower clusters to one fruit per bud, set with ``fruit_set``
    (the library's spur clusters set several apples at one point, inside each other)."""
    return tuple(
        change
        for shoot in shoots
        for change in (
            (shoot, "max_terminal_floral_buds", _constant(1)),
            (shoot, "phytomer_parameters.internode.max_floral_buds_per_petiole", _constant(1)),
            (shoot, "fruit_set_probability", _constant(fruit_set)),
        )
    )


#: The harvest day of the nut and olive trees: the library builds them dormant, breaks dormancy
#: at day 90 (almond) or 165, sets fruit 7-10 days later, grows them to full size in 20 more and
#: makes the tree dormant (fruit dropped) at day 365 of each cycle; in the second season the fruit
#: are full size from about day 490 (almond) or 570 to about day 730, so day 680 lies in the middle.
TREE_HARVEST_DAY = 680.0
#: The grapevines' clusters are full size from about day 140 to 360 (dormancy at 365).
VINE_HARVEST_DAY = 180.0
#: Inflorescence parameters, by dotted path.
FLOWERS_PER_PEDUNCLE = "phytomer_parameters.inflorescence.flowers_per_peduncle"
FRUIT_PROTOTYPE_SCALE = "phytomer_parameters.inflorescence.fruit_prototype_scale"

#: Every plant-library crop's recipe, by command-line name (docs/crops.md says why each change).
LIBRARY_RECIPES: dict[str, LibraryRecipe] = {
    # The third leaf: dormant until day 895, fruit full size from about day 945 to dormancy at 1095.
    # One fruit per bud: the library's spur clusters set several apples at one point, a quarter to
    # two fifths of them interpenetrating a neighbour.
    "apple": LibraryRecipe(
        "apple",
        1000.0,
        _one_fruit_per_bud(("proleptic", "spur"), 0.4),
        ("*",),
        (10, 250),
        135_000,
    ),
    # The wall fruits in its second season only (max age 730 days): full-size fruit from about day
    # 570; thinned to single fruit per bud (the library sets clusters of 5-6 interpenetrating apples).
    "apple-wall": LibraryRecipe(
        "apple_fruitingwall",
        650.0,
        _one_fruit_per_bud(("lateral", "proleptic", "spur"), 0.8),
        ("*",),
        (10, 250),
        73_000,
        yaw_deg=90.0,
    ),
    "almond": LibraryRecipe("almond", TREE_HARVEST_DAY, (), ("*",), (10, 250), 36_000),
    # The library sets 10 olives per fruiting inflorescence; olives set 1-2 (Lavee et al. 1996).
    "olive": LibraryRecipe(
        "olive",
        TREE_HARVEST_DAY,
        tuple((shoot, FLOWERS_PER_PEDUNCLE, _constant(2)) for shoot in ("proleptic", "scaffold")),
        ("*",),
        (10, 250),
        27_000,
    ),
    # A young tree's light crop: half the clusters, 10 nuts each; the library's nuts are 1.5-2x
    # the literature's length.
    "pistachio": LibraryRecipe(
        "pistachio",
        TREE_HARVEST_DAY,
        tuple(
            change
            for shoot in ("proleptic", "scaffold", "spur")
            for change in (
                (shoot, FLOWERS_PER_PEDUNCLE, _constant(10)),
                (shoot, "flower_bud_break_probability", _constant(0.175)),
            )
        ),
        ("*",),
        (10, 250),
        40_000,
        fruit_scale=0.65,
    ),
    # The library's walnut in its husk is 8.6 cm long; a husked walnut is about 5 cm.
    "walnut": LibraryRecipe("walnut", TREE_HARVEST_DAY, (), ("*",), (10, 250), 37_000, fruit_scale=0.6),
    # Fruit on the main stem only (as a stem-trained greenhouse crop carries them), set more often;
    # the library's fruit are 133 mm long, a large bell pepper 100 mm.
    "capsicum": LibraryRecipe(
        "capsicum",
        260.0,
        (
            ("mainstem", "fruit_set_probability", _constant(0.42)),
            ("secondary", "flower_bud_break_probability", _constant(0.0)),
        ),
        (),
        (3, 20),
        27_000,
        fruit_scale=0.75,
    ),
    # Cherry-tomato fruit (the library's are a salad tomato's 5.9 cm) in trusses of 12.
    "cherry-tomato": LibraryRecipe(
        "cherrytomato",
        160.0,
        (
            ("mainstem", FRUIT_PROTOTYPE_SCALE, _constant(0.045)),
            ("mainstem", FLOWERS_PER_PEDUNCLE, _constant(12)),
        ),
        (),
        (10, 250),
        260_000,
    ),
    "vsp-vine": LibraryRecipe(
        "grapevine_VSP",
        VINE_HARVEST_DAY,
        (),
        ("grapevine_trunk", "grapevine_cane"),
        (10, 250),
        318_000,
        build_parameters={"vine_spacing": 1.8},
        yaw_deg=90.0,
    ),
    # 60 berries of 13.7 mm a cluster instead of about 90 of 12 mm (the same cluster volume): a
    # Wye vine is 0.9 million primitives, 82 % of them berries, and its row would not fit 24 GB.
    "wye-vine": LibraryRecipe(
        "grapevine_Wye",
        VINE_HARVEST_DAY,
        (),
        ("grapevine_trunk", "grapevine_cordon"),
        (10, 250),
        575_000,
        build_parameters={"vine_spacing": 1.8, "cluster_berry_count": 60, "berry_diameter": 0.0137},
        yaw_deg=90.0,
    ),
}


UC_PISTACHIO = "http://fruitsandnuts.ucdavis.edu/pistachiopages/pistachio_orchard_management/"
SILVERCREEK = "silvercreekvineyards.com, 'Trellis choice' (https://silvercreekvineyards.com/trellis-choice)"

#: The plant-library crops, by command-line name (appended to ``specs.CROPS``): nominal plant as
#: measured (height, fruit radius, leaf length; docs/crops.md) and the crop's commercial row.
LIBRARY_CROPS: dict[str, CropSpec] = {
    "apple": scaled_crop(
        "apple",
        "Apple",
        LIBRARY_RECIPES["apple"],
        3.61,
        0.04,
        0.09,
        RowSpec(
            "free-standing central-leader orchard",
            3.7,
            5.5,
            1,
            2.0,
            (0.9, 1.8, 2.7),
            "central leaders on semi-dwarf rootstock at 200 trees/acre (Robinson et al., "
            "https://studylib.net/doc/8900291/a-vision-for-apple-orchard-systems-of-the-future): 12 x 18 ft",
        ),
    ),
    "apple-wall": scaled_crop(
        "apple-wall",
        "AppleWall",
        LIBRARY_RECIPES["apple-wall"],
        3.8,
        0.04,
        0.09,
        RowSpec(
            "tall spindle fruiting wall",
            1.2,
            3.5,
            5,
            1.0,
            (0.9, 1.6, 2.3),
            "tall spindle: 3-4 ft in the row, rows 11-12 ft (http://www.goodfruit.com/horticulturist-favors-tall-spindle/)",
        ),
    ),
    "almond": scaled_crop(
        "almond",
        "Almond",
        LIBRARY_RECIPES["almond"],
        2.66,
        0.0165,
        0.09,
        RowSpec(
            "orchard",
            5.0,
            6.5,
            1,
            1.5,
            (0.8, 1.6, 2.4),
            "rows 21-22 ft (https://thealmonddoctor.com/almond-orchard-row-width/), trees 10-22 ft apart "
            "(https://www.wcngg.com/2021/06/09/orchard-spacing-considerations-in-a-tree-nut-orchard/)",
        ),
    ),
    "olive": scaled_crop(
        "olive",
        "Olive",
        LIBRARY_RECIPES["olive"],
        1.62,
        0.012,
        0.06,
        RowSpec(
            "super-high-density hedgerow",
            1.5,
            3.75,
            4,
            1.0,
            (0.5, 1.0, 1.5),
            "rows 3.5-5 m, trees 1.2-1.8 m (https://www.vezorla.com/blogs/faq-about-olive-oil/"
            "what-does-mean-hedge-row-olive-grove; http://www.agromillora-ca.com/products/high-density-requirements/)",
        ),
    ),
    "pistachio": scaled_crop(
        "pistachio",
        "Pistachio",
        LIBRARY_RECIPES["pistachio"],
        2.26,
        0.0075,
        0.08,
        RowSpec("orchard", 5.5, 6.3, 1, 1.5, (0.7, 1.4, 2.1), f"rows 20-22 ft, trees 17-21 ft (UC, {UC_PISTACHIO})"),
    ),
    "walnut": scaled_crop(
        "walnut",
        "Walnut",
        LIBRARY_RECIPES["walnut"],
        3.07,
        0.024,
        0.1,
        RowSpec(
            "hedgerow",
            4.6,
            6.7,
            1,
            1.75,
            (0.9, 1.8, 2.7),
            "hedgerow 22 x 15 ft (UC, https://fruitsandnuts.ucdavis.edu/walnut-orchard-establishment)",
        ),
    ),
    "capsicum": scaled_crop(
        "capsicum",
        "Capsicum",
        LIBRARY_RECIPES["capsicum"],
        1.31,
        0.045,
        0.1,
        RowSpec(
            "greenhouse rows",
            0.35,
            1.8,
            8,
            0.75,
            (0.4, 0.8, 1.2),
            "1.5-3.8 plants/m2 in greenhouses (Jovicich et al. 2004, HortTechnology 14(4):507, "
            "https://journals.ashs.org/horttech/view/journals/horttech/14/4/article-p507.xml): 0.35 x 1.8 m is 1.6",
            step=0.25,
        ),
    ),
    "cherry-tomato": scaled_crop(
        "cherry-tomato",
        "CherryTomato",
        LIBRARY_RECIPES["cherry-tomato"],
        2.36,
        0.0134,
        0.2,
        RowSpec(
            "staked rows",
            0.5,
            1.5,
            6,
            0.5,
            (0.6, 1.2, 1.8),
            "rows 5 ft apart, 18-24 in in the row (https://tomatocultivation.com/Tomato-Crop-Spacing.html)",
            step=0.25,
        ),
    ),
    "vsp-vine": scaled_crop(
        "vsp-vine",
        "VSPVine",
        LIBRARY_RECIPES["vsp-vine"],
        2.01,
        0.04,
        0.15,
        RowSpec(
            "vertically shoot-positioned vineyard",
            1.8,
            3.0,
            2,
            1.0,
            (0.6, 1.0, 1.4),
            f"VSP: rows 10 ft, vines 6-8 ft ({SILVERCREEK})",
        ),
    ),
    "wye-vine": scaled_crop(
        "wye-vine",
        "WyeVine",
        LIBRARY_RECIPES["wye-vine"],
        2.81,
        0.04,
        0.15,
        RowSpec(
            "divided-canopy (Wye) vineyard",
            1.8,
            3.66,
            1,
            1.5,
            (0.8, 1.4, 2.0),
            f"divided canopies (Geneva double curtain, lyre): rows 12 ft, vines 6-8 ft ({SILVERCREEK})",
        ),
    ),
}

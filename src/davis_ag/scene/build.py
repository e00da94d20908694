"""A scene: plants grown in a Helios Context on textured soil, with its fruit numbered.

This is the scene description the renderer draws and the writer saves; every random choice is
drawn from the generator handed in.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from davis_ag.errors import UserError
from davis_ag.scene.cover import SWARD_TEXTURE, add_cover, floor_system
from davis_ag.scene.helios_threads import one_helios_thread
from davis_ag.scene.lighting import Lighting
from davis_ag.scene.organs import ORGAN_DATA
from davis_ag.scene.plants import (
    GrownPlant,
    fruit_body_uuids,
    helios_seed,
    primitive_vertices,
    require_native_helios,
    sample_phenotype,
)
from davis_ag.scene.specs import (
    DEFAULT_PLANTS,
    LIBRARY_PLANTS,
    MAX_FRUIT,
    CropSpec,
    ScenarioSpec,
    check_plants,
    plant_positions,
)
from davis_ag.scene.structures import (
    add_greenhouse_floor,
    add_structures,
    builds_something,
    greenhouse_floor,
    structure_parts,
)

if TYPE_CHECKING:  # pyhelios loads its native library: imported only where a scene is built
    from pyhelios import Context

#: Side of the square soil tile under every scene, m: wide enough to reach the horizon's haze.
GROUND_SIZE = 60.0
#: Side of the finely textured soil around the grid and the size of one of its patches, m.
NEAR_SIZE = 12.0
NEAR_PATCH = 0.12
#: Size of one texture repeat on the far soil, m.
FAR_REPEAT = 1.5


@dataclass
class Fruit:
    """One fruit (a grape cluster for the vine) with its scene-wide id.

    Attributes:
        id: Scene-wide id, 0..254: the value in segmentation images and boxes.
        plant: Index of the plant bearing it.
        uuids: Its Helios primitives: the fruit body, without calyx and stalk.
        polygons: Its primitives' vertices grouped by vertex count, arrays (n, k, 3).
        center: Centre of its bounding box (x, y, z), m.
        size: Extent of its bounding box (dx, dy, dz), m.
    """

    id: int
    plant: int
    uuids: np.ndarray
    polygons: list[np.ndarray] = field(repr=False)
    center: tuple[float, float, float]
    size: tuple[float, float, float]

    def summary(self) -> dict:
        """JSON-ready description for scene.json."""
        return {"id": self.id, "plant": self.plant, "center": list(self.center), "size": list(self.size)}


@dataclass
class SceneModel:
    """Everything that is drawn.

    Attributes:
        context: The Helios Context.
        plants: The grown plants.
        fruits: Every fruit, by id.
        lighting: Sun and sky.
        aim_height: Height single-plant cameras aim at, m.
        plant_generator: Which generator grew the plants (``canopy``, ``architecture`` or, for a
            plant-library crop, ``library``).
        structures: The structures setting that built the scene's trellis, stakes or strings
            (:mod:`davis_ag.scene.structures`); None where the scene has none.
    """

    context: Context
    plants: list[GrownPlant]
    fruits: list[Fruit]
    lighting: Lighting
    aim_height: float
    plant_generator: str = DEFAULT_PLANTS
    structures: str | None = None

    @property
    def uuid_count(self) -> int:
        """One more than the largest primitive UUID."""
        return int(max(self.context.getAllUUIDs())) + 1

    def organ_of_uuid(self) -> np.ndarray:
        """Organ class (:mod:`davis_ag.scene.organs`) of every primitive, indexed by UUID.

        Returns:
            uint8 array of length :attr:`uuid_count`; primitives without organ data read 0 (sky).
        """
        uuids = list(self.context.getAllUUIDs())
        table = np.zeros(self.uuid_count, dtype=np.uint8)
        try:  # one bulk call when every primitive is labelled, as in scenes built here
            table[np.asarray(uuids)] = np.asarray(self.context.getPrimitiveDataArray(uuids, ORGAN_DATA))
            return table
        except (RuntimeError, ValueError):
            pass
        labelled = [u for u in uuids if self.context.doesPrimitiveDataExist(u, ORGAN_DATA)]
        if labelled:
            table[np.asarray(labelled)] = np.asarray(self.context.getPrimitiveDataArray(labelled, ORGAN_DATA))
        return table


def helios_texture(name: str) -> str:
    """Path of a texture shipped with pyhelios3d's Visualizer plug-in."""
    import pyhelios

    path = Path(pyhelios.__file__).parent / "assets/build/plugins/visualizer/textures" / name
    if not path.exists():
        raise UserError(f"pyhelios3d lacks its texture {path}: reinstall pyhelios3d")
    return str(path)


def add_ground(context, soil_texture: str = "dirt.jpg") -> None:
    """Textured soil at z = 0: fine patches under the grid, a coarse ring out to the horizon.

    Every soil primitive is labelled with the organ class ``soil``. ``soil_texture`` is an image
    shipped with Helios (:func:`helios_texture`); randomised appearance picks others.

    Helios keeps textures at a low resolution, so a texture stretched over metres turns into a
    checkerboard of blocks; one texture per ``NEAR_PATCH`` patch keeps the soil's grain. The far
    field is a ring around the patches rather than one tile beneath them, which Helios would fill
    a second time in every frame and in every shadow map (20 % of a view's time).
    """
    from pyhelios.types import int2, vec2, vec3

    from davis_ag.scene.organ_labels import label_soil

    texture = helios_texture(soil_texture)
    patches = round(NEAR_SIZE / NEAR_PATCH)
    tiles = [
        context.addTileObject(
            center=vec3(0.0, 0.0, 0.0),
            size=vec2(NEAR_SIZE, NEAR_SIZE),
            subdiv=int2(patches, patches),
            texturefile=texture,
        )
    ]
    band = (GROUND_SIZE - NEAR_SIZE) / 2
    offset = (NEAR_SIZE + band) / 2
    strips = [  # (centre x, centre y, size x, size y): north, south, east, west
        (0.0, offset, GROUND_SIZE, band),
        (0.0, -offset, GROUND_SIZE, band),
        (offset, 0.0, band, NEAR_SIZE),
        (-offset, 0.0, band, NEAR_SIZE),
    ]
    for x, y, width, depth in strips:
        repeats = int2(max(1, round(width / FAR_REPEAT)), max(1, round(depth / FAR_REPEAT)))
        tiles.append(
            context.addTileObject(
                center=vec3(x, y, 0.0),
                size=vec2(width, depth),
                subdiv=int2(1, 1),
                texturefile=texture,
                texture_repeat=repeats,
            )
        )
    label_soil(context, tiles)


def _fruit(context, fruit_id: int, plant: int, body: list[int]) -> Fruit:
    uuids = np.asarray(body, dtype=np.int64)
    parts = primitive_vertices(context, list(uuids))
    by_count: dict[int, list[np.ndarray]] = {}
    for part in parts:
        by_count.setdefault(len(part), []).append(part)
    polygons = [np.stack(group).astype(np.float64) for group in by_count.values()]
    points = np.concatenate(parts)
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, size = (lo + hi) / 2, hi - lo
    return Fruit(
        fruit_id,
        plant,
        uuids,
        polygons,
        (float(centre[0]), float(centre[1]), float(centre[2])),
        (float(size[0]), float(size[1]), float(size[2])),
    )


def _grow_architecture_plants(
    context, scenario: ScenarioSpec, crop: CropSpec, rng: np.random.Generator
) -> list[GrownPlant]:
    """PlantArchitecture plants grown towards their phenotypes (``--plants architecture``)."""
    from davis_ag.scene.architecture_plants import grow_architecture_plant, load_architecture_model

    model = load_architecture_model(context, crop, rng)
    plants = []
    for index, position in enumerate(plant_positions(scenario, crop)):
        target = sample_phenotype(crop, rng)
        plants.append(grow_architecture_plant(model, index, position, target, helios_seed(rng)))
    for plant in plants:
        plant.fruit_bodies = [fruit_body_uuids(context, object_id) for object_id in plant.fruit_objects]
    return plants


def _grow_canopy_plants(context, scenario: ScenarioSpec, crop: CropSpec, rng: np.random.Generator) -> list[GrownPlant]:
    """Canopy Generator plants with the phenotypes drawn for them (``--plants canopy``)."""
    from davis_ag.scene.canopy_plants import grow_canopy_plant

    plants = []
    for index, position in enumerate(plant_positions(scenario, crop)):
        target = sample_phenotype(crop, rng)
        seed = int(rng.integers(0, 2**31 - 1))
        plants.append(grow_canopy_plant(context, crop, index, position, target, seed))
    return plants


def _grow_library_plants(context, scenario: ScenarioSpec, crop: CropSpec, rng: np.random.Generator) -> list[GrownPlant]:
    """Plant-library crops, grown as their recipes grow them (:mod:`davis_ag.scene.library_plants`)."""
    from davis_ag.scene.library_plants import grow_library_crop_plant, load_library_model

    model = load_library_model(context, crop, rng)
    return [
        grow_library_crop_plant(model, index, position, rng)
        for index, position in enumerate(plant_positions(scenario, crop))
    ]


def build_scene(
    scenario: ScenarioSpec,
    crop: CropSpec,
    rng: np.random.Generator,
    plants: str = DEFAULT_PLANTS,
    soil_texture: str = "dirt.jpg",
    structures: str = "none",
    cover_rng: np.random.Generator | None = None,
) -> SceneModel:
    """Grow a scene's plants on soil, choose the sun and number the fruit.

    Args:
        scenario: Single or multi plant.
        crop: The crop.
        rng: The scene's only source of randomness.
        plants: The plant generator of the paper's crops
            (:data:`~davis_ag.scene.specs.PLANT_GENERATORS`); a plant-library crop grows from
            the library whatever it says, recorded as ``library``.
        soil_texture: The soil's image (:func:`add_ground`).
        structures: ``none`` or ``default``: a ``row`` scene's trellis, stakes or strings
            (:mod:`davis_ag.scene.structures`), added after the plants and the soil and drawing
            nothing from ``rng``, so a scene without them is the scene as it always was; with
            them, an orchard's or vineyard's alleys grow their cover crop (:mod:`davis_ag.scene.cover`).
        cover_rng: The cover's own stream (``[scene seed, COVER_STREAM]``); needed only where a
            cover grows.

    Returns:
        The :class:`SceneModel`.
    """
    require_native_helios()
    from pyhelios import Context

    # Every growth (Canopy Generator, PlantArchitecture, plant library) runs under here.
    one_helios_thread()  # a team of threads grows up to 29x slower on a busy machine
    context = Context()
    check_plants(plants)
    if crop.source == "library":
        plants, grow = LIBRARY_PLANTS, _grow_library_plants
    else:
        grow = _grow_canopy_plants if plants == "canopy" else _grow_architecture_plants
    grown = grow(context, scenario, crop, rng)
    add_ground(context, soil_texture)
    parts = structure_parts(scenario.name, crop, structures)
    if parts:
        add_structures(context, parts)
        floor_sides = greenhouse_floor(crop)
        if floor_sides is not None:
            add_greenhouse_floor(context, floor_sides)
    floor = floor_system(scenario.name, crop, structures)
    if floor is not None and crop.row is not None:
        if cover_rng is None:
            raise ValueError("a scene with a cover crop needs its cover_rng")
        add_cover(context, crop.row, floor, cover_rng, helios_texture(SWARD_TEXTURE))

    fruits: list[Fruit] = []
    for plant in grown:
        assert plant.fruit_bodies is not None  # every grower above fills it in
        for body in plant.fruit_bodies:
            if len(fruits) >= MAX_FRUIT:
                raise UserError(
                    f"a {crop.name} scene grew more than {MAX_FRUIT} fruit, the most a 16-bit mask can label "
                    "(davis_ag.formats.masks)"
                )
            fruits.append(_fruit(context, len(fruits), plant.index, body))
    lighting = Lighting(sun_elevation=float(rng.uniform(35.0, 75.0)), sun_azimuth=float(rng.uniform(0.0, 360.0)))
    return SceneModel(
        context,
        grown,
        fruits,
        lighting,
        aim_height=crop.centre_height,
        plant_generator=plants,
        structures=structures if builds_something(scenario.name, crop, structures) else None,
    )

"""Grow the plant-library crops (:mod:`davis_ag.scene.library_crops`) in a scene's Context.

Each plant is the library model as its recipe grows it, varied as the paper varies its plants
(section III-A): its size, fruit size and leaf size by factors drawn uniformly within +-15 %,
+-20 % and +-20 % (:data:`~davis_ag.scene.specs.PHENOTYPE_SPREAD`). The size factor scales the
built plant about its stem's foot (the library's internode lengths and trunk heights do not set
a tree's height reliably, and a trunk of more than 20 nodes fails to build); the fruit and leaf
prototype scales are divided by it before the build, so fruit and leaves end at their own
factors. One build per plant: the factors are the target, and what was built is measured and
recorded beside it. A plant whose fruit load falls
outside the recipe's range is grown again from the next seed (the library's fruit set is random).

Every random choice comes from the scene's generator: the model's load seed, each plant's
factors and Helios seed. A fruit is the library's fruit object, whole (an apple, a pepper, a nut,
a grape cluster), so a scene's fruit ids are exactly its plants' ``getPlantFruitObjectIDs``.
"""

from __future__ import annotations

import copy
import time
from typing import Any

import numpy as np

from davis_ag.errors import UserError
from davis_ag.scene.library_crops import LIBRARY_RECIPES, LibraryRecipe
from davis_ag.scene.organ_labels import label_library_plant
from davis_ag.scene.plants import (
    HELIOS_SEED_RANGE,
    ArchitectureModel,
    GrownPlant,
    Phenotype,
    helios_seed,
    object_vertices,
    primitive_vertices,
    principal_extents,
    quiet_stdout,
    scale_parameter,
)
from davis_ag.scene.specs import PHENOTYPE_SPREAD, CropSpec

#: Builds a plant may take before the crop is declared unable to bear its load.
MAX_BUILDS = 12
#: Parameter paths scaled by the fruit and leaf factors.
FRUIT_SCALE = "phytomer_parameters.inflorescence.fruit_prototype_scale"
LEAF_SCALE = "phytomer_parameters.leaf.prototype_scale"


def recipe_of(crop: CropSpec) -> LibraryRecipe:
    """The recipe of a plant-library crop.

    Raises:
        UserError: for a crop that is not grown from the library.
    """
    if crop.name not in LIBRARY_RECIPES:
        raise UserError(f"{crop.name} is not grown from Helios's plant library")
    return LIBRARY_RECIPES[crop.name]


def load_library_model(context, crop: CropSpec, rng: np.random.Generator) -> ArchitectureModel:
    """Load a crop's library model into a new PlantArchitecture of ``context``, seeded first.

    Args:
        context: The scene's Helios Context.
        crop: A plant-library crop.
        rng: The scene's generator; the load's seed is a child of it (``rng.spawn``), as in
            :func:`davis_ag.scene.architecture_plants.load_architecture_model`, whose docstring
            says why the Context is seeded before the load.

    Returns:
        The loaded model, with every shoot type's parameters as the library defines them.
    """
    from pyhelios import PlantArchitecture

    recipe = recipe_of(crop)
    context.seedRandomGenerator(helios_seed(rng.spawn(1)[0]))
    plant_architecture = PlantArchitecture(context)
    plant_architecture.disableMessages()
    with quiet_stdout():
        plant_architecture.loadPlantModelFromLibrary(recipe.model)
    defaults = {
        label: plant_architecture.getCurrentShootParameters(label) for label in plant_architecture.listShootTypeLabels()
    }
    return ArchitectureModel(context, plant_architecture, crop, defaults)


def _get(params: dict, path: str) -> Any:
    node: Any = params
    for key in path.split("."):
        if not isinstance(node, dict) or key not in node:
            return None
        node = node[key]
    return node


def _set(params: dict, path: str, value: Any) -> None:
    *parents, last = path.split(".")
    node = params
    for key in parents:
        node = node[key]
    node[last] = copy.deepcopy(value)


def shoot_parameters(defaults: dict[str, dict], recipe: LibraryRecipe, factors: dict[str, float]) -> dict[str, dict]:
    """Every shoot type's parameters with the recipe's changes and a plant's factors applied.

    Args:
        defaults: The library's parameters by shoot type.
        recipe: The crop's recipe.
        factors: ``size``, ``fruit`` and ``leaf`` factors (1 for the nominal plant); fruit and
            leaves are divided by ``size``, which scales the whole plant after the build.

    Returns:
        New parameters by shoot type (``defaults`` is left as it is).

    Raises:
        ValueError: for a recipe change no shoot type of the model has (a misspelt path would
            otherwise change nothing, silently).
    """
    scales = {
        FRUIT_SCALE: recipe.fruit_scale * factors["fruit"] / factors["size"],
        LEAF_SCALE: factors["leaf"] / factors["size"],
    }
    shoots = {}
    applied = set()
    for label, params in defaults.items():
        params = copy.deepcopy(params)
        for change in recipe.shoot_changes:
            shoot, path, value = change
            if shoot in ("*", label) and _get(params, path) is not None:
                _set(params, path, value)
                applied.add(change[:2])

        for path, factor in scales.items():
            spec = _get(params, path)
            if isinstance(spec, dict) and spec.get("distribution") in ("constant", "uniform", "normal"):
                scale_parameter(spec, factor)
        shoots[label] = params
    if missing := [change[:2] for change in recipe.shoot_changes if change[:2] not in applied]:
        raise ValueError(f"{recipe.model}: no shoot type has {missing[0][1]!r} for the change on {missing[0][0]!r}")
    return shoots


def place_plant(
    context, plant_architecture, plant_id: int, position: tuple[float, float], factor: float, yaw_deg: float
) -> None:
    """Scale a built plant about its stem's foot and turn it about its stem. Its organs are compound
    objects, which Helios moves only as objects; a primitive outside them is moved alone."""
    from pyhelios.types import vec3

    if factor == 1.0 and yaw_deg == 0.0:
        return
    foot = vec3(position[0], position[1], 0.0)
    objects = list(plant_architecture.getAllPlantObjectIDs(plant_id))
    in_objects = set(context.getObjectPrimitiveUUIDs(objects)) if objects else set()
    loose = [u for u in plant_architecture.getAllPlantUUIDs(plant_id) if u not in in_objects]
    if factor != 1.0:
        scale = vec3(factor, factor, factor)
        if objects:
            context.scaleObject(objects, scale, point=foot)
        if loose:
            context.scalePrimitive(loose, scale, foot)
    if yaw_deg != 0.0:
        up, angle = vec3(0.0, 0.0, 1.0), float(np.radians(yaw_deg))
        if objects:
            context.rotateObject(objects, angle, up, origin=foot)
        if loose:
            context.rotatePrimitive(loose, angle, up, origin=foot)


def draw_factors(rng: np.random.Generator) -> dict[str, float]:
    """A plant's size, fruit and leaf factors, uniform within the paper's spread (section III-A)."""
    return {
        "size": float(1.0 + rng.uniform(-1, 1) * PHENOTYPE_SPREAD["plant_height"]),
        "fruit": float(1.0 + rng.uniform(-1, 1) * PHENOTYPE_SPREAD["fruit_radius"]),
        "leaf": float(1.0 + rng.uniform(-1, 1) * PHENOTYPE_SPREAD["leaf_length"]),
    }


def measure_library_plant(context, plant_architecture, plant_id: int) -> dict[str, float]:
    """Height, crown width (x, y), fruit length and width (the median over fruit of their largest
    and middle extents along their principal axes) and median leaf length of a built plant, m."""
    parts = primitive_vertices(context, plant_architecture.getAllPlantUUIDs(plant_id))
    points = np.concatenate(parts)
    lo, hi = points.min(axis=0), points.max(axis=0)
    sizes = []  # per fruit, its extents along its principal axes, largest first
    for fruit in plant_architecture.getPlantFruitObjectIDs(plant_id):
        vertices = object_vertices(context, int(fruit))
        if len(vertices) > 3:
            sizes.append(principal_extents(vertices))
    leaves = []
    for leaf in plant_architecture.getPlantLeafObjectIDs(plant_id):
        vertices = object_vertices(context, int(leaf))
        if len(vertices):
            leaves.append(float(np.max(vertices.max(axis=0) - vertices.min(axis=0))))
    return {
        "plant_height": float(hi[2]),
        "width_x": float(hi[0] - lo[0]),
        "width_y": float(hi[1] - lo[1]),
        "fruit_length": float(np.median([e[0] for e in sizes])) if sizes else float("nan"),
        "fruit_diameter": float(np.median([e[1] for e in sizes])) if sizes else float("nan"),
        "leaf_length": float(np.median(leaves)) if leaves else float("nan"),
    }


def grow_library_crop_plant(
    model: ArchitectureModel, index: int, position: tuple[float, float], rng: np.random.Generator
) -> GrownPlant:
    """Grow one plant of a library crop with its own factors and seed, drawn from ``rng``.

    Args:
        model: What :func:`load_library_model` returned.
        index: The plant's index in the scene.
        position: Its stem (x, y), m.
        rng: The scene's generator.

    Returns:
        The grown plant, left in the context, every primitive labelled with its organ class.

    Raises:
        UserError: when no seed gives a fruit load in the recipe's range in :data:`MAX_BUILDS` builds.
    """
    from pyhelios.types import vec3

    context, plant_architecture, crop = model.context, model.plant_architecture, model.crop
    recipe = recipe_of(crop)
    factors = draw_factors(rng)
    seed = helios_seed(rng)
    for label, params in shoot_parameters(model.shoot_defaults, recipe, factors).items():
        plant_architecture.defineShootType(label, params)
    started = time.perf_counter()
    low, high = recipe.fruit_range
    for builds in range(1, MAX_BUILDS + 1):
        context.seedRandomGenerator(seed)
        with quiet_stdout():
            plant_id = plant_architecture.buildPlantInstanceFromLibrary(
                vec3(position[0], position[1], 0.0), recipe.age_days, build_parameters=recipe.build_parameters
            )
        fruit = [int(f) for f in plant_architecture.getPlantFruitObjectIDs(plant_id)]
        if low <= len(fruit) <= high:
            break
        plant_architecture.deletePlantInstance(plant_id)
        seed = seed + 1 if seed < HELIOS_SEED_RANGE[1] else HELIOS_SEED_RANGE[0]
    else:
        raise UserError(
            f"{crop.name}: no plant with {low}-{high} fruit in {MAX_BUILDS} builds from Helios's "
            f"{recipe.model} model at {recipe.age_days:g} days"
        )
    place_plant(context, plant_architecture, plant_id, position, factors["size"], recipe.yaw_deg)
    label_library_plant(context, plant_architecture, plant_id, recipe.woody_shoots)
    measured = measure_library_plant(context, plant_architecture, plant_id)
    target = Phenotype(
        plant_height=crop.plant_height * factors["size"],
        fruit_radius=crop.fruit_radius * factors["fruit"],
        leaf_length=crop.leaf_length * factors["leaf"],
    )
    return GrownPlant(
        index,
        seed,
        position,
        target,
        Phenotype(measured["plant_height"], measured["fruit_diameter"] / 2, measured["leaf_length"]),
        fruit,
        [int(u) for u in plant_architecture.getAllPlantUUIDs(plant_id)],
        builds,
        fruit_bodies=[[int(u) for u in context.getObjectPrimitiveUUIDs(f)] for f in fruit],
        build_s=time.perf_counter() - started,
        library={
            "model": recipe.model,
            "age_days": recipe.age_days,
            "shoot_changes": [list(change) for change in recipe.shoot_changes],
            "fruit_scale": recipe.fruit_scale,
            "build_parameters": recipe.build_parameters,
            "yaw_deg": recipe.yaw_deg,
            "factors": factors,
            "width_m": [measured["width_x"], measured["width_y"]],
            "fruit_length_m": measured["fruit_length"],
            "fruit_diameter_m": measured["fruit_diameter"],
        },
    )

"""PlantArchitecture plants (``--plants architecture``): a crop's model loaded into a scene's
Context, and its plants grown towards their phenotypes.

Strawberry and tomato come from pyhelios3d's plant library (:func:`grow_library_plant`), the
goblet vine is composed from its grapevine shoot types (:mod:`davis_ag.scene.goblet_vine`);
:func:`grow_architecture_plant` picks the one for the model's crop.
"""

from __future__ import annotations

from davis_ag.scene.goblet_vine import grow_goblet_vine, load_vine_model
from davis_ag.scene.plants import (
    ArchitectureModel,
    GrownPlant,
    Phenotype,
    blades_per_leaf,
    grow_to_target,
    lift_to_ground,
    prepare_build,
    quiet_stdout,
)
from davis_ag.scene.specs import CropSpec

#: Measured height ~ a + b * knob for our plants (fitted on a few seeds), used only for
#: the first build's guess; later builds correct it by the secant through the last two builds.
HEIGHT_MODEL = {"strawberry": (-0.07, 0.43), "tomato": (0.505, 0.68)}
#: Fruit size (half the mean principal extent) and leaf length of the library models as built,
#: for the first build's guess.
DEFAULT_SIZES = {"strawberry": (0.037, 0.139), "tomato": (0.016, 0.205)}
#: Blades measured as one leaf where not all of a petiole's: Table 1's strawberry leaf length is
#: a leaflet's, as ``leaf_length`` is in the Canopy Generator that made the original's plants.
LEAF_UNIT = {"strawberry": 1}


def load_architecture_model(context, crop: CropSpec) -> ArchitectureModel:
    """Load a crop's shoot types into a new PlantArchitecture of ``context``.

    Args:
        context: The scene's Helios Context.
        crop: The crop: the library model ``crop.helios_model``, or the goblet vine's shoots.

    Returns:
        The loaded model, with every shoot type's parameters as loaded.
    """
    from pyhelios import PlantArchitecture

    plant_architecture = PlantArchitecture(context)
    plant_architecture.disableMessages()
    with quiet_stdout():
        if crop.name == "vine":
            shoot_defaults = load_vine_model(plant_architecture)
        else:
            plant_architecture.loadPlantModelFromLibrary(crop.helios_model)
            shoot_defaults = {
                label: plant_architecture.getCurrentShootParameters(label)
                for label in plant_architecture.listShootTypeLabels()
            }
    return ArchitectureModel(context, plant_architecture, crop, shoot_defaults)


def grow_architecture_plant(
    model: ArchitectureModel, index: int, position: tuple[float, float], target: Phenotype, seed: int
) -> GrownPlant:
    """Grow one plant of the model's crop: a goblet vine or a library strawberry or tomato.

    Args:
        model: What :func:`load_architecture_model` returned.
        index, position, target, seed: As for :func:`davis_ag.scene.plants.grow_to_target`.

    Returns:
        The grown plant, left in the context.
    """
    grow = grow_goblet_vine if model.crop.name == "vine" else grow_library_plant
    return grow(model, index, position, target, seed)


def grow_library_plant(
    model: ArchitectureModel, index: int, position: tuple[float, float], target: Phenotype, seed: int
) -> GrownPlant:
    """Grow a strawberry or tomato from the PlantArchitecture library to a target phenotype.

    Returns:
        The grown plant, left in the context.
    """
    from pyhelios.types import vec3

    context, plant_architecture, crop = model.context, model.plant_architecture, model.crop

    def build(knobs: dict, seed: int) -> tuple[int, None]:
        prepare_build(context, plant_architecture, model.shoot_defaults, crop, knobs, seed)
        with quiet_stdout():
            plant_id = plant_architecture.buildPlantInstanceFromLibrary(
                vec3(position[0], position[1], 0.0), crop.age_days
            )
        lift_to_ground(context, plant_architecture, plant_id)
        return plant_id, None

    intercept, slope = HEIGHT_MODEL[crop.name]
    first_knobs = {
        "plant_height": max(0.2, (target.plant_height - intercept) / slope),
        "fruit_radius": target.fruit_radius * crop.fruit_size_per_radius / DEFAULT_SIZES[crop.name][0],
        "leaf_length": target.leaf_length / DEFAULT_SIZES[crop.name][1],
    }
    blades = LEAF_UNIT.get(crop.name, blades_per_leaf(model.shoot_defaults))
    return grow_to_target(context, plant_architecture, crop, index, position, target, seed, build, first_knobs, blades)

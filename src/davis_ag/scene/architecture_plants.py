"""PlantArchitecture plants (``--plants architecture``): a crop's model loaded into a scene's
Context, and its plants grown towards their phenotypes.

Strawberry and tomato come from pyhelios3d's plant library (:func:`grow_library_plant`), the
goblet vine is composed from its grapevine shoot types (:mod:`davis_ag.scene.goblet_vine`);
:func:`grow_architecture_plant` picks the one for the model's crop.

Loading a model draws from the Context's generator, which Helios seeds from the clock
(``Context::Context``), and one of those draws lasts: the library assigns each shoot type its
``LeafPrototype`` (``LeafPrototype::operator=`` samples the non-constant parameters), later copies
keep the sampled value (``LeafPrototype::duplicate``) and the leaf builder reads it without drawing
again (``GenericLeafPrototype``). The tomato's and the grapevine's ``longitudinal_curvature``
(uniform) is drawn so, once per model, and bends every leaf of every plant; redefining the shoot
types, even after seeding, does not draw it again (pyhelios3d 0.1.38, measured). So the Context is
seeded before the model is loaded (:func:`load_architecture_model`): without it no tomato or vine
could be grown twice alike. The strawberry's prototype has no random parameter.
"""

from __future__ import annotations

import numpy as np

from davis_ag.scene.goblet_vine import grow_goblet_vine, load_vine_model
from davis_ag.scene.plants import (
    ArchitectureModel,
    GrownPlant,
    Phenotype,
    blades_per_leaf,
    grow_to_target,
    helios_seed,
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


def load_architecture_model(context, crop: CropSpec, rng: np.random.Generator) -> ArchitectureModel:
    """Load a crop's shoot types into a new PlantArchitecture of ``context``, seeded first.

    Args:
        context: The scene's Helios Context.
        crop: The crop: the library model ``crop.helios_model``, or the goblet vine's shoots.
        rng: The scene's generator. The load's Helios seed comes from a child of it
            (``rng.spawn``), so what ``rng`` draws next (the plants' phenotypes and seeds) is
            the same as if the model had not been loaded.

    Returns:
        The loaded model, with every shoot type's parameters as loaded.
    """
    from pyhelios import PlantArchitecture

    # Helios seeds a new Context from the clock, and the load keeps some of its draws for
    # good (the module docstring): seed it before anything is drawn.
    context.seedRandomGenerator(helios_seed(rng.spawn(1)[0]))
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

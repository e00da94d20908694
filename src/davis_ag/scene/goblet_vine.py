"""A head-trained, free-standing goblet vine composed from pyhelios3d's grapevine shoot types.

pyhelios3d ships trellised grapevines only (VSP, Wye). A goblet ("vaso") vine has no wires: a
vertical trunk (Table 1: 70 cm) ends in a head from which 4 to 6 short arms (spurs of three
nodes) radiate outwards and upwards, and the season's fruiting shoots grow from the arms into an
open vase. We build exactly that with PlantArchitecture's manual API, as Helios builds its own
VSP vine: ``addPlantInstance``; the trunk with ``addBaseStemShoot`` (``grapevine_trunk``); the
arms with ``appendShoot`` at the trunk's head (``goblet_arm``: the library's ``grapevine_cane``
limited to 3 nodes, so the ``grapevine_shoot`` shoots it bears carry the clusters); bare wood
(``removeShootLeaves``); the VSP model's phenology; dormancy broken; then ``advanceTime`` grows
the season's shoots, leaves and clusters.
"""

from __future__ import annotations

import copy
import math

import numpy as np

from davis_ag.scene.plants import (
    ArchitectureModel,
    GrownPlant,
    Phenotype,
    blades_per_leaf,
    fruit_body_uuids,
    grow_to_target,
    prepare_build,
    quiet_stdout,
)

TRUNK_NODES = 7
ARM_NODES = 3
ARM_COUNT = (4, 6)
#: Colour of ripe dark grapes (linear RGB), varied by +-15 % per cluster.
BERRY_COLOUR = (0.26, 0.12, 0.30)
#: Berry radius and leaf length of the library's grapevine shoots as built, for the first guess.
DEFAULT_SIZES = (0.0085, 0.16)
#: The vine's woody shoot types, labelled ``trunk`` (the cane wood the arms are made of included).
WOODY_SHOOTS = ("grapevine_trunk", "goblet_arm")


def load_vine_model(plant_architecture) -> dict[str, dict]:
    """Load the VSP grapevine's shoot types and add the goblet's arm.

    Returns:
        The default parameters of every shoot type, the arm included.
    """
    plant_architecture.loadPlantModelFromLibrary("grapevine_VSP")
    arm = copy.deepcopy(plant_architecture.getCurrentShootParameters("grapevine_cane"))
    arm["max_nodes"] = {"distribution": "constant", "parameters": [float(ARM_NODES)]}
    arm["internode_length_max"] = {"distribution": "constant", "parameters": [0.09]}
    plant_architecture.defineShootType("goblet_arm", arm)
    return {
        label: plant_architecture.getCurrentShootParameters(label) for label in plant_architecture.listShootTypeLabels()
    }


def grow_goblet_vine(
    model: ArchitectureModel, index: int, position: tuple[float, float], target: Phenotype, seed: int
) -> GrownPlant:
    """Grow one goblet vine to a target trunk height, berry radius and leaf length.

    ``model`` holds the shoot types :func:`load_vine_model` loaded; the other arguments are as for
    :func:`davis_ag.scene.plants.grow_to_target`. Returns the grown vine, left in the context.
    """
    from pyhelios.types import AxisRotation, vec3

    context, plant_architecture, crop = model.context, model.plant_architecture, model.crop
    shoot_defaults = model.shoot_defaults

    def build(knobs: dict, seed: int) -> tuple[int, float]:
        prepare_build(context, plant_architecture, shoot_defaults, crop, knobs, seed)
        rng = np.random.default_rng(seed)  # the vine's own layout draws
        plant_id = plant_architecture.addPlantInstance(vec3(position[0], position[1], 0.0), 0.0)
        internode = knobs["plant_height"] * crop.plant_height / TRUNK_NODES
        lean = AxisRotation(float(rng.uniform(0.0, 0.03 * math.pi)), float(rng.uniform(0, 2 * math.pi)), 0.0)
        trunk = plant_architecture.addBaseStemShoot(
            plant_id, TRUNK_NODES, lean, 0.04, internode, 1.0, 1.0, 0.5, "grapevine_trunk"
        )
        arm_count = int(rng.integers(ARM_COUNT[0], ARM_COUNT[1] + 1))
        first_yaw = rng.uniform(0, 2 * math.pi)
        arms = []
        for k in range(arm_count):
            yaw = first_yaw + 2 * math.pi * k / arm_count + rng.uniform(-0.3, 0.3)
            tilt = rng.uniform(0.25, 0.35) * math.pi  # from vertical: arms rise outwards
            arms.append(
                plant_architecture.appendShoot(
                    plant_id,
                    trunk,
                    ARM_NODES,
                    AxisRotation(float(tilt), float(yaw), math.pi),
                    0.015,
                    0.09,
                    1.0,
                    1.0,
                    0.6,
                    "goblet_arm",
                )
            )
        for shoot in [trunk, *arms]:
            plant_architecture.removeShootLeaves(plant_id, shoot)
        # The library VSP vine's phenology (days): fruit set and maturity 45 days after budbreak.
        plant_architecture.setPlantPhenologicalThresholds(plant_id, 165, -1, -1, 45, 45, 200, False)
        plant_architecture.breakPlantDormancy(plant_id)
        with quiet_stdout():
            plant_architecture.advanceTime(crop.age_days, plant_id=plant_id)
        trunk_top = float(plant_architecture.getShootInternodeVertices(plant_id, trunk)[-1][2])
        return plant_id, trunk_top

    first_knobs = {
        "plant_height": target.plant_height / crop.plant_height,
        "fruit_radius": target.fruit_radius / DEFAULT_SIZES[0],
        "leaf_length": target.leaf_length / DEFAULT_SIZES[1],
    }
    vine = grow_to_target(
        context,
        plant_architecture,
        crop,
        index,
        position,
        target,
        seed,
        build,
        first_knobs,
        blades_per_leaf(shoot_defaults),
        woody_shoots=WOODY_SHOOTS,
    )
    # The library's berries are near black (0.05, 0.08, 0.1) and render as silhouettes.
    from pyhelios.types import RGBcolor

    rng = np.random.default_rng(vine.seed)
    for cluster in vine.fruit_objects:
        shade = rng.uniform(0.85, 1.15)
        colour = RGBcolor(*(min(1.0, c * shade) for c in BERRY_COLOUR))
        context.setPrimitiveColor(fruit_body_uuids(context, cluster), colour)
    return vine

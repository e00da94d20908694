"""Label the primitives of PlantArchitecture plants and of the soil with their organ class.

The plant builders call :func:`label_architecture_plant` once a plant is final (after any
regrowth and after it was lifted or recoloured), and :func:`label_soil` labels the soil tiles.
Each primitive then carries the Context's primitive data ``organ``
(:data:`davis_ag.scene.organs.ORGAN_DATA`), which
:meth:`SceneModel.organ_of_uuid <davis_ag.scene.build.SceneModel.organ_of_uuid>` reads back.

How PlantArchitecture's organs map to the classes (PlantArchitecture records each organ as its
own Context objects, queried per plant):

- fruit objects (``getPlantFruitObjectIDs``): the fruit body is ``fruit``; the green calyx and
  stalk Helios builds into the same object are ``stem``, as
  :func:`~davis_ag.scene.plant_geometry.fruit_body_uuids` separates them for the fruit masks;
- leaf blades (``getPlantLeafObjectIDs``): ``leaf``;
- petioles, peduncles, flowers and internodes: ``stem``; for the goblet vine, the internodes of
  its woody shoot types (trunk and arms, ``getPlantInternodeObjectIDs(plant, shoot_type)``) are
  ``trunk``.
"""

from __future__ import annotations

from collections.abc import Iterable

import numpy as np

from davis_ag.scene.organs import FLOWER, FRUIT, LEAF, ORGAN_DATA, PEDUNCLE, PETIOLE, SOIL, STEM, TRUNK
from davis_ag.scene.plant_geometry import fruit_body_uuids


def set_organ(context, uuids: Iterable[int], organ: int) -> None:
    """Give primitives an organ class (one native call)."""
    uuids = [int(u) for u in uuids]
    if uuids:
        context.setPrimitiveDataUInt(uuids, ORGAN_DATA, int(organ))


def object_primitives(context, object_ids: Iterable[int]) -> list[int]:
    """Every primitive of some Context objects."""
    object_ids = [int(o) for o in object_ids]
    if not object_ids:
        return []
    return [int(u) for u in np.atleast_1d(context.getObjectPrimitiveUUIDs(object_ids))]


def label_soil(context, tile_objects: Iterable[int]) -> None:
    """Label the primitives of the soil's tile objects ``soil``."""
    set_organ(context, object_primitives(context, tile_objects), SOIL)


def label_architecture_plant(context, plant_architecture, plant_id: int, woody_shoots: tuple[str, ...] = ()) -> None:
    """Label every primitive of a finished PlantArchitecture plant with its organ class.

    Args:
        context: The scene's Helios Context.
        plant_architecture: The PlantArchitecture that built the plant.
        plant_id: The plant.
        woody_shoots: Shoot types whose internodes are ``trunk`` (the vine's trunk and arms).
    """
    # Everything first as stem: whatever no query below names (a tube Helios adds) is plant tissue.
    set_organ(context, plant_architecture.getAllPlantUUIDs(plant_id), STEM)
    set_organ(context, object_primitives(context, plant_architecture.getPlantLeafObjectIDs(plant_id)), LEAF)
    for fruit in plant_architecture.getPlantFruitObjectIDs(plant_id):
        set_organ(context, fruit_body_uuids(context, int(fruit)), FRUIT)
    for shoot_type in woody_shoots:
        woody = plant_architecture.getPlantInternodeObjectIDs(plant_id, shoot_type)
        set_organ(context, object_primitives(context, woody), TRUNK)


def label_library_plant(context, plant_architecture, plant_id: int, woody_shoots: tuple[str, ...]) -> None:
    """Label every primitive of a plant-library crop's plant, each organ list its own class.

    Unlike :func:`label_architecture_plant` (the paper's crops, whose classes stay as they were),
    petioles, peduncles and flowers get their own classes, and a fruit is its whole fruit object.

    Args:
        context: The scene's Helios Context.
        plant_architecture: The PlantArchitecture that built the plant.
        plant_id: The plant.
        woody_shoots: Shoot types whose internodes are ``trunk`` (trunks, scaffolds, canes);
            ``("*",)``: every internode.
    """
    set_organ(context, plant_architecture.getAllPlantUUIDs(plant_id), STEM)
    for shoot_type in woody_shoots:
        woody = plant_architecture.getPlantInternodeObjectIDs(plant_id, None if shoot_type == "*" else shoot_type)
        set_organ(context, object_primitives(context, woody), TRUNK)
    for query, organ in (
        (plant_architecture.getPlantPetioleObjectIDs, PETIOLE),
        (plant_architecture.getPlantPeduncleObjectIDs, PEDUNCLE),
        (plant_architecture.getPlantFlowerObjectIDs, FLOWER),
        (plant_architecture.getPlantLeafObjectIDs, LEAF),
        (plant_architecture.getPlantFruitObjectIDs, FRUIT),
    ):
        set_organ(context, object_primitives(context, query(plant_id)), organ)

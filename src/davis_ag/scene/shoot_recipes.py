"""Shoot parameters that make our plants carry the paper's fruit load and leaf canopy.

The original DAVIS-Ag strawberry came from Helios's Canopy Generator (through AgML), whose
strawberry has 50 stems, each with a trifoliate leaf whose leaflets are ``leaf_length`` (Table 1:
10 cm) long, and 0.6 fruit clusters per stem hanging 10-30 cm out from it: the dense bush of the
original's pictures, fruit mostly hidden under it. pyhelios3d has no Canopy Generator; its
PlantArchitecture strawberry grows one crown of 15 nodes (15 leaves) and bears 4-9 fruit at 90
days (mean 5.9 over 10 seeds), where the paper's showcase plant (section IV, Fig. 2) carries 24.

Strawberry: 50 nodes, as the original's 50 stems. Growth is determinate and stops at the first
flower, so the nodes must come faster (``phyllochron_min`` 0.5 instead of 2 days); one floral
bud per node and a fruit set of 0.5 (library: 0.3) give about 25 fruit (measured by
davis-ag scene-stats: docs/scenes.md). The leaf length is measured per leaflet, as the Canopy
Generator's ``leaf_length`` is (``architecture_plants.LEAF_UNIT``), which doubles the leaflets.
Where the fruit hang decides how many a camera sees (Fig. 2). The library builder makes every
internode 4 mm whatever ``internode_length_max`` says, so 50 nodes stacked into a 20 cm column
with fruit hanging all the way up it, outside a narrow tuft of leaves: no view of ours saw fewer
than 5 fruit, where Fig. 2 has several. We set each internode to 1 mm as it is created
(``CROWN_INTERNODE``: a crown of 5 cm), shorten the peduncles (0.04-0.08 m instead of 0.16-0.20)
so the fruit lie around the crown on the soil, and let the petioles lean further out and arch
over them (pitch 20-50 degrees from vertical instead of 10-45, curvature -200 to -100 instead of
-150 to -50): the leaves roof the fruit as in the original's bush. docs/scenes.md has what this
does to the fruit in view (davis-ag scene-stats). What did not work (shared notes, measured):
two floral buds per node fuse fruit pairs and lift the plant; more nodes without a shorter
phyllochron change nothing; vegetative bud break grows dozens of crowns; petioles leaning out
45-85 degrees dive under the soil once the crown is compact.

Tomato: the library's trusses carry 6 flowers each (so every plant came out a multiple of 6,
most 18), and one node in five breaks a floral bud; a greenhouse tomato has a truss every third
leaf carrying 4-8 fruit, which we copy. The goblet vine's load (clusters per shoot) is the
grapevine library's own.
"""

from __future__ import annotations

import copy
from collections.abc import Callable

from davis_ag.scene.specs import CropSpec


def _constant(value: float) -> dict:
    return {"distribution": "constant", "parameters": [float(value)]}


def _uniform(low: float, high: float) -> dict:
    return {"distribution": "uniform", "parameters": [float(low), float(high)]}


#: Per crop: (path of keys into a shoot type's parameters, new RandomParameter spec).
SHOOT_RECIPES: dict[str, tuple[tuple[tuple[str, ...], dict], ...]] = {
    "strawberry": (
        (("max_nodes",), _constant(50)),
        (("phyllochron_min",), _constant(0.5)),
        (("fruit_set_probability",), _constant(0.5)),
        (("phytomer_parameters", "petiole", "pitch"), _uniform(20.0, 50.0)),
        (("phytomer_parameters", "petiole", "curvature"), _uniform(-200.0, -100.0)),
        (("phytomer_parameters", "peduncle", "length"), _uniform(0.04, 0.08)),
    ),
    "tomato": (
        (("flower_bud_break_probability",), _constant(0.33)),
        (("phytomer_parameters", "inflorescence", "flowers_per_peduncle"), _uniform(4.0, 8.0)),
    ),
    "vine": (),
}


#: Fully elongated length of every internode of a crop's main stem, m, where the library's is
#: wrong for our plant: the library strawberry's internodes are 4 mm, so 50 nodes stack into a
#: 20 cm column with fruit hanging from all of it; a strawberry crown is a few centimetres tall.
CROWN_INTERNODE: dict[str, float] = {"strawberry": 0.001}


def with_shoot_recipe(params: dict, crop: CropSpec) -> dict:
    """A shoot type's parameters with the crop's recipe applied.

    Args:
        params: One shoot type's parameters (``getCurrentShootParameters``); not modified.
        crop: The crop whose :data:`SHOOT_RECIPES` entry applies.

    Returns:
        A modified deep copy; keys a shoot type does not have are left out.
    """
    out = copy.deepcopy(params)
    for path, spec in SHOOT_RECIPES.get(crop.name, ()):
        parent: dict | None = out
        for key in path[:-1]:
            parent = parent.get(key) if isinstance(parent, dict) else None
            if parent is None:
                break
        if isinstance(parent, dict) and path[-1] in parent:
            parent[path[-1]] = copy.deepcopy(spec)
    return out


def fixed_internode(plant_architecture, length: float) -> Callable[..., None]:
    """A phytomer creation callback that sets each new internode's fully elongated length.

    The library's strawberry builder ignores ``internode_length_max``, so the length is set per
    phytomer as it is created (the strawberry has no library creation function to replace).

    Args:
        plant_architecture: The PlantArchitecture the callback is installed on.
        length: Internode length, m (``CROWN_INTERNODE``).

    Returns:
        The callback for ``setPhytomerCreationFunction``.
    """

    def creation(plant_id: int, shoot_id: int, node_index: int, *_: object) -> None:
        plant_architecture.setInternodeMaxLength(plant_id, shoot_id, node_index, length)

    return creation

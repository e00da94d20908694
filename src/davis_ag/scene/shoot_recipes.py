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
tools/scene_stats.py: docs/scenes.md). The leaf length is measured per leaflet, as the Canopy
Generator's ``leaf_length`` is (``plants.LEAF_UNIT``), which doubles the leaflets. Petioles
spread wider (pitch 45-85 degrees from vertical instead of 10-45) and peduncles are shorter
(0.08-0.16 m instead of 0.16-0.20), so the leaves roof the fruit as in the original's bush
rather than the fruit hanging outside a narrow tuft. Measured on 21 views of one plant at
192x108 (Table 1 altitudes): visible fruit per view went from 16-22 of 22 (15 leaves) to 11-17
of 21; the paper's Fig. 2 has fewer than 5 to 16 of 24. What did not work (shared
notes, measured): two floral buds per node fuse fruit pairs and lift the plant; more nodes
without a shorter phyllochron change nothing; vegetative bud break grows dozens of crowns.

Tomato: the library's trusses carry 6 flowers each (so every plant came out a multiple of 6,
most 18), and one node in five breaks a floral bud; a greenhouse tomato has a truss every third
leaf carrying 4-8 fruit, which we copy. The goblet vine's load (clusters per shoot) is the
grapevine library's own.
"""

from __future__ import annotations

import copy

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
        (("phytomer_parameters", "petiole", "pitch"), _uniform(45.0, 85.0)),
        (("phytomer_parameters", "peduncle", "length"), _uniform(0.08, 0.16)),
    ),
    "tomato": (
        (("flower_bud_break_probability",), _constant(0.33)),
        (("phytomer_parameters", "inflorescence", "flowers_per_peduncle"), _uniform(4.0, 8.0)),
    ),
    "vine": (),
}


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
        parent = out
        for key in path[:-1]:
            parent = parent.get(key) if isinstance(parent, dict) else None
            if parent is None:
                break
        if isinstance(parent, dict) and path[-1] in parent:
            parent[path[-1]] = copy.deepcopy(spec)
    return out

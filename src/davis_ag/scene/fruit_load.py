"""How many fruit a plant carries: PlantArchitecture shoot parameters that set the fruit load.

The library plants bear few fruit: a strawberry 4-9 (mean 5.9 over 10 seeds at 90 days), where
the paper's showcase plant (section IV, Fig. 2) carries 24. A strawberry's expected fruit count is
about nodes x floral buds per node x fruit set x flowers per peduncle (one crown, determinate
growth: about 15 nodes). Raising the fruit set from 0.3 to 0.8 and the flowers per peduncle from
1 to 2 on average gives about 24 (measured: tools/fruit_per_plant.py writes docs/scenes.md).
Longer, more varied peduncles, bent less far back, spread the trusses around the crown so fruit
do not grow into each other (23 % of fruit interpenetrating at the library's peduncles, 14 %
with these). What did not work (shared notes, measured): two floral buds per node fuses fruit
pairs and lifts the plant; more nodes alone changes nothing (growth stops at the first flower);
any vegetative bud break grows dozens of crowns.

Tomato: the library's trusses carry 6 flowers, but only one node in five breaks a floral bud;
one in three is what a greenhouse tomato shows (a truss every third leaf), which gives 10-30
fruit per plant. The goblet vine's load (clusters per shoot) is the grapevine library's own.
"""

from __future__ import annotations

import copy

from davis_ag.scene.specs import CropSpec

#: Per crop: (path of keys into a shoot type's parameters, new RandomParameter spec).
FRUIT_LOAD: dict[str, tuple[tuple[tuple[str, ...], dict], ...]] = {
    "strawberry": (
        (("fruit_set_probability",), {"distribution": "constant", "parameters": [0.8]}),
        (("phytomer_parameters", "inflorescence", "flowers_per_peduncle"),
         {"distribution": "uniform", "parameters": [1.0, 3.0]}),
        (("phytomer_parameters", "peduncle", "length"), {"distribution": "uniform", "parameters": [0.10, 0.28]}),
        (("phytomer_parameters", "peduncle", "curvature"),
         {"distribution": "uniform", "parameters": [-120.0, -40.0]}),
    ),
    "tomato": (
        (("flower_bud_break_probability",), {"distribution": "constant", "parameters": [0.33]}),
    ),
    "vine": (),
}


def with_fruit_load(params: dict, crop: CropSpec) -> dict:
    """A shoot type's parameters with the crop's fruit load applied.

    Args:
        params: One shoot type's parameters (``getCurrentShootParameters``); not modified.
        crop: The crop whose :data:`FRUIT_LOAD` applies.

    Returns:
        A modified deep copy; keys a shoot type does not have are left out (a vine's trunk has
        no inflorescence worth changing).
    """
    out = copy.deepcopy(params)
    for path, spec in FRUIT_LOAD.get(crop.name, ()):
        parent = out
        for key in path[:-1]:
            parent = parent.get(key) if isinstance(parent, dict) else None
            if parent is None:
                break
        if isinstance(parent, dict) and path[-1] in parent:
            parent[path[-1]] = copy.deepcopy(spec)
    return out

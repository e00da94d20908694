"""Shoot recipes: the fruit load and canopy changes applied to the library's shoot parameters."""

from __future__ import annotations

import copy

from davis_ag.scene.architecture_plants import LEAF_UNIT
from davis_ag.scene.shoot_recipes import SHOOT_RECIPES, with_shoot_recipe
from davis_ag.scene.specs import CROPS


def library_like() -> dict:
    """The shape of a strawberry mainstem's parameters (the keys the recipes touch)."""
    constant = {"distribution": "constant", "parameters": [1.0]}
    return {
        "max_nodes": dict(constant),
        "phyllochron_min": dict(constant),
        "fruit_set_probability": dict(constant),
        "flower_bud_break_probability": dict(constant),
        "phytomer_parameters": {
            "petiole": {"pitch": dict(constant), "curvature": dict(constant)},
            "peduncle": {"length": dict(constant), "curvature": dict(constant)},
            "inflorescence": {"flowers_per_peduncle": dict(constant)},
        },
    }


def test_recipe_sets_every_listed_parameter_and_leaves_the_input_alone() -> None:
    for name, recipe in SHOOT_RECIPES.items():
        params = library_like()
        before = copy.deepcopy(params)
        out = with_shoot_recipe(params, CROPS[name])
        assert params == before
        for path, spec in recipe:
            value = out
            for key in path:
                value = value[key]
            assert value == spec
            assert value is not spec  # a copy: building a plant cannot alter the recipe


def test_strawberry_is_the_original_canopy_generators_plant() -> None:
    recipe = {path[-1]: spec["parameters"] for path, spec in SHOOT_RECIPES["strawberry"]}
    # Helios's Canopy Generator strawberry: 50 stems, each a trifoliate leaf measured per leaflet.
    assert recipe["max_nodes"] == [50.0] and LEAF_UNIT["strawberry"] == 1
    # About 24 fruit (section IV): 50 nodes x one floral bud x fruit set.
    assert 20 <= 50 * recipe["fruit_set_probability"][0] <= 30


def test_keys_a_shoot_type_lacks_are_skipped() -> None:
    out = with_shoot_recipe({"max_nodes": {"distribution": "constant", "parameters": [3.0]}}, CROPS["strawberry"])
    assert out == {"max_nodes": {"distribution": "constant", "parameters": [50.0]}}
    assert with_shoot_recipe({"a": 1}, CROPS["vine"]) == {"a": 1}

"""Plant-library crops grown with Helios: their fruit are the library's fruit objects, their organs
labelled by the library's lists, their growth reproducible, their boxes Helios's Visualizer's."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from davis_ag.labels.fruit_labels import fruit_lookup, label_view
from davis_ag.scene.camera import Camera
from davis_ag.scene.library_crops import LIBRARY_RECIPES
from davis_ag.scene.organs import FLOWER, FRUIT, LEAF, ORGAN_DATA, PEDUNCLE, PETIOLE, SOIL, TRUNK
from davis_ag.scene.specs import CROPS, plant_centres, scenario_spec
from davis_ag.scene.view_grid import build_view_grid
from helios_reference import helios_reference

pytestmark = pytest.mark.slow

#: A tree and a vegetable, the fastest of each to grow (seconds).
CROPS_GROWN = ("olive", "capsicum")
CAMERA = Camera(640, 360)


def grow(name: str, seed: int = 5):
    from davis_ag.scene.build import build_scene

    crop = CROPS[name]
    scenario = scenario_spec("sp", crop)
    rng = np.random.default_rng(seed)
    model = build_scene(scenario, crop, rng)
    grid = build_view_grid(scenario, crop, plant_centres(scenario, crop), model.aim_height, rng)
    return model, grid


@pytest.fixture(scope="module", params=CROPS_GROWN)
def grown(request: pytest.FixtureRequest):
    return request.param, *grow(request.param)


def organs(model) -> np.ndarray:
    return model.organ_of_uuid()


def test_fruit_are_the_librarys_fruit_objects_whole(grown) -> None:
    name, model, _ = grown
    (plant,) = model.plants
    low, high = LIBRARY_RECIPES[name].fruit_range
    assert low <= plant.fruit_count <= high
    assert len(model.fruits) == len(plant.fruit_objects) == plant.fruit_count
    table = organs(model)
    for fruit, obj in zip(model.fruits, plant.fruit_objects):
        whole = sorted(int(u) for u in model.context.getObjectPrimitiveUUIDs(obj))
        assert sorted(int(u) for u in fruit.uuids) == whole  # the object, not a part of it
        assert (table[whole] == FRUIT).all()
    labelled = np.flatnonzero(table == FRUIT)
    assert set(labelled.tolist()) == {int(u) for f in model.fruits for u in f.uuids}


def test_every_primitive_has_an_organ_and_the_library_lists_have_their_own(grown) -> None:
    name, model, _ = grown
    table = organs(model)
    every = [int(u) for u in model.context.getAllUUIDs()]
    assert (table[every] > 0).all()  # nothing left as sky
    present = set(np.unique(table[every]).tolist())
    assert {SOIL, FRUIT, LEAF, PETIOLE, PEDUNCLE} <= present
    if name == "olive":  # every internode of the trees is barked wood
        assert TRUNK in present
    assert present <= {SOIL, FRUIT, LEAF, PETIOLE, PEDUNCLE, FLOWER, TRUNK, 4}
    assert model.context.doesPrimitiveDataExist(every[0], ORGAN_DATA)


def test_the_record_names_the_model_age_changes_and_factors(grown) -> None:
    name, model, _ = grown
    summary = model.plants[0].summary()
    recipe = LIBRARY_RECIPES[name]
    assert summary["library"]["model"] == recipe.model and summary["library"]["age_days"] == recipe.age_days
    factors = summary["library"]["factors"]
    assert abs(factors["size"] - 1) <= 0.15 and abs(factors["fruit"] - 1) <= 0.2 and abs(factors["leaf"] - 1) <= 0.2
    assert model.plant_generator == "library"


def test_the_same_seed_grows_the_same_plant_and_another_seed_another() -> None:
    from davis_ag.scene.plants import primitive_vertices

    def digest(seed: int) -> tuple[int, float]:
        model, _ = grow("capsicum", seed)
        points = np.concatenate(primitive_vertices(model.context, [int(u) for u in model.plants[0].uuids]))
        return len(points), float(points.sum())

    assert digest(11) == digest(11)
    assert digest(11) != digest(12)


@helios_reference
def test_fruit_boxes_match_helios_visualizer(grown) -> None:
    from davis_ag.render.backends import open_renderer

    name, model, grid = grown
    crop = CROPS[name]
    # Low, middle and high, on three sides of the plant.
    views = [grid.viewpoints[i] for i in (20, 150, 290)]
    lookup = fruit_lookup({f.id: f.uuids for f in model.fruits}, model.uuid_count)
    threshold = crop.min_fruit_pixels_at(CAMERA.width, CAMERA.height)
    frames = {}
    for renderer in ("helios", "opengl"):
        with open_renderer(renderer, model.context, CAMERA, model.lighting, "helios") as drawing:
            frames[renderer] = [drawing.render(view)[1] for view in views]
    compared = 0
    for ours, theirs in zip(frames["opengl"], frames["helios"]):
        mine, ref = label_view(ours, lookup, threshold), label_view(theirs, lookup, threshold)
        boxes = {b[4]: b for b in ref.boxes}
        # A fruit at the threshold may fall on either side of it: compare those both boxed.
        for box in mine.boxes:
            if box[4] in boxes:
                assert np.abs(np.subtract(box[:4], boxes[box[4]][:4])).max() <= 1, (box, boxes[box[4]])
                compared += 1
        assert len({b[4] for b in mine.boxes} ^ set(boxes)) <= 1
    assert compared >= 3


@pytest.mark.parametrize("name", sorted(LIBRARY_RECIPES))
def test_every_recipe_change_lands_on_a_shoot_type_of_its_model(name: str) -> None:
    from pyhelios import Context

    from davis_ag.scene.library_plants import load_library_model, shoot_parameters

    model = load_library_model(Context(), CROPS[name], np.random.default_rng(0))
    factors = {"size": 1.0, "fruit": 1.0, "leaf": 1.0}
    changed = shoot_parameters(model.shoot_defaults, LIBRARY_RECIPES[name], factors)  # raises on a miss
    assert set(changed) == set(model.shoot_defaults)
    broken = replace(LIBRARY_RECIPES[name], shoot_changes=(("*", "no.such.parameter", 1.0),))
    with pytest.raises(ValueError, match=r"no.such.parameter"):
        shoot_parameters(model.shoot_defaults, broken, factors)

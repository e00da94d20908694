"""Grow the plants of a scene with pyhelios3d's PlantArchitecture and measure what was built.

Phenotypes follow Table 1 of the paper, varied per plant (section III-A). The library models do
not expose height, fruit radius or leaf length directly, so each plant is built, measured, its
shoot parameters corrected by the ratio of target to measured value, and rebuilt from the same
seed, until the measurement is within ``TOLERANCE`` of the target (at most ``MAX_BUILDS`` builds).

What is measured (metres):

- height: top of the plant above the ground (strawberry, tomato); for the vine, the trunk height.
- fruit radius: per fruit, half the mean extent of its body's vertices along their principal
  axes (the body: the fruit object without its green calyx and stalk), divided by the crop's
  ``fruit_size_per_radius`` to put it in Table 1's terms (the Canopy Generator's parameter; a
  strawberry of Table 1's 2.5 cm is 2.5 cm wide, see ``specs.CropSpec``); for the vine, the
  radius of single berries (a cluster is one fruit object, split into berries by mesh
  connectivity). The plant's value is the median over fruit.
- leaf length: per leaf (every blade on one petiole: seven leaflets for tomato, one for the vine;
  each strawberry leaflet, see ``LEAF_UNIT``), the extent of its blades along their principal
  axis; the plant's value is the median over leaves. Helios numbers a leaf's blades
  consecutively, so a leaf is a run of consecutive blade object ids, at most ``blades_per_leaf`` long.
"""

from __future__ import annotations

import contextlib
import math
import os
import sys
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field
from typing import TYPE_CHECKING, Any

import numpy as np

from davis_ag.errors import UserError
from davis_ag.scene.organ_labels import label_architecture_plant
from davis_ag.scene.plant_geometry import (  # noqa: F401 - re-exported for the plant builders
    berry_radii,
    fruit_body_uuids,
    fruit_radius,
    leaf_groups,
    leaf_length,
    object_vertices,
    primitive_vertices,
    principal_extents,
)
from davis_ag.scene.shoot_recipes import CROWN_INTERNODE, fixed_internode, with_shoot_recipe
from davis_ag.scene.specs import PHENOTYPE_SPREAD, CropSpec

if TYPE_CHECKING:  # pyhelios loads its native library: imported only where a scene is built
    from pyhelios import Context, PlantArchitecture

#: Helios maps seeds 0, 1, 2**31 - 1 and 2**32 - 1 to the same plant: stay inside this range.
HELIOS_SEED_RANGE = (2, 2**31 - 2)
#: Relative error at which a built phenotype counts as on target.
TOLERANCE = 0.03
MAX_BUILDS = 4


@dataclass(frozen=True)
class Phenotype:
    """Plant height (vine: trunk height), fruit (vine: berry) radius and leaf length, in metres."""

    plant_height: float
    fruit_radius: float
    leaf_length: float


@dataclass
class GrownPlant:
    """One plant as built in the Helios context.

    Attributes:
        index: Position of the plant in the scene, 0-based.
        seed: The Helios seed it was grown from (after any regrowth).
        position: Stem position (x, y), m.
        target: The phenotype asked for.
        measured: The phenotype measured on the built geometry.
        fruit_objects: Helios object ids of its fruit (a grape cluster is one object).
        uuids: Every primitive of the plant.
        builds: Builds it took, regrowths for too few fruit included.
        fruit_bodies: Per fruit, the primitives of its body, when the builder knows them (the
            Canopy Generator plants); otherwise read from ``fruit_objects``.
        build_s: Seconds it took to build and measure (not in :meth:`summary`: scene.json is the
            same, byte for byte, whenever the scene is made again).
        library: For a plant-library crop: its model, age, shoot changes, drawn factors and
            measured crown width (:mod:`davis_ag.scene.library_plants`).
    """

    index: int
    seed: int
    position: tuple[float, float]
    target: Phenotype
    measured: Phenotype
    fruit_objects: list[int]
    uuids: list[int] = field(repr=False)
    builds: int
    fruit_bodies: list[list[int]] | None = field(default=None, repr=False)
    build_s: float | None = None
    library: dict[str, Any] | None = None

    @property
    def fruit_count(self) -> int:
        """How many fruit it bears (a grape cluster counts once)."""
        return len(self.fruit_bodies) if self.fruit_bodies is not None else len(self.fruit_objects)

    def summary(self) -> dict:
        """JSON-ready description for scene.json."""
        return {
            "index": self.index,
            "seed": self.seed,
            "position": list(self.position),
            "phenotype_target": asdict(self.target),
            "phenotype_measured": asdict(self.measured),
            "fruit_count": self.fruit_count,
            "builds": self.builds,
            **({"library": self.library} if self.library is not None else {}),
        }


def require_native_helios() -> None:
    """Fail loudly when pyhelios would silently fall back to its mock mode.

    Raises:
        UserError: when the native Helios library (and with it system libGL/libEGL) is missing.
    """
    try:
        from pyhelios.plugins import get_library_info
    except ImportError as error:  # pragma: no cover - depends on the machine
        raise UserError(f"pyhelios3d is not installed ({error}): run 'make demo' or pip install pyhelios3d") from None
    info = get_library_info()
    if info.get("is_mock", True):
        raise UserError(
            "pyhelios3d runs in mock mode: its native library did not load "
            f"({info.get('library_path')}); install the system GL libraries (Debian: apt-get install libgl1 libegl1)"
        )


@contextlib.contextmanager
def quiet_stdout():
    """Silence native prints (growth progress bars) by redirecting file descriptor 1."""
    sys.stdout.flush()
    saved = os.dup(1)
    with open(os.devnull, "w") as devnull:
        os.dup2(devnull.fileno(), 1)
    try:
        yield
    finally:
        sys.stdout.flush()
        os.dup2(saved, 1)
        os.close(saved)


def helios_seed(rng: np.random.Generator) -> int:
    """Draw a seed Helios treats as distinct from every other."""
    low, high = HELIOS_SEED_RANGE
    return int(rng.integers(low, high + 1))


def sample_phenotype(crop: CropSpec, rng: np.random.Generator) -> Phenotype:
    """Draw a target phenotype uniformly within the paper's spread around Table 1."""

    def vary(nominal: float, spread: float) -> float:
        return float(nominal * (1.0 + rng.uniform(-spread, spread)))

    return Phenotype(
        plant_height=vary(crop.plant_height, PHENOTYPE_SPREAD["plant_height"]),
        fruit_radius=vary(crop.fruit_radius, PHENOTYPE_SPREAD["fruit_radius"]),
        leaf_length=vary(crop.leaf_length, PHENOTYPE_SPREAD["leaf_length"]),
    )


# ---------------------------------------------------------------------------------------------
# Geometry measurement


def measure_plant(
    context,
    plant_architecture,
    plant_id: int,
    crop: CropSpec,
    blades_per_leaf: int,
    trunk_top: float | None = None,
) -> Phenotype:
    """Measure height, fruit radius and leaf length of a built plant (see the module docstring)."""
    fruit_ids = plant_architecture.getPlantFruitObjectIDs(plant_id)
    if crop.name == "vine":
        radii = np.concatenate([berry_radii(context, f) for f in fruit_ids]) if fruit_ids else np.zeros(0)
    else:
        radii = (
            np.array(
                [
                    fruit_radius(np.concatenate(primitive_vertices(context, fruit_body_uuids(context, f))))
                    for f in fruit_ids
                ]
            )
            / crop.fruit_size_per_radius
        )
    blades = plant_architecture.getPlantLeafObjectIDs(plant_id)
    lengths = np.array(
        [
            leaf_length(np.concatenate([object_vertices(context, b) for b in group]))
            for group in leaf_groups(blades, blades_per_leaf)
        ]
    )
    if trunk_top is not None:
        height = trunk_top
    else:
        parts = primitive_vertices(context, plant_architecture.getAllPlantUUIDs(plant_id))
        height = float(max(p[:, 2].max() for p in parts))
    return Phenotype(
        plant_height=height,
        fruit_radius=float(np.median(radii)) if len(radii) else math.nan,
        leaf_length=float(np.median(lengths)) if len(lengths) else math.nan,
    )


def relative_error(measured: Phenotype, target: Phenotype) -> dict[str, float]:
    """Relative error of each measured trait; NaN traits (no fruit) count as infinitely wrong."""
    errors = {}
    for name, want in asdict(target).items():
        got = getattr(measured, name)
        errors[name] = math.inf if not math.isfinite(got) else abs(got / want - 1.0)
    return errors


def scale_parameter(spec: dict, factor: float) -> None:
    """Scale a PlantArchitecture RandomParameter spec ``{'distribution', 'parameters'}`` in place."""
    if spec["distribution"] in ("constant", "uniform"):
        spec["parameters"] = [float(v) * factor for v in spec["parameters"]]
    elif spec["distribution"] == "normal":  # mean and standard deviation both scale
        spec["parameters"] = [float(v) * factor for v in spec["parameters"]]
    else:
        raise ValueError(f"cannot scale a {spec['distribution']} parameter")


def scaled_shoot_parameters(defaults: dict, crop: CropSpec, knobs: dict[str, float]) -> dict:
    """Shoot parameters with the height, fruit and leaf knobs applied.

    Args:
        defaults: The library's parameters of one shoot type.
        crop: Which parameter drives the height.
        knobs: Multiplicative factors ``plant_height``, ``fruit_radius``, ``leaf_length``.

    Returns:
        A modified deep copy, with the crop's recipe (``shoot_recipes.SHOOT_RECIPES``) applied.
    """
    params = with_shoot_recipe(defaults, crop)
    phytomer = params["phytomer_parameters"]
    scale_parameter(phytomer["inflorescence"]["fruit_prototype_scale"], knobs["fruit_radius"])
    scale_parameter(phytomer["leaf"]["prototype_scale"], knobs["leaf_length"])
    if crop.name == "strawberry":
        # A strawberry's height is its petioles (the stem barely grows).
        scale_parameter(phytomer["petiole"]["length"], knobs["plant_height"])
    elif crop.name == "tomato":
        scale_parameter(params["internode_length_max"], knobs["plant_height"])
    return params


# ---------------------------------------------------------------------------------------------
# Growing


def lift_to_ground(context, plant_architecture, plant_id: int) -> None:
    """Raise a plant whose drooping fruit would hang below the soil, as if on a small mound."""
    from pyhelios.types import vec3

    uuids = plant_architecture.getAllPlantUUIDs(plant_id)
    lowest = min(float(p[:, 2].min()) for p in primitive_vertices(context, uuids))
    if lowest >= 0.0:
        return
    shift = vec3(0.0, 0.0, -lowest + 0.002)
    # Helios moves the primitives of a compound object only through the object itself.
    objects = list(plant_architecture.getAllPlantObjectIDs(plant_id))
    in_objects = set(context.getObjectPrimitiveUUIDs(objects)) if objects else set()
    loose = [u for u in uuids if u not in in_objects]
    if objects:
        context.translateObject(objects, shift)
    if loose:
        context.translatePrimitive(loose, shift)


def _next_height_knob(history: list[tuple[float, float]], target: float) -> float:
    """Secant step through the last two (knob, height) builds; a ratio step after the first."""
    (k1, h1) = history[-1]
    if len(history) == 1 or abs(history[-2][1] - h1) < 1e-6:
        return k1 * target / h1
    (k0, h0) = history[-2]
    slope = (h1 - h0) / (k1 - k0) if k1 != k0 else h1 / k1
    return max(0.2, k1 + (target - h1) / slope) if slope > 0 else k1 * target / h1


def in_table_range(measured: Phenotype, crop: CropSpec, slack: float = 0.0) -> bool:
    """Whether every measured trait lies within Table 1's value +- the paper's spread (+ slack)."""
    nominal = {"plant_height": crop.plant_height, "fruit_radius": crop.fruit_radius, "leaf_length": crop.leaf_length}
    return all(
        abs(getattr(measured, name) / value - 1.0) <= PHENOTYPE_SPREAD[name] + slack for name, value in nominal.items()
    )


@dataclass
class ArchitectureModel:
    """One crop's PlantArchitecture model in a scene's Context, ready to grow plants.

    Attributes:
        context: The scene's Helios Context.
        plant_architecture: Its PlantArchitecture, with the crop's shoot types loaded.
        crop: The crop.
        shoot_defaults: The parameters of every shoot type as loaded, read before any change.
    """

    context: Context
    plant_architecture: PlantArchitecture
    crop: CropSpec
    shoot_defaults: dict[str, dict]


#: Builds a plant from knobs and a seed; returns its id and, for the vine, its trunk's top.
BuildPlant = Callable[[dict, int], "tuple[int, float | None]"]


def grow_to_target(
    context,
    plant_architecture,
    crop: CropSpec,
    index: int,
    position: tuple[float, float],
    target: Phenotype,
    seed: int,
    build: BuildPlant,
    first_knobs: dict[str, float],
    blades_per_leaf: int,
    woody_shoots: tuple[str, ...] = (),
) -> GrownPlant:
    """Build, measure, correct and rebuild a plant until it matches its target phenotype.

    Args:
        context: The scene's Helios Context.
        plant_architecture: Its PlantArchitecture, with the crop's model loaded.
        crop: The crop.
        index: The plant's index in the scene.
        position: Stem position (x, y), m.
        target: The phenotype to reach.
        seed: Helios seed. A plant with fewer than ``crop.min_fruit`` fruit, or one still
            outside Table 1's range after ``MAX_BUILDS`` builds, is regrown from the next seed.
        build: Makes the plant from knobs (factors on the library's height, fruit and leaf
            parameters) and a seed.
        first_knobs: The knobs of the first build.
        blades_per_leaf: Leaf blades on one petiole, to measure whole leaves.
        woody_shoots: Shoot types labelled ``trunk`` (see :mod:`davis_ag.scene.organ_labels`).

    Returns:
        The grown plant, left in the context, every primitive labelled with its organ class.
    """
    builds = 0
    started = time.perf_counter()
    while True:
        knobs = dict(first_knobs)
        history: list[tuple[float, float]] = []
        for attempt in range(MAX_BUILDS):
            plant_id, trunk_top = build(knobs, seed)
            builds += 1
            fruit = plant_architecture.getPlantFruitObjectIDs(plant_id)
            if len(fruit) < crop.min_fruit:
                plant_architecture.deletePlantInstance(plant_id)
                break
            measured = measure_plant(context, plant_architecture, plant_id, crop, blades_per_leaf, trunk_top)
            # A target near the edge of the range plus the tolerance could leave it: require both.
            in_range = in_table_range(measured, crop)
            on_target = max(relative_error(measured, target).values()) <= TOLERANCE and in_range
            if on_target or (attempt == MAX_BUILDS - 1 and in_range):
                label_architecture_plant(context, plant_architecture, plant_id, woody_shoots)
                return GrownPlant(
                    index,
                    seed,
                    position,
                    target,
                    measured,
                    list(fruit),
                    list(plant_architecture.getAllPlantUUIDs(plant_id)),
                    builds,
                    build_s=time.perf_counter() - started,
                )
            history.append((knobs["plant_height"], measured.plant_height))
            knobs["plant_height"] = _next_height_knob(history, target.plant_height)
            # Fruit and leaf size are proportional to their prototype scales.
            for name in ("fruit_radius", "leaf_length"):
                knobs[name] *= getattr(target, name) / getattr(measured, name)
            plant_architecture.deletePlantInstance(plant_id)
        seed = seed + 1 if seed < HELIOS_SEED_RANGE[1] else HELIOS_SEED_RANGE[0]
        if builds > 40:
            raise UserError(f"{crop.name}: no plant with {crop.min_fruit}+ fruit on target after {builds} builds")


def blades_per_leaf(shoot_defaults: dict[str, dict]) -> int:
    """Leaf blades per petiole of a model's shoots."""
    first_shoot = next(iter(shoot_defaults.values()))
    return int(first_shoot["phytomer_parameters"]["leaf"]["leaves_per_petiole"]["parameters"][0])


def prepare_build(
    context, plant_architecture, shoot_defaults: dict[str, dict], crop: CropSpec, knobs: dict[str, float], seed: int
) -> None:
    """Redefine every shoot type with the knobs applied and seed Helios, before a build."""
    internode = CROWN_INTERNODE.get(crop.name)
    for label, defaults in shoot_defaults.items():
        plant_architecture.defineShootType(label, scaled_shoot_parameters(defaults, crop, knobs))
        if internode is not None:
            plant_architecture.setPhytomerCreationFunction(label, fixed_internode(plant_architecture, internode))
    context.seedRandomGenerator(seed)

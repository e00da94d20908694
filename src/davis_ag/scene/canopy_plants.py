"""Canopy Generator plants in the Helios Context: add their parts, label organs, measure them.

Section III-A sets each plant's phenotype directly as the plug-in's parameters (fruit radius and
leaf size +-20 %, plant or trunk height +-15 %, around Table 1), so a plant is built once from
the phenotype drawn for it; what was built is then measured back from the Context:

- height: top of the plant's tallest stem (strawberry: the highest point of its stems, which
  lean and bend, so below the drawn height; tomato: the main stem's top; vine: the trunk's top);
- fruit radius in Table 1's terms: for the strawberry, half the mean principal extent of each
  fruit over the crop's ``fruit_size_per_radius``; a tomato or a grape berry is a sphere, and its
  radius the mean distance of its vertices from their centre; median over fruit (berries);
- leaf length: the largest leaf's size (the largest distance between two of its vertices) over
  that of the crop's unit leaf, the shape every leaf is a scaled copy of.
"""

from __future__ import annotations

import time
from dataclasses import dataclass

import numpy as np

from davis_ag.errors import UserError
from davis_ag.scene.canopy import PART_BUILDERS, UNIT_LEAVES
from davis_ag.scene.canopy_geometry import PlantParts, Sphere, Tube, diameter
from davis_ag.scene.organs import FRUIT, LEAF, ORGAN_DATA
from davis_ag.scene.plant_geometry import fruit_radius, primitive_vertices
from davis_ag.scene.plants import GrownPlant, Phenotype
from davis_ag.scene.specs import CropSpec

#: A plant with fewer fruit is drawn again (next seed), as the PlantArchitecture plants are.
MAX_DRAWS = 20


@dataclass
class PlacedPlant:
    """UUIDs of a plant's parts once in the Context.

    Attributes:
        uuids: Every primitive.
        fruits: Per fruit, its primitives (a grape cluster: all its berries).
        fruit_parts: Per fruit, per tube or sphere, its primitives (berries one by one).
        leaves: Per leaf, its primitives.
        stems: Per tube of the plant's frame (stems, trunk, canes), its primitives.
    """

    uuids: list[int]
    fruits: list[list[int]]
    fruit_parts: list[list[list[int]]]
    leaves: list[list[int]]
    stems: list[list[int]]


def _add_tube(context, tube: Tube) -> list[int]:
    from pyhelios.types import RGBcolor, vec3

    nodes = [vec3(*map(float, p)) for p in tube.nodes]
    radii = [float(r) for r in tube.radii]
    if tube.texture is not None:
        obj = context.addTubeObject(tube.subdivisions, nodes, radii, texturefile=tube.texture)
    else:
        assert tube.colour is not None  # an untextured tube is coloured
        obj = context.addTubeObject(tube.subdivisions, nodes, radii, colors=[RGBcolor(*tube.colour)] * len(nodes))
    return list(context.getObjectPrimitiveUUIDs(obj))


def _add_sphere(context, sphere: Sphere) -> list[int]:
    from pyhelios.types import RGBcolor, vec3

    obj = context.addSphereObject(
        center=vec3(*map(float, sphere.centre)),
        radius=float(sphere.radius),
        ndivs=sphere.subdivisions,
        color=RGBcolor(*sphere.colour),
    )
    return list(context.getObjectPrimitiveUUIDs(obj))


def add_parts(context, parts: PlantParts) -> PlacedPlant:
    """Add a plant's parts to the Context and label every primitive with its organ.

    Tubes and spheres become Helios objects; all leaves go in with one call of textured triangles.

    Returns:
        Where each part went.
    """
    stems = [_add_tube(context, tube) for tube in parts.tubes]
    for tube, uuids in zip(parts.tubes, stems):
        context.setPrimitiveDataUInt(uuids, ORGAN_DATA, tube.organ)
    fruit_parts = [
        [_add_tube(context, p) if isinstance(p, Tube) else _add_sphere(context, p) for p in fruit]
        for fruit in parts.fruits
    ]
    fruits = [[u for piece in fruit for u in piece] for fruit in fruit_parts]
    if fruits:
        context.setPrimitiveDataUInt([u for f in fruits for u in f], ORGAN_DATA, FRUIT)
    leaves: list[list[int]] = []
    if parts.leaves:
        triangles = np.concatenate([leaf.triangles for leaf in parts.leaves])
        uvs = np.concatenate([leaf.uvs for leaf in parts.leaves])
        faces = np.arange(3 * len(triangles), dtype=np.int32).reshape(-1, 3)
        added = list(
            context.addTrianglesFromArraysTextured(
                triangles.reshape(-1, 3).astype(np.float32),
                faces,
                uvs.reshape(-1, 2).astype(np.float32),
                parts.leaf_texture,
            )
        )
        context.setPrimitiveDataUInt(added, ORGAN_DATA, LEAF)
        bounds = np.cumsum([0] + [len(leaf.triangles) for leaf in parts.leaves])
        leaves = [added[bounds[i] : bounds[i + 1]] for i in range(len(parts.leaves))]
    uuids = [u for group in stems + fruits + leaves for u in group]
    return PlacedPlant(uuids, fruits, fruit_parts, leaves, stems)


def _sphere_radius(points: np.ndarray) -> float:
    points = np.unique(np.round(points, 7), axis=0)
    return float(np.linalg.norm(points - points.mean(axis=0), axis=1).mean())


def measure_placed(context, placed: PlacedPlant, crop: CropSpec) -> Phenotype:
    """Measure height, fruit radius and leaf length of a placed plant (see the module docstring)."""
    frame = placed.stems if crop.name == "strawberry" else placed.stems[:1]  # tomato: main stem; vine: trunk
    height = float(max(v[:, 2].max() for s in frame for v in primitive_vertices(context, s)))
    pieces = [np.concatenate(primitive_vertices(context, piece)) for fruit in placed.fruit_parts for piece in fruit]
    # A tomato or a berry is a sphere: every vertex lies at its radius from the centre (half its
    # principal extent would read a coarsely tessellated sphere a few per cent small).
    radii = [_sphere_radius(p) if crop.name != "strawberry" else fruit_radius(p) for p in pieces]
    radius = float(np.median(radii)) / crop.fruit_size_per_radius if radii else float("nan")
    unit = UNIT_LEAVES[crop.name]()
    unit_size = unit.diameter()
    sizes = [diameter(np.concatenate(primitive_vertices(context, leaf))) for leaf in placed.leaves]
    return Phenotype(
        plant_height=height, fruit_radius=radius, leaf_length=max(sizes) / unit_size if sizes else float("nan")
    )


def grow_canopy_plant(
    context, crop: CropSpec, index: int, position: tuple[float, float], target: Phenotype, seed: int
) -> GrownPlant:
    """Build one Canopy Generator plant with the phenotype drawn for it, and measure it.

    Args:
        context: The scene's Helios Context.
        crop: The crop.
        index: The plant's index in the scene.
        position: Stem position (x, y), m.
        target: The phenotype, set directly as the generator's parameters.
        seed: Seed of the plant's own random generator; a plant with fewer than
            ``crop.min_fruit`` fruit is built again from the next seed.

    Returns:
        The plant, left in the Context.
    """
    started = time.perf_counter()
    origin = np.array([position[0], position[1], 0.0])
    for draw in range(1, MAX_DRAWS + 1):
        parts = PART_BUILDERS[crop.name](target, origin, np.random.default_rng(seed))
        if len(parts.fruits) >= crop.min_fruit:
            break
        seed += 1
    else:
        raise UserError(f"{crop.name}: no plant with {crop.min_fruit}+ fruit in {MAX_DRAWS} draws")
    placed = add_parts(context, parts)
    measured = measure_placed(context, placed, crop)
    return GrownPlant(
        index=index,
        seed=seed,
        position=position,
        target=target,
        measured=measured,
        fruit_objects=[],
        uuids=placed.uuids,
        builds=draw,
        fruit_bodies=placed.fruits,
        build_s=time.perf_counter() - started,
    )

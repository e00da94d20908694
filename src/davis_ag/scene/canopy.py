"""The paper's plants: Helios's Canopy Generator strawberry, tomato and goblet vine, in Python.

Section III-A of the paper grew its plants with Helios's Canopy Generator plug-in, and Table 1 is
that plug-in's default parameters. pyhelios3d does not ship the plug-in, so this module builds the
same geometry anew (our code, written from a reading of Helios's ``plugins/canopygenerator``:
``strawberry.cpp``, ``tomato.cpp``, and the goblet of ``grapevine.cpp`` in the version with tile
leaves and ``getVariation`` jitter, current in 2023, before the 2024 rewrite that added parameter
spreads) and adds it to the Helios Context: tubes and spheres as Helios objects (so both renderers
shade them smoothly, as the plug-in's own ``addTube``/``addSphere`` are), each plant's leaves as one
bulk call of textured triangles.

What each plant is (Table 1's parameters in capitals: H height, R fruit radius, L leaf length):

- strawberry: 50 stems from the crown, each ``(0.75..1) H`` long, rising at 54-81 degrees and
  bending down, with a trifoliate leaf at its tip (cupped leaflets, L and 0.8 L long); with
  probability 0.6 a fruit (a tube 1.1 R long and R wide) floats 0.1-0.3 m out from the point 35 %
  along the stem. The plug-in's clusters also try a second and third fruit, but builds them with
  every node at one point (a tube of zero length that draws nothing; in every version we read),
  so a cluster shows one fruit, as here.
- tomato: one vertical stem H tall with eleven shoots (0.3..0.8 H long) from 40 % of its height
  up, each with a tip leaf L long and two pairs of lateral leaves; with probability 0.66 a
  cluster of 1-3 fruit (spheres of radius R) hangs 4 R below the point 25 % along the shoot.
- goblet vine: a trunk H tall (radius 5 cm) and two opposite fans of ten canes from its head,
  from horizontal to near vertical, each with a cluster of grape berries (radius R, about 100
  per cluster) near its base and leaves up to L wide along it, each hanging from its stalk
  (stalk end above the tip and next to the cane).

Textures come from pyhelios3d's assets (the plug-in's own are not shipped): see ``TEXTURES``.
Every primitive carries its organ class (:mod:`davis_ag.scene.organs`).
"""

from __future__ import annotations

import math
from pathlib import Path
from typing import TypedDict

import numpy as np

from davis_ag.errors import UserError
from davis_ag.scene.canopy_geometry import (
    LeafMesh,
    PlantParts,
    Sphere,
    Tube,
    bent_shoot,
    cart2sphere,
    cupped_leaflet,
    final_elevation,
    flat_tile,
    interpolate_tube,
    rotate_about_line,
    rotate_point,
    sphere2cart,
)
from davis_ag.scene.organs import FRUIT, STEM, TRUNK
from davis_ag.scene.plants import Phenotype

PI = math.pi
#: Which pyhelios3d asset stands for each texture of the plug-in (paths below pyhelios's
#: ``assets/build/plugins``).
TEXTURES = {
    "strawberry_leaf": "plantarchitecture/assets/textures/StrawberryLeaf.png",  # StrawberryLeaf.png
    "strawberry_fruit": "plantarchitecture/assets/textures/StrawberryFruitTexture.jpg",  # StrawberryTexture.jpg
    "tomato_leaf": "plantarchitecture/assets/textures/TomatoLeaf.png",  # TomatoLeaf_big.png
    "grape_leaf": "plantarchitecture/assets/textures/GrapeLeaf.png",  # GrapeLeaf.png
    "wood": "visualizer/textures/wood.jpg",  # wood.jpg
}
#: Where the grape leaf texture's stalk (the petiole's junction) and tip lie, in texture
#: coordinates, read off ``GrapeLeaf.png`` (the same picture as the plug-in's): the stalk at
#: 27 % of the width from the left, the main lobe's tip at the right edge, both on the midline.
GRAPE_LEAF_STALK_UV = (0.27, 0.5)
GRAPE_LEAF_TIP_UV = (0.98, 0.5)


class StrawberryParameters(TypedDict):
    """:data:`STRAWBERRY`'s keys: counts are whole numbers, sizes (m) and chances floats."""

    stems: int
    clusters_per_stem: float
    stem_radius: float
    subdivisions: int
    fruit_subdivisions: int


class TomatoParameters(TypedDict):
    """:data:`TOMATO`'s keys."""

    subdivisions: int
    fruit_subdivisions: int
    stem_radius: float
    shoot_radius: float


class GobletParameters(TypedDict):
    """:data:`GOBLET`'s keys."""

    trunk_radius: float
    cordon_height: float
    shoot_length: float
    shoot_radius: float
    shoots_per_cordon: int
    leaf_spacing_fraction: float
    cluster_radius: float
    cluster_height_max: float
    grape_subdivisions: int
    wood_subdivisions: int


#: The plug-in's defaults that Table 1 does not list (``CanopyGenerator.cpp``'s constructors).
STEM_COLOUR = (0.35, 0.45, 0.2)
TOMATO_COLOUR = (0.7, 0.28, 0.2)
GRAPE_COLOUR = (0.18, 0.2, 0.25)
STRAWBERRY: StrawberryParameters = {
    "stems": 50,
    "clusters_per_stem": 0.6,
    "stem_radius": 0.005,
    "subdivisions": 10,
    "fruit_subdivisions": 12,
}
TOMATO: TomatoParameters = {"subdivisions": 10, "fruit_subdivisions": 8, "stem_radius": 0.02, "shoot_radius": 0.005}
GOBLET: GobletParameters = {
    "trunk_radius": 0.05,
    "cordon_height": 0.9,
    "shoot_length": 0.9,
    "shoot_radius": 0.0025,
    "shoots_per_cordon": 10,
    "leaf_spacing_fraction": 0.6,
    "cluster_radius": 0.03,
    "cluster_height_max": 0.1,
    "grape_subdivisions": 8,
    "wood_subdivisions": 10,
}
#: Strawberry fruit: heights of the tube's nodes and their radii, in units of R.
STRAWBERRY_PROFILE = ((0.6, 1e-3), (0.45, 0.4), (0.3, 0.5), (0.1, 0.45), (-0.2, 0.2), (-0.4, 0.15), (-0.5, 1e-3))
#: Tomato shoots: where they leave the stem, as fractions of its length.
TOMATO_SHOOTS = (0.4, 0.5, 0.6, 0.65, 0.7, 0.75, 0.8, 0.85, 0.9, 0.95, 1.0)
#: Tomato lateral leaves: (fraction along the shoot, size as a fraction of L).
TOMATO_LATERALS = ((0.9, 0.3), (0.8, 0.85), (0.6, 0.3), (0.45, 0.75))


def texture_path(key: str) -> str:
    """Absolute path of a texture of :data:`TEXTURES`."""
    import pyhelios

    path = Path(pyhelios.__file__).parent / "assets/build/plugins" / TEXTURES[key]
    if not path.exists():
        raise UserError(f"pyhelios3d lacks its texture {path}: reinstall pyhelios3d")
    return str(path)


def vary(rng: np.random.Generator, spread: float) -> float:
    """The plug-in's ``getVariation``: uniform in [-spread, spread]."""
    return float(rng.uniform(-spread, spread))


def tapering(count: int, base: float, tip_scale: float, taper: float) -> np.ndarray:
    """Radii of a stem: ``base`` at the first node, then ``tip_scale * (1 - taper * v)`` along it.

    (The plug-in multiplies every radius after the first by the plant's height, a quirk kept here.)
    """
    radii = tip_scale * (1.0 - taper * np.arange(count) / (count - 1))
    radii[0] = base
    return radii


# ---------------------------------------------------------------------------------------------
# The three plants, as parts


def strawberry_parts(phenotype: Phenotype, origin: np.ndarray, rng: np.random.Generator) -> PlantParts:
    """A Canopy Generator strawberry at ``origin`` (see the module docstring)."""
    height, radius, leaf = phenotype.plant_height, phenotype.fruit_radius, phenotype.leaf_length
    parts = PlantParts(leaf_texture=texture_path("strawberry_leaf"))
    leaflet = cupped_leaflet()
    stems = STRAWBERRY["stems"]
    fruit_texture = texture_path("strawberry_fruit")
    for i in range(stems):
        order = i / (stems - 1)
        base = origin + sphere2cart(0.1 * rng.random() * height, 0.0, 2 * PI * rng.random())
        direction = sphere2cart(1.0, 0.45 * PI - 0.15 * PI * order, 2 * PI * rng.random())
        bend = 0.3 * PI * order
        length = (0.75 + 0.25 * (1 - order)) * height * (0.9 + 0.2 * rng.random())
        nodes = bent_shoot(base, direction, length, bend, STRAWBERRY["subdivisions"])
        radii = tapering(len(nodes), STRAWBERRY["stem_radius"], STRAWBERRY["stem_radius"] * height, 0.8)
        parts.tubes.append(Tube(nodes, radii, STEM, STRAWBERRY["subdivisions"], colour=STEM_COLOUR))
        azimuth = cart2sphere(direction)[2]
        tilt = 0.75 * (0.6 * PI - final_elevation(direction, bend))
        size = np.array([leaf, 0.8 * leaf, leaf])
        for scale, turn in ((1.0, 0.5 * PI), (0.8, -0.05 * PI), (0.8, 1.05 * PI)):
            parts.leaves.append(leaflet.transformed(scale * size, [(tilt, "y"), (-azimuth + turn, "z")], nodes[-1]))
        if rng.random() < STRAWBERRY["clusters_per_stem"]:
            centre = interpolate_tube(nodes, 0.35) + sphere2cart(0.1 + 0.2 * rng.random(), 0.0, 2 * PI * rng.random())
            profile = np.array(STRAWBERRY_PROFILE) * radius
            fruit_nodes = centre + np.outer(profile[:, 0], [0.0, 0.0, 1.0])
            parts.fruits.append(
                [Tube(fruit_nodes, profile[:, 1], FRUIT, STRAWBERRY["fruit_subdivisions"], texture=fruit_texture)]
            )
    return parts


def _tomato_lateral_leaves(nodes: np.ndarray, fraction: float, size: float) -> list[LeafMesh]:
    """A pair of lateral leaves either side of a shoot, ``fraction`` of the way along it."""
    down = 0.1 * PI
    r0 = interpolate_tube(nodes, fraction)
    _, elevation, azimuth = cart2sphere(interpolate_tube(nodes, min(1.0, 1.01 * fraction)) - r0)
    tile = flat_tile(size, 0.5 * size, 4, 3, flip=True)
    side = 0.6 * size * np.array([math.cos(-azimuth), math.sin(-azimuth), 0.0])
    drop = np.array([0.0, 0.0, 0.3 * size * math.sin(down)])
    return [
        tile.transformed(np.ones(3), [(elevation, "x"), (down, "y"), (-azimuth, "z")], r0 + side - drop),
        tile.transformed(np.ones(3), [(elevation, "x"), (down, "y"), (-azimuth + PI, "z")], r0 - side - drop),
    ]


def tomato_parts(phenotype: Phenotype, origin: np.ndarray, rng: np.random.Generator) -> PlantParts:
    """A Canopy Generator tomato at ``origin`` (see the module docstring)."""
    height, radius, leaf = phenotype.plant_height, phenotype.fruit_radius, phenotype.leaf_length
    parts = PlantParts(leaf_texture=texture_path("tomato_leaf"))
    subdivisions = TOMATO["subdivisions"]
    count = max(2, round(2 * height * subdivisions))
    stem = origin + np.outer(np.linspace(0.0, height, count), [0.0, 0.0, 1.0])
    parts.tubes.append(
        Tube(
            stem,
            tapering(count, TOMATO["stem_radius"], TOMATO["stem_radius"] * height, 0.9),
            STEM,
            subdivisions,
            colour=STEM_COLOUR,
        )
    )
    last = len(TOMATO_SHOOTS) - 1
    for i, at in enumerate(TOMATO_SHOOTS):
        order = i / last
        direction = sphere2cart(1.0, 0.2 * PI + 0.2 * PI * order, 2 * PI * rng.random())
        bend = 0.5 * PI + 0.2 * PI * order
        nodes = bent_shoot(interpolate_tube(stem, at), direction, (0.3 + 0.5 * order) * height, bend, subdivisions)
        radii = tapering(len(nodes), TOMATO["shoot_radius"], TOMATO["shoot_radius"] * height, 0.8)
        parts.tubes.append(Tube(nodes, radii, STEM, subdivisions, colour=STEM_COLOUR))
        theta, azimuth = final_elevation(direction, bend), cart2sphere(direction)[2]
        tip = nodes[-1] + sphere2cart(0.45 * leaf, theta, azimuth)
        parts.leaves.append(
            flat_tile(leaf, 0.5 * leaf, 4, 3, flip=True).transformed(
                np.ones(3), [(-theta, "y"), (-azimuth + 0.5 * PI, "z")], tip
            )
        )
        for fraction, size in TOMATO_LATERALS:
            parts.leaves.extend(_tomato_lateral_leaves(nodes, fraction, size * leaf))
        if rng.random() < 0.66:
            centre = interpolate_tube(nodes, 0.25) - np.array([0.0, 0.0, 4 * radius])
            turn = 2 * PI * rng.random()
            centres = [centre]
            if rng.random() < 0.75:
                centres.append(centre + sphere2cart(1.5 * radius, 0.0, turn))
            if rng.random() < 0.5:
                centres.append(centre + sphere2cart(1.5 * radius, 0.0, turn + 0.5 * PI))
            for c in centres:  # each tomato of a cluster is a fruit of its own
                parts.fruits.append([Sphere(c, radius, TOMATO_COLOUR, TOMATO["fruit_subdivisions"])])
    return parts


def grape_cluster(top: np.ndarray, berry: float, cluster: float, rng: np.random.Generator) -> list[Sphere]:
    """The plug-in's grape cluster: rings of berries, widest near the top, 9-13 rings deep."""
    berries: list[Sphere] = []
    z, theta, ring, count, per_ring = float(top[2]), 0.0, cluster, 0, 100
    levels = int(13 - 4 * rng.random())
    while (per_ring > 3 or count < 3) and count < levels:
        if count < 3:
            ring = cluster * 0.5 ** (2 - count)
        elif count == 3:
            ring = cluster
        per_ring = math.floor(PI * ring / berry) + 1
        step = 2 * PI / per_ring
        for _ in range(per_ring):
            jitter = rng.random(3) * 0.25 * berry
            centre = np.array([top[0] + ring * math.sin(theta), top[1] + ring * math.cos(theta), z]) + jitter
            berries.append(Sphere(centre, berry, GRAPE_COLOUR, max(2, GOBLET["grape_subdivisions"])))
            theta += step
        z -= 1.8 * berry
        theta += 0.5 * step
        ring = ring * 0.85 + rng.random() * ring * 0.15
        count += 1
    return berries


def _goblet_leaves(cane: np.ndarray, origin: np.ndarray, width: float, rng: np.random.Generator) -> list[LeafMesh]:
    """Leaves along a cane from its tip down, growing from 0.1 to nearly ``width`` wide.

    As the 2023 plug-in places them, with the 2023 core's conventions: the prototype tile is made
    turned half a turn about z (``make_SphericalCoord(0, M_PI)``), so its stalk end (texture u
    small, :data:`GRAPE_LEAF_STALK_UV`) starts on +x; the tilt about y then lifts the stalk end
    above the tip; ``CompoundObject::rotate`` about z turns by ``-Rphi``, which points the stalk
    end back at the cane; and the leaf sits at ``pos_leaf - leaf_offset``, on the side of the cane
    opposite the offset.
    """
    leaves = []
    tile = flat_tile(1.0, 1.0, flip=True)
    flip = 1 if rng.random() < 0.5 else 0
    fraction = 1.0
    while fraction > 0.5 * width:  # the plug-in compares the fraction with half the leaf width
        size = max(width * (1.0 - math.exp(-5.0 * (1.0 - fraction))), 0.1 * width)
        at = interpolate_tube(cane, fraction)
        normal = interpolate_tube(cane, max(0.0, fraction - 0.001)) - at
        normal /= max(np.linalg.norm(normal), 1e-12)
        offset = rotate_about_line(
            np.array([0.0, size * (0.3 + vary(rng, 0.25)), 0.0]),
            np.zeros(3),
            normal,
            flip * PI + rng.random() * 0.25 * PI,
        )
        side = 1.0 if flip % 2 == 0 else -1.0
        r_phi = -side * 0.5 * PI * (1.0 + vary(rng, 0.4))
        r_theta = 0.4 * PI * (1.0 + vary(rng, 0.1))
        leaves.append(
            tile.transformed(np.array([size, size, 1.0]), [(-r_theta, "y"), (-r_phi, "z")], origin + at - offset)
        )
        fraction -= GOBLET["leaf_spacing_fraction"] * size * (1.0 + vary(rng, 0.25))
        flip += 1
    return leaves


def goblet_vine_parts(phenotype: Phenotype, origin: np.ndarray, rng: np.random.Generator) -> PlantParts:
    """A Canopy Generator goblet vine at ``origin`` (see the module docstring)."""
    trunk_height, berry, width = phenotype.plant_height, phenotype.fruit_radius, phenotype.leaf_length
    parts = PlantParts(leaf_texture=texture_path("grape_leaf"))
    wood, wood_subdivisions = texture_path("wood"), GOBLET["wood_subdivisions"]
    trunk = origin + np.outer([0.0, 0.2, 0.22, 0.6, 0.96, 1.0], [0.0, 0.0, trunk_height])
    trunk_radii = GOBLET["trunk_radius"] * np.array([0.75, 0.8, 1.0, 0.7, 0.95, 0.1])
    parts.tubes.append(Tube(trunk, trunk_radii, TRUNK, wood_subdivisions, texture=wood))
    canes = GOBLET["shoots_per_cordon"]
    cordon_height = GOBLET["cordon_height"]
    for side in (0, 1):
        for j in range(1, canes + 1):
            top = (cordon_height + GOBLET["shoot_length"]) * (1.0 + 0.55 * (1.0 - j / canes))
            theta0 = 0.5 * PI * (1.0 - (j - 1) / canes)
            theta_end = (0.1 - rng.random()) * 0.2
            segments = 2 * wood_subdivisions
            dz = ((1.0 + vary(rng, 0.1)) * top - cordon_height) / segments
            nodes = [np.array([0.0, 0.0, trunk_height])]
            for k in range(1, segments):
                step = rotate_point(
                    np.array([0.0, 0.0, dz]), theta0 + (theta_end - theta0) * k / (segments - 1), PI * side
                )
                nodes.append(nodes[-1] + step + np.array([vary(rng, 0.02), vary(rng, 0.01), 0.0]))
            cane = np.array(nodes)
            radii = np.full(len(cane), GOBLET["shoot_radius"])
            radii[-1] = 0.0
            parts.tubes.append(Tube(cane + origin, radii, TRUNK, wood_subdivisions, texture=wood))
            at = interpolate_tube(cane + origin, 0.035 + (GOBLET["cluster_height_max"] - 0.035) * rng.random())
            sign = -1.0 if rng.random() < 0.5 else 1.0
            vary(rng, 0.1)  # the plug-in also draws an x offset, multiplied by sin(0) for an unrotated row
            offset = np.array([0.0, sign * (2 * GOBLET["cluster_radius"] + vary(rng, 0.1)), 0.0])
            parts.fruits.append(grape_cluster(at + offset, berry, GOBLET["cluster_radius"], rng))
            parts.leaves.extend(_goblet_leaves(cane, origin, width, rng))
    return parts


PART_BUILDERS = {"strawberry": strawberry_parts, "tomato": tomato_parts, "vine": goblet_vine_parts}
#: The unit leaf each crop's leaves are scaled copies of, for measuring leaf length.
UNIT_LEAVES = {
    "strawberry": lambda: cupped_leaflet().transformed(np.array([1.0, 0.8, 1.0]), [], np.zeros(3)),
    "tomato": lambda: flat_tile(1.0, 0.5, 4, 3),
    "vine": lambda: flat_tile(1.0, 1.0),
}

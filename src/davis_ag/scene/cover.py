"""The floor between the rows: a grass cover crop in the alleys of orchards and vineyards.

Growers keep a vegetation-free strip under the trees or vines and a sod or cereal cover in the
alleys between the rows, the "most widely adopted method of orchard floor management" (Utah State
University's Intermountain Fruit, "Orchard floor management systems": a vegetation-free zone of
2.5-3 ft on each side of the tree row, 5-6 ft in all, grass in the alley); a vineyard's under-vine
strip is narrower (a 7 ft row spacing with 3 ft tilled rows and 4 ft grass lanes; Virginia Tech
SPES-209, "Floor management strategies for Virginia vineyards", cover in the row middles).

The alley's sward is a tile of Helios's grass photograph over each covered strip; on it stand
tufts grown from Helios's plant library: the cereal ``wheat`` a week or so after
emergence (0.15-0.23 m: a grass alley between mowings, and the cereal cover crops that
vineyards sow), with one spot in twenty a weed of the library (``cheeseweed``, a mallow, or
``bindweed``). A handful of prototypes are grown, then copied to spots on a jittered grid across
each alley's covered part, each turned about its foot: a cover of thousands of tufts costs a few
growths. Every primitive is labelled organ class ``cover``; the robots brush through it as they do
leaves. Each random choice (spots, turns, the prototypes' Helios seeds) comes from the scene's
cover stream (:data:`davis_ag.seeds.COVER_STREAM`), so the crop's plants, the sun and the
cameras are drawn exactly as in a scene without cover. Lengths are metres, angles degrees.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Final

import numpy as np

from davis_ag.scene.crop_spec import CropSpec, RowSpec
from davis_ag.scene.organs import COVER


@dataclass(frozen=True)
class FloorSystem:
    """How a crop's floor is kept.

    Attributes:
        name: The system in words.
        bare_strip: Width of the vegetation-free strip along each row (both sides together).
        source: Where the width comes from.
    """

    name: str
    bare_strip: float
    source: str


ORCHARD: Final = FloorSystem(
    "grass alleys, a vegetation-free strip under the trees",
    1.6,
    "Intermountain Fruit (Utah State University), orchard floor management: 5-6 ft strip",
)
VINEYARD: Final = FloorSystem(
    "cover crop in the row middles, a bare strip under the vines",
    0.9,
    "Virginia Tech SPES-209 (cover in the row middles); a 3 ft tilled vine row in 7 ft rows",
)

#: The crops whose rows stand in a covered alley, by crop name (the greenhouse and bed crops
#: have none: their floors are covered or bare).
FLOOR_SYSTEMS: dict[str, FloorSystem] = {
    **{name: ORCHARD for name in ("apple", "apple-wall", "almond", "olive", "pistachio", "walnut")},
    **{name: VINEYARD for name in ("vine", "vsp-vine", "wye-vine")},
}

#: Library model, age in days: the prototypes. Wheat at 7-9 days is 0.15-0.23 m high with
#: 400-470 primitives; cheeseweed at 40 days a rosette of 0.1 m, bindweed at 10 days a runner of
#: 0.3 m, each 900-4,900 primitives (measured on this machine, a few seeds each).
GRASS: Final = (("wheat", 7.0), ("wheat", 8.0), ("wheat", 9.0))
WEEDS: Final = (("cheeseweed", 40.0), ("bindweed", 10.0))
#: Share of spots that are a weed instead of a grass tuft.
WEED_SHARE: Final = 0.05
#: Distance between the spots' grid points; each spot moves up to half of it either way.
SPACING: Final = 0.35
#: The sward's photograph, shipped with Helios's visualizer (a mixed grass sward seen from above).
SWARD_TEXTURE: Final = "grass2.jpg"
#: Height of the sward above the soil, m: under the renderer's ground tolerance (1 mm).
SWARD_HEIGHT: Final = 0.0008


@dataclass(frozen=True)
class Spot:
    """Where one tuft stands.

    Attributes:
        x: Along the row.
        y: Across the rows.
        yaw: Its turn about its foot.
        prototype: Index into ``GRASS + WEEDS``.
    """

    x: float
    y: float
    yaw: float
    prototype: int


def covered_strips(row: RowSpec, system: FloorSystem) -> list[tuple[float, float]]:
    """The covered part of each alley of a ``row`` scene (between its three rows and outside
    them, as the heating pipes of a greenhouse): ``(y_low, y_high)``, low to high."""
    half_width = (row.row_spacing - system.bare_strip) / 2
    return [(k * row.row_spacing - half_width, k * row.row_spacing + half_width) for k in (-1.5, -0.5, 0.5, 1.5)]


def cover_length(row: RowSpec) -> float:
    """Half the covered stretch along the row: the planted stretch and half a spacing beyond it,
    as far as the structures reach."""
    return (row.plants + 2) * row.in_row_spacing / 2


def cover_spots(row: RowSpec, system: FloorSystem, rng: np.random.Generator) -> list[Spot]:
    """Every tuft of a ``row`` scene's cover: a grid of :data:`SPACING` over each alley's covered
    strip, each point jittered within its cell, turned at random, a weed one time in twenty.

    Args:
        row: The crop's row.
        system: Its floor system.
        rng: The cover's stream.

    Returns:
        The spots, alley by alley, along x within an alley.
    """
    half = cover_length(row)
    xs = np.arange(-half + SPACING / 2, half, SPACING)
    spots: list[Spot] = []
    for low, high in covered_strips(row, system):
        ys = np.arange(low + SPACING / 2, high, SPACING)
        if ys.size == 0:
            continue
        gx, gy = np.meshgrid(xs, ys, indexing="xy")
        n = gx.size
        jitter = rng.uniform(-SPACING / 2, SPACING / 2, size=(n, 2))
        x = np.clip(gx.ravel() + jitter[:, 0], -half, half)
        y = np.clip(gy.ravel() + jitter[:, 1], low, high)
        yaw = rng.uniform(0.0, 360.0, size=n)
        weed = rng.random(n) < WEED_SHARE
        kind = np.where(weed, len(GRASS) + rng.integers(len(WEEDS), size=n), rng.integers(len(GRASS), size=n))
        spots += [Spot(float(a), float(b), float(c), int(d)) for a, b, c, d in zip(x, y, yaw, kind, strict=True)]
    return spots


def floor_system(scenario_name: str, crop: CropSpec, setting: str) -> FloorSystem | None:
    """A scene's floor system: its crop's in a ``row`` scene with structures, else none."""
    if setting == "none" or scenario_name != "row" or crop.row is None:
        return None
    return FLOOR_SYSTEMS.get(crop.name)


def add_sward(context, row: RowSpec, system: FloorSystem, texture: str) -> list[int]:
    """Lay the sward under the tufts: each alley's covered strip a tile of Helios's grass
    photograph, one texture per metre patch (as the near soil keeps its grain), labelled ``cover``.

    It lies :data:`SWARD_HEIGHT` above the soil, within the renderer's ground tolerance, so it
    receives shadows and casts none, as the soil does.

    Args:
        context: The scene's Context.
        row: The crop's row.
        system: Its floor system.
        texture: Path of the grass image.

    Returns:
        The primitives added.
    """
    from pyhelios.types import int2, vec2, vec3

    from davis_ag.scene.organ_labels import object_primitives, set_organ

    half = cover_length(row)
    tiles = [
        context.addTileObject(
            center=vec3(0.0, (low + high) / 2, SWARD_HEIGHT),
            size=vec2(2 * half, high - low),
            subdiv=int2(max(1, round(2 * half)), max(1, round(high - low))),
            texturefile=texture,
        )
        for low, high in covered_strips(row, system)
        if high > low
    ]
    uuids = object_primitives(context, tiles)
    set_organ(context, uuids, COVER)
    return uuids


def add_cover(
    context, row: RowSpec, system: FloorSystem, rng: np.random.Generator, sward_texture: str | None = None
) -> list[int]:
    """Lay the sward (:func:`add_sward`), grow the prototypes and copy them to every spot of the
    cover, labelled ``cover``.

    Args:
        context: The scene's Context (its plants already grown: the Helios generator is reseeded).
        row: The crop's row.
        system: Its floor system.
        rng: The cover's stream.
        sward_texture: The sward's grass image (:data:`SWARD_TEXTURE`, found by the caller); no
            sward where ``None``.

    Returns:
        The primitives added, the sward's first (the prototypes, grown at the origin, are deleted).
    """
    from pyhelios import PlantArchitecture
    from pyhelios.types import vec3

    from davis_ag.scene.organ_labels import set_organ
    from davis_ag.scene.plants import helios_seed, quiet_stdout

    swards = add_sward(context, row, system, sward_texture) if sward_texture is not None else []
    spots = cover_spots(row, system, rng)
    architecture = PlantArchitecture(context)
    architecture.disableMessages()
    prototypes: list[list[int]] = []
    for model, age in GRASS + WEEDS:
        context.seedRandomGenerator(helios_seed(rng))
        with quiet_stdout():
            architecture.loadPlantModelFromLibrary(model)
            plant = architecture.buildPlantInstanceFromLibrary(vec3(0.0, 0.0, 0.0), age)
        prototypes.append([int(u) for u in architecture.getAllPlantUUIDs(plant)])
    uuids: list[int] = []
    up, foot = vec3(0.0, 0.0, 1.0), vec3(0.0, 0.0, 0.0)
    for spot in spots:  # copies of the prototypes, which stay at the origin until the end
        tuft = [int(u) for u in np.atleast_1d(context.copyPrimitive(prototypes[spot.prototype]))]
        context.rotatePrimitive(tuft, float(np.radians(spot.yaw)), up, foot)
        context.translatePrimitive(tuft, vec3(spot.x, spot.y, 0.0))
        uuids += tuft
    context.deletePrimitive([u for proto in prototypes for u in proto])
    set_organ(context, uuids, COVER)
    return swards + uuids

"""What growers build around a row: trellis posts and wires, stakes and twine, strings and pipes.

A ``row`` scene (:class:`~davis_ag.scene.crop_spec.RowSpec`) of a crop whose growing system uses
a structure gets one, built from Helios tubes in the scene's Context, so every renderer, label and
point cloud sees it, labelled with the organ class ``structure``. The parts are plain geometry
(:class:`Part`), computed from the crop's row alone: no random draw, so a scene without them
(``--structures none``) grows exactly as before.

Dimensions come from growers' guides, cited beside each system below (docs/crops.md lists them);
where a library plant's own geometry disagrees (its canes lie lower than a guide's fruiting
wire), the wire follows the plant, so the canes rest on it, and the comment says so.

Supports stand on the row's centre line, midway between two plants every ``n`` plants (the
midpoint nearest the origin always carries one, so the cameras see it) and at both ends of the
planted stretch, half a spacing beyond the last plants, where the wires are tied off; the three
rows of a ``row`` scene each get their own. Lengths are metres.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from typing import Final, Literal, get_args

from davis_ag.errors import UserError
from davis_ag.scene.cover import floor_system
from davis_ag.scene.crop_spec import CropSpec, RowSpec
from davis_ag.scene.organs import STRUCTURE

#: ``none``: today's bare rows; ``default``: each row crop's structure (``row`` scenes only).
StructureSetting = Literal["none", "default"]
STRUCTURE_SETTINGS: tuple[str, ...] = get_args(StructureSetting)
DEFAULT_STRUCTURES: Final = "default"

Point = tuple[float, float, float]

#: Colours (RGB in 0..1): weathered wood, galvanised steel, white polypropylene twine and pipe paint.
WOOD = (0.42, 0.36, 0.29)
STEEL = (0.62, 0.63, 0.65)
TWINE = (0.86, 0.84, 0.76)
PIPE = (0.80, 0.81, 0.82)
#: High-tensile trellis wire, 12.5 gauge (2.5 mm), as the vineyard and orchard guides use.
WIRE_RADIUS = 0.00125


@dataclass(frozen=True)
class Part:
    """One piece of a structure: a tube through ``nodes``.

    Attributes:
        kind: ``post``, ``wire``, ``arm``, ``stake``, ``string`` or ``pipe`` (what it is, in words).
        nodes: The tube's centre line, at least two points.
        radius: Its radius; a square stake is a four-sided tube of this circumradius.
        colour: RGB in 0..1.
        sides: Sides of the tube's cross-section (4: a sawn stake).
    """

    kind: str
    nodes: tuple[Point, ...]
    radius: float
    colour: tuple[float, float, float]
    sides: int = 8


def check_structures(name: str) -> str:
    """The structures setting, checked.

    Raises:
        UserError: for an unknown setting.
    """
    if name not in STRUCTURE_SETTINGS:
        raise UserError(f"unknown structures {name!r}: choose {' or '.join(STRUCTURE_SETTINGS)}")
    return name


def _half_length(row: RowSpec) -> float:
    """Half the planted stretch: the segment's plants, one more at each end, half a spacing beyond."""
    return (row.plants + 2) * row.in_row_spacing / 2


def support_positions(row: RowSpec, every: int) -> list[float]:
    """Where a row's supports stand along x: midway between plants every ``every`` plants, the
    midpoint nearest the origin among them, and at both ends of the planted stretch.

    Args:
        row: The crop's row.
        every: Plants between two supports.

    Returns:
        Sorted x positions, m.
    """
    half, spacing = _half_length(row), row.in_row_spacing
    midpoints = [round(-half + k * spacing, 9) for k in range(row.plants + 3)]  # between plants, and the ends
    centre = min(range(len(midpoints)), key=lambda k: (abs(midpoints[k]), midpoints[k]))
    chosen = {k for k in range(len(midpoints)) if (k - centre) % every == 0} | {0, len(midpoints) - 1}
    return [midpoints[k] for k in sorted(chosen)]


def _line(kind: str, x0: float, x1: float, y: float, z: float, radius: float, colour) -> Part:
    return Part(kind, ((x0, y, z), (x1, y, z)), radius, colour)


def _post(x: float, y: float, height: float, radius: float, kind: str = "post", colour=WOOD, sides: int = 8) -> Part:
    return Part(kind, ((x, y, 0.0), (x, y, height)), radius, colour, sides)


def vsp_trellis(row: RowSpec, y: float) -> list[Part]:
    """A vertically shoot-positioned vineyard's trellis.

    Sources: line posts 3-4 in thick, 8 ft long set 2 ft deep (6 ft, 1.83 m, above ground), every
    21-28 ft (P. Domoto, Iowa State University, "Constructing a vineyard trellis", 2002,
    https://docslib.org/doc/9132756/constructing-a-vineyard-trellis): every fourth vine of 1.8 m,
    7.2 m. A drip-line wire about 14 in (0.36 m) up, the fruiting wire, and two pairs of catch
    wires at about 4 and 5 ft (1.22, 1.52 m), one wire of a pair each side of the posts ("The
    Organic Backyard Vineyard", http://what-when-how.com/Tutorial/topic-455tjs98/
    The-Organic-Backyard-Vineyard-63.html). The guides put the fruiting wire at 3 ft (0.91 m,
    silvercreekvineyards.com, "Trellis choice"); the library vine's canes lie at 0.80 m (its
    trunk of eight 0.1 m internodes, measured), so the wire is there, under them.
    """
    half, post_radius = _half_length(row), 0.045
    parts = [_post(x, y, 1.83, post_radius) for x in support_positions(row, 4)]
    parts.append(_line("wire", -half, half, y, 0.36, WIRE_RADIUS, STEEL))
    parts.append(_line("wire", -half, half, y, 0.80, WIRE_RADIUS, STEEL))
    for height in (1.22, 1.52):
        for side in (-1.0, 1.0):
            offset = side * (post_radius + WIRE_RADIUS)
            parts.append(_line("wire", -half, half, y + offset, height, WIRE_RADIUS, STEEL))
    return parts


def wye_trellis(row: RowSpec, y: float) -> list[Part]:
    """A divided-canopy (Wye) vineyard's trellis: posts with a cross-arm under the two cordons and
    two arms rising outwards to the catch wires.

    Sources: divided canopies (Geneva double curtain, lyre) keep their two fruiting wires 4 ft
    (1.22 m) apart, 3 to 6 ft up (silvercreekvineyards.com, "Trellis choice",
    https://silvercreekvineyards.com/trellis-choice); posts every 21-28 ft (Domoto, as
    :func:`vsp_trellis`). The library's Wye vine splits its trunk at 1.42 m into two cordons
    0.64 m apart (measured), so the cross-arm and the fruiting wires follow it; its shoots rise
    in a V to about 2.1 m and 0.9 m either side, where the arms end and carry the catch wires.
    """
    half, cordon_z, cordon_y = _half_length(row), 1.42, 0.32
    tip_z, tip_y, arm_radius = 2.1, 0.9, 0.02
    parts = []
    for x in support_positions(row, 4):
        parts.append(_post(x, y, cordon_z, 0.045))
        parts.append(Part("arm", ((x, y - cordon_y - 0.05, cordon_z), (x, y + cordon_y + 0.05, cordon_z)), 0.03, WOOD))
        for side in (-1.0, 1.0):
            nodes = ((x, y + side * cordon_y, cordon_z), (x, y + side * tip_y, tip_z))
            parts.append(Part("arm", nodes, arm_radius, STEEL))
    for side in (-1.0, 1.0):
        parts.append(_line("wire", -half, half, y + side * cordon_y, cordon_z + 0.03 + WIRE_RADIUS, WIRE_RADIUS, STEEL))
        parts.append(_line("wire", -half, half, y + side * tip_y, tip_z, WIRE_RADIUS, STEEL))
    return parts


def fruiting_wall_trellis(row: RowSpec, y: float) -> list[Part]:
    """A tall-spindle apple fruiting wall's trellis.

    Sources: line posts 3-4 in thick (0.09 m), 32-35 ft apart (every eighth tree of 1.2 m,
    9.6 m), 14 ft long set 3 ft deep (3.35 m up), five to six wires (Good Fruit Grower, "The five
    most common mistakes", https://www.goodfruit.com/the-five-most-common-mistakes/); the bottom
    wire about 2 ft (0.6 m) up, the top one 9-12 ft ("Growing Organic Orchard Fruits",
    http://what-when-how.com/Tutorial/topic-10555ph0f/Growing-Organic-Orchard-Fruits-625.html):
    five wires evenly from 0.6 to 3.3 m.
    """
    half = _half_length(row)
    parts = [_post(x, y, 3.35, 0.045) for x in support_positions(row, 8)]
    for k in range(5):
        parts.append(_line("wire", -half, half, y, 0.6 + k * (3.3 - 0.6) / 4, WIRE_RADIUS, STEEL))
    return parts


def stake_and_weave(row: RowSpec, y: float, stake_height: float, levels: int) -> list[Part]:
    """Staked field tomatoes (the Florida or basket weave).

    Sources: stakes about 1 in square, 4-8 ft long, twine woven around them (Rutgers NJAES fact
    sheet FS1102, https://njaes.rutgers.edu/FS1102/); a stake between every other plant, driven
    1 ft deep, 4 ft for determinate and 6-7 ft for indeterminate plants, the first twine 8-10 in
    up (Penn State Extension, "Stake your tomatoes", https://extension.psu.edu/stake-your-tomatoes);
    four to six tiers of twine as the plants grow (Kansas State, "Stake and weave tomatoes"):
    tiers every 8 in (0.2 m) from 9 in (0.23 m). The twine runs on both sides of the row, wrapped
    round each stake and pushed out past the stems between them.
    """
    half, stake_radius = _half_length(row), 0.0127 * 2**0.5  # a 1 in square stake's circumradius
    stakes = support_positions(row, 2)
    parts = [_post(x, y, stake_height, stake_radius, "stake", sides=4) for x in stakes]
    spacing = row.in_row_spacing
    plants = [-half + (k + 0.5) * spacing for k in range(row.plants + 2)]
    for level in range(levels):
        z = 0.23 + 0.2 * level
        for side in (-1.0, 1.0):
            points = sorted(
                [(x, 0.0135) for x in stakes] + [(x, 0.05) for x in plants],
                key=lambda p: p[0],
            )
            nodes = tuple((x, y + side * (off + 0.0015), z) for x, off in points)
            parts.append(Part("string", nodes, 0.0015, TWINE, 6))
    return parts


def high_wire_greenhouse(row: RowSpec, y: float) -> list[Part]:
    """A greenhouse's stem-trained row: every plant on a string from its foot to the crop wire
    above (the alleys' heating pipes are :func:`heating_pipes`).

    The crop wire at 3.5 m and the 2 mm twine are our choices (no guide found in time), in the
    range of high-wire houses; the wire hangs from the greenhouse's trusses, which are not built.
    """
    half, wire_z = _half_length(row), 3.5
    plants = [-half + (k + 0.5) * row.in_row_spacing for k in range(row.plants + 2)]
    parts = [_line("wire", -half, half, y, wire_z, WIRE_RADIUS * 2, STEEL)]
    parts += [Part("string", ((x, y, 0.02), (x, y, wire_z)), 0.001, TWINE, 6) for x in plants]
    return parts


def heating_pipes(row: RowSpec, alley: float) -> list[Part]:
    """A greenhouse alley's heating-pipe rail: two pipes on low stands along the alley's centre.

    Sources: the hot-water heating loop of 51 mm pipe 0.10 m above the floor between the rows
    (Influence of heating pipe placement on microclimate of greenhouses with raised-trough tomato
    production, 2006, https://acemap.info/paper/456898195); greenhouses use these floor pipes as
    the rails of their carts (vistagreenhouse.com, "Central boiler heating system"). The rail's
    gauge, 0.55 m between the pipes' centres, and a stand every 1.5 m are our choices, in the range
    of commercial pipe-rail trolleys.
    """
    half, pipe_radius, pipe_z = _half_length(row), 0.0255, 0.10
    stands = [-half + k * 1.5 for k in range(int(2 * half / 1.5) + 1)]
    parts = []
    for side in (-1.0, 1.0):
        pipe_y = alley + side * 0.275
        parts.append(_line("pipe", -half, half, pipe_y, pipe_z, pipe_radius, PIPE))
        parts += [_post(x, pipe_y, pipe_z - pipe_radius, 0.02, "stand", STEEL, 4) for x in stands]
    return parts


#: Each crop's system, by crop name: the parts of one row centred on ``y``.
SYSTEMS: dict[str, Callable[[RowSpec, float], list[Part]]] = {
    "vsp-vine": vsp_trellis,
    "wye-vine": wye_trellis,
    "apple-wall": fruiting_wall_trellis,
    # a 1 m determinate plant: 5 ft stakes (1.22 m up), five tiers of twine
    "tomato": lambda row, y: stake_and_weave(row, y, 1.22, 5),
    # a 2.4 m indeterminate plant: 7 ft stakes (1.83 m up), six tiers (the sources' most)
    "cherry-tomato": lambda row, y: stake_and_weave(row, y, 1.83, 6),
    "capsicum": high_wire_greenhouse,
}
#: Crops grown in greenhouses, whose alleys carry heating-pipe rails: by crop name, the alley's parts.
ALLEY_SYSTEMS: dict[str, Callable[[RowSpec, float], list[Part]]] = {"capsicum": heating_pipes}
#: White woven polypropylene ground cover, the floor of a greenhouse, RGB in 0..1.
GROUND_COVER = (0.86, 0.86, 0.83)
#: How far the floor cover reaches past the planted stretch and the outer alleys' rails, m.
FLOOR_MARGIN = 1.0


def greenhouse_floor(crop: CropSpec) -> tuple[float, float] | None:
    """The half-sides (x, y) of a greenhouse crop's floor cover, centred on the scene: the planted
    stretch and the three rows with their four alleys, :data:`FLOOR_MARGIN` beyond; ``None``
    for a crop grown outdoors.

    Greenhouses lay white woven ground cover over the whole floor, under the rows and the pipe
    rails, against weeds and to throw light back into the crop (the same heating-pipe house the
    rails' source describes).
    """
    if crop.name not in ALLEY_SYSTEMS or crop.row is None:
        return None
    return _half_length(crop.row) + FLOOR_MARGIN, 2 * crop.row.row_spacing + FLOOR_MARGIN


def add_greenhouse_floor(context, half_sides: tuple[float, float]) -> list[int]:
    """Lay the floor cover on the soil (0.8 mm above it, within the renderer's ground tolerance:
    it casts no shadow), labelled ``soil``: it is the ground the cameras see and the robots drive
    on (the robots' ground is their own half-space), not an obstacle.

    Args:
        context: The scene's Context.
        half_sides: :func:`greenhouse_floor`.

    Returns:
        The primitives added.
    """
    from pyhelios.types import RGBcolor, int2, vec2, vec3

    from davis_ag.scene.organ_labels import label_soil, object_primitives

    hx, hy = half_sides
    tile = context.addTileObject(
        center=vec3(0.0, 0.0, 0.0008),
        size=vec2(2 * hx, 2 * hy),
        subdiv=int2(max(1, round(2 * hx)), max(1, round(2 * hy))),  # metre patches
        color=RGBcolor(*GROUND_COVER),
    )
    label_soil(context, [tile])
    return object_primitives(context, [tile])


def structure_parts(scenario_name: str, crop: CropSpec, setting: str) -> list[Part]:
    """The structure of a scene: its row crop's system in each of its three rows, or nothing.

    Args:
        scenario_name: ``row`` scenes get structures; single- and multi-plant scenes none.
        crop: The crop (its row and its name choose the system).
        setting: ``none`` or ``default``.

    Returns:
        Every part, rows in the order of :meth:`RowSpec.stems` (centre, -y, +y).
    """
    check_structures(setting)
    system = SYSTEMS.get(crop.name)
    if setting == "none" or scenario_name != "row" or crop.row is None or system is None:
        return []
    row = crop.row
    parts = [part for y in (0.0, -row.row_spacing, row.row_spacing) for part in system(row, y)]
    alley = ALLEY_SYSTEMS.get(crop.name)
    if alley is not None:  # the alleys between the three rows and outside them
        parts += [part for k in (-1.5, -0.5, 0.5, 1.5) for part in alley(row, k * row.row_spacing)]
    return parts


def builds_something(scenario_name: str, crop: CropSpec, setting: str) -> bool:
    """Whether a scene of this setting gets a structure or a covered floor
    (:func:`davis_ag.scene.cover.floor_system`): where neither, the scene is a bare one and
    records itself as such."""
    return bool(structure_parts(scenario_name, crop, setting)) or floor_system(scenario_name, crop, setting) is not None


def add_structures(context, parts: list[Part]) -> list[int]:
    """Add a structure's parts to a Helios Context as tubes, labelled ``structure``.

    Args:
        context: The scene's Context.
        parts: :func:`structure_parts`.

    Returns:
        The primitives added.
    """
    from pyhelios.types import RGBcolor, vec3

    from davis_ag.scene.organ_labels import set_organ

    uuids: list[int] = []
    for part in parts:
        nodes = [vec3(*map(float, p)) for p in part.nodes]
        colours = [RGBcolor(*part.colour)] * len(nodes)
        obj = context.addTubeObject(part.sides, nodes, [float(part.radius)] * len(nodes), colors=colours)
        uuids += [int(u) for u in context.getObjectPrimitiveUUIDs(obj)]
    set_organ(context, uuids, STRUCTURE)
    return uuids

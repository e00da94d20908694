"""A crop's settings (:class:`CropSpec`) and its commercial row (:class:`RowSpec`): plain data.

The values live in :mod:`davis_ag.scene.specs` (the paper's three crops, Table 1) and
:mod:`davis_ag.scene.library_crops` (the crops of Helios's plant library). Lengths are metres.
"""

from __future__ import annotations

from dataclasses import dataclass

#: The paper's image size (section III-C), at which the crops' box thresholds are given.
PAPER_IMAGE_SIZE = (1280, 720)
PAPER_PIXELS = PAPER_IMAGE_SIZE[0] * PAPER_IMAGE_SIZE[1]


@dataclass(frozen=True)
class RowSpec:
    """A segment of a commercial row, its neighbours and where a harvesting robot's camera goes.

    The row runs along x through the origin; the neighbouring rows stand ``row_spacing`` away on
    both sides. The cameras drive in the two alleys along the row: on lines ``standoff`` and
    ``standoff + step`` metres from the row's centre line on each side, every ``step`` metres
    along the segment (the MP lattice, staggered), at two of three heights, with the MP grid's
    12 headings (:func:`davis_ag.scene.specs.scenario_spec`).

    Attributes:
        system: The planting system, in words (``tall spindle fruiting wall``).
        in_row_spacing: Stem to stem along the row, m.
        row_spacing: Row centre to row centre, m.
        plants: Plants along the segment the cameras drive past; one more grows at each end and
            every neighbouring row is as long, so no row ends in view.
        standoff: The inner camera line's distance from the row's centre line, m: a multiple of
            half of ``step``.
        altitudes: The three camera heights, low to high, m (the scenario uses the lowest and
            highest, as MP does).
        source: Where the spacing comes from (a citation; docs/crops.md lists them).
        step: Distance between camera positions, m (MP's 50 cm).
    """

    system: str
    in_row_spacing: float
    row_spacing: float
    plants: int
    standoff: float
    altitudes: tuple[float, float, float]
    source: str
    step: float = 0.5

    @property
    def segment_length(self) -> float:
        """Length of the segment the cameras drive along: its plants' share of the row, m."""
        return self.plants * self.in_row_spacing

    @property
    def extent(self) -> tuple[float, float]:
        """The camera lattice's extent: the segment along x, both alleys' outer lines across, m."""
        return (self.segment_length, 2 * (self.standoff + self.step))

    @property
    def exclusion_band(self) -> float:
        """Lattice lines at most this far from the row's centre line hold no camera, m."""
        return self.standoff - self.step / 2

    def stems(self) -> list[tuple[float, float]]:
        """Every plant's stem (x, y): the segment with one more plant at each end, in three rows."""
        count = self.plants + 2
        offset = (count - 1) / 2
        return [
            ((i - offset) * self.in_row_spacing, y)
            for y in (0.0, -self.row_spacing, self.row_spacing)
            for i in range(count)
        ]


@dataclass(frozen=True)
class CropSpec:
    """One crop's Table 1 defaults and the settings that follow from them.

    Attributes:
        name: Short name used on the command line (``strawberry``, ``tomato``, ``vine``).
        title: Capitalised name in published folder names (``Strawberry``...).
        plant_height: Plant height, or trunk height for the vine (Table 1), m.
        fruit_radius: Fruit radius, or single-berry radius for the vine (Table 1), m: the Canopy
            Generator's ``fruit_radius`` parameter, whose defaults Table 1 lists.
        fruit_size_per_radius: Half the mean principal extent of a fruit body (what
            :mod:`davis_ag.scene.plants` measures) per unit of ``fruit_radius``, as the Canopy
            Generator builds it. Its tomato fruit and grape berries are spheres of that radius
            (1.0); its strawberry is a tube whose widest radius is half ``fruit_radius`` and whose
            length is 1.1 ``fruit_radius``, so (0.5 + 0.5 + 0.55) / 3 (``strawberry.cpp`` of
            Helios's canopygenerator plug-in): Table 1's 2.5 cm makes a strawberry 2.5 cm wide.
        leaf_length: Leaf length (Table 1), m.
        altitudes: The three camera altitudes, low to high (Table 1), m.
        min_fruit_pixels: Visible pixels a fruit needs to get a box (section III-C), at the paper's
            1280x720 (:meth:`min_fruit_pixels_at` scales it to another size).
        exclusion_radius: Cameras at most this far from a plant's stem, measured horizontally,
            are not placed, m (section III-C: "<75cm for strawberry and <100cm for others").
        centre_height: Height of the plant's centre, which single-plant cameras aim at: half
            the plant, or the middle of the vine's canopy, m.
        mp_plants: Plants in the multi-plant row.
        mp_spacing: Distance between neighbouring plants in the multi-plant row, m.
        sp_extent: The single-plant grid's size along x and y, m (the comment above ``CROPS`` says why).
        mp_extent: The multi-plant grid's size along x and y, m.
        min_fruit: A plant with fewer fruit is regrown from the next seed.
        helios_model: The pyhelios3d PlantArchitecture model the plant starts from.
        age_days: Age the plant is grown to: old enough to bear fruit.
        row: The crop's commercial row (the ``row`` scenario); None where it has none.
        primitives_per_plant: Primitives of a typical plant (measured), for the scene-size check
            (:func:`davis_ag.scene.scene_size.check_scene_size`).
        grid_scale: The SP and MP grids' steps are Table 2's times this (the plant-library crops'
            grids are the tomato's scaled to the plant, :func:`davis_ag.scene.library_crops.scaled_crop`).
        source: ``canopy`` for the paper's three crops (Helios's Canopy Generator, or
            PlantArchitecture plants bent towards them with ``--plants architecture``); ``library``
            for the crops grown from Helios's plant library as they are
            (:mod:`davis_ag.scene.library_crops`).
    """

    name: str
    title: str
    plant_height: float
    fruit_radius: float
    leaf_length: float
    altitudes: tuple[float, float, float]
    min_fruit_pixels: int
    exclusion_radius: float
    centre_height: float
    mp_plants: int
    mp_spacing: float
    min_fruit: int
    helios_model: str
    age_days: float
    sp_extent: tuple[float, float] = (3.0, 3.0)
    mp_extent: tuple[float, float] = (7.0, 3.0)
    fruit_size_per_radius: float = 1.0
    row: RowSpec | None = None
    primitives_per_plant: int = 0
    grid_scale: float = 1.0
    source: str = "canopy"

    def min_fruit_pixels_at(self, width: int, height: int) -> int:
        """The box threshold at an image size: :attr:`min_fruit_pixels` scaled by the image area
        over the paper's 1280x720, at least 1 pixel."""
        return max(1, round(self.min_fruit_pixels * width * height / PAPER_PIXELS))

"""Plant organ classes: what every primitive of a scene is, for labels beyond fruit.

Each primitive a scene adds to the Helios Context carries the primitive data ``organ`` (an
unsigned int, one of the values below), so labels can be read back from the Context as the
renderer reads everything else: in bulk, by UUID. :meth:`SceneModel.organ_of_uuid
<davis_ag.scene.build.SceneModel>` turns it into a lookup array indexed by UUID.

Value 0 is the sky: a pixel where nothing was hit. It is never stored on a primitive. Values 6-8
(petiole, peduncle, flower) are given to the crops of Helios's plant library
(:mod:`davis_ag.scene.library_crops`), whose organs come as separate lists; the paper's three crops
keep petioles and peduncles in ``stem``, as their labels have always had them. Value 9
(structure) is what growers build around a row (:mod:`davis_ag.scene.structures`), value 10
(cover) the grass and weeds in a row scene's alleys (:mod:`davis_ag.scene.cover`).
"""

from __future__ import annotations

#: Name of the Context's per-primitive organ data (uint).
ORGAN_DATA = "organ"

SKY, SOIL, FRUIT, LEAF, STEM, TRUNK, PETIOLE, PEDUNCLE, FLOWER, STRUCTURE, COVER = 0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10

#: Class value -> (name, what it covers). The order is the value: ``ORGAN_CLASSES[v]``.
ORGAN_CLASSES: tuple[tuple[str, str], ...] = (
    ("sky", "nothing hit"),
    ("soil", "the ground"),
    ("fruit", "fruit bodies: strawberries, tomatoes, grape berries"),
    ("leaf", "leaf blades and leaflets"),
    ("stem", "green stems and shoots; the paper's crops' petioles and peduncles too"),
    ("trunk", "woody parts: trunk, scaffolds, cordons (arms) and canes"),
    ("petiole", "leaf stalks of the plant-library crops"),
    ("peduncle", "fruit and flower stalks of the plant-library crops"),
    ("flower", "flowers and flower buds of the plant-library crops"),
    ("structure", "what growers build: trellis posts, wires and arms, stakes, twine, strings, heating pipes"),
    ("cover", "the cover crop and weeds in the alleys between orchard and vineyard rows"),
)

ORGAN_NAMES: tuple[str, ...] = tuple(name for name, _ in ORGAN_CLASSES)
#: The table of a scene without structures (``--structures none``): what every scene recorded
#: before classes ``structure`` and ``cover`` existed, so such a scene's scene.json comes out as it always did.
BARE_ORGAN_NAMES: tuple[str, ...] = ORGAN_NAMES[:STRUCTURE]


def scene_organ_names(structured: bool) -> tuple[str, ...]:
    """The class table a scene records: with ``structure`` only where the scene has one."""
    return ORGAN_NAMES if structured else BARE_ORGAN_NAMES


def organ_table() -> list[dict]:
    """The class table as written to dataset.json: ``[{"value", "name", "covers"}, ...]``."""
    return [{"value": value, "name": name, "covers": covers} for value, (name, covers) in enumerate(ORGAN_CLASSES)]

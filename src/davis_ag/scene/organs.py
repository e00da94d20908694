"""Plant organ classes: what every primitive of a scene is, for labels beyond fruit.

Each primitive a scene adds to the Helios Context carries the primitive data ``organ`` (an
unsigned int, one of the values below), so labels can be read back from the Context as the
renderer reads everything else: in bulk, by UUID. :meth:`SceneModel.organ_of_uuid
<davis_ag.scene.build.SceneModel>` turns it into a lookup array indexed by UUID.

Value 0 is the sky: a pixel where nothing was hit. It is never stored on a primitive.
"""

from __future__ import annotations

#: Name of the Context's per-primitive organ data (uint).
ORGAN_DATA = "organ"

SKY, SOIL, FRUIT, LEAF, STEM, TRUNK = 0, 1, 2, 3, 4, 5

#: Class value -> (name, what it covers). The order is the value: ``ORGAN_CLASSES[v]``.
ORGAN_CLASSES: tuple[tuple[str, str], ...] = (
    ("sky", "nothing hit"),
    ("soil", "the ground"),
    ("fruit", "fruit bodies: strawberries, tomatoes, grape berries"),
    ("leaf", "leaf blades and leaflets"),
    ("stem", "green stems, shoots and petioles"),
    ("trunk", "woody parts: trunk, cordons (arms) and canes"),
)

ORGAN_NAMES: tuple[str, ...] = tuple(name for name, _ in ORGAN_CLASSES)


def organ_table() -> list[dict]:
    """The class table as written to dataset.json: ``[{"value", "name", "covers"}, ...]``."""
    return [{"value": value, "name": name, "covers": covers} for value, (name, covers) in enumerate(ORGAN_CLASSES)]

"""Whether a scene fits this machine's memory, decided before anything grows.

A scene lives three times in memory while it is drawn: Helios's Context (its primitives with
their data), our renderer's vertex arrays and the labelling tables. Measured on the 2-core
machine: a VSP vineyard row (12 vines, 3.82 million primitives) peaked at 5.8 GB grown and
10.5 GB once drawn at 640x360, 2,760 bytes a primitive (:data:`BYTES_PER_PRIMITIVE`); an apple
row (1.21 million) at 4.3 GB, which a process's own 0.8 GB (:data:`BASE_BYTES`: Python, numpy,
Helios and the GL context) beside them explains; a cherry-tomato row (24 plants, 6.2 million) at
17.8 GB, 2,853 bytes a primitive (``davis-ag bench --only crops`` measures every crop's).
"""

from __future__ import annotations

import os

from davis_ag.errors import UserError
from davis_ag.scene.crop_spec import CropSpec
from davis_ag.scene.specs import ScenarioSpec, plant_positions

#: Peak memory per primitive of a scene while it grows and is drawn, bytes (module docstring).
BYTES_PER_PRIMITIVE = 2_800
#: A scene process's memory before any primitive, bytes (module docstring).
BASE_BYTES = 800_000_000
#: Share of the machine's memory one scene may take.
MEMORY_SHARE = 0.75


def machine_memory() -> int:
    """This machine's physical memory, bytes."""
    return os.sysconf("SC_PAGE_SIZE") * os.sysconf("SC_PHYS_PAGES")


def scene_bytes(scenario: ScenarioSpec, crop: CropSpec) -> int:
    """Estimated peak memory of one scene: its plants' primitives times :data:`BYTES_PER_PRIMITIVE`,
    and the process's own :data:`BASE_BYTES`."""
    return BASE_BYTES + len(plant_positions(scenario, crop)) * crop.primitives_per_plant * BYTES_PER_PRIMITIVE


def check_scene_size(scenario: ScenarioSpec, crop: CropSpec, memory: int | None = None) -> None:
    """Refuse a scene that would not fit :data:`MEMORY_SHARE` of the machine's memory.

    Args:
        scenario, crop: The scene's kind.
        memory: The machine's memory, bytes (default: this machine's).

    Raises:
        UserError: one line: the plants, their primitives, the memory they need and what to do.
    """
    memory = machine_memory() if memory is None else memory
    needed = scene_bytes(scenario, crop)
    if needed > MEMORY_SHARE * memory:
        plants = len(plant_positions(scenario, crop))
        raise UserError(
            f"a {scenario.name} scene of {crop.name} holds {plants} plants of about "
            f"{crop.primitives_per_plant:,} primitives, needing about {needed / 1e9:.1f} GB, more than "
            f"{MEMORY_SHARE:.0%} of this machine's {memory / 1e9:.1f} GB: generate it where there is more "
            "(--executor ray on a larger machine) or choose sp or mp"
        )

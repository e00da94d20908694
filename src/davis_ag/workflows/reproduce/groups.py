"""The scenario and crop of each part of a ``davis-ag reproduce`` run, and the name each part goes
by: in the stages, ``state.json``, the models, the results files and the results page."""

from __future__ import annotations

from davis_ag.scene.library_crops import LIBRARY_CROPS

#: Table 4's two benchmarks: single-plant strawberry and multi-plant vine.
SCENARIO_CROPS: tuple[tuple[str, str], ...] = (("sp", "strawberry"), ("mp", "vine"))


#: The crops run's groups: every plant-library crop's single plant and row (docs/crops.md).
CROPS_PAIRS: tuple[tuple[str, str], ...] = tuple(
    (scenario, crop) for crop in LIBRARY_CROPS for scenario in ("sp", "row")
)


def group_key(scenario: str, crop: str) -> str:
    """The name of a scenario's scenes and all made from them (``sp-strawberry``)."""
    return f"{scenario}-{crop}"


#: The run's group of each scenario (``{"sp": "sp-strawberry", "mp": "mp-vine"}``).
GROUPS: dict[str, str] = {scenario: group_key(scenario, crop) for scenario, crop in SCENARIO_CROPS}

#: The ``mapping`` run's rows (docs/mapping.md): trellised, staked, greenhouse and orchard rows.
MAPPING_PAIRS: tuple[tuple[str, str], ...] = tuple(
    ("row", crop) for crop in ("apple-wall", "vsp-vine", "capsicum", "cherry-tomato", "olive")
)

#: The ``robot`` run's rows (docs/robot.md): a trellised wall, a vineyard and a greenhouse crop.
ROBOT_PAIRS: tuple[tuple[str, str], ...] = tuple(("row", crop) for crop in ("apple-wall", "vsp-vine", "capsicum"))

#: The ``structures`` run's rows (docs/crops.md): a fruiting wall, a VSP vineyard, a greenhouse crop
#: and, last (its row takes the most memory), a Wye vineyard.
STRUCTURE_PAIRS: tuple[tuple[str, str], ...] = tuple(
    ("row", crop) for crop in ("apple-wall", "vsp-vine", "capsicum", "wye-vine")
)

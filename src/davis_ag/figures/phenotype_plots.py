"""Plants of different phenotypes side by side (the paper's Fig. 6h-j: smaller and bigger fruit,
shorter and longer leaves, shorter and taller plants), and a scene's contact sheet.

Phenotypes are the *measured* ones in our scene.json (``plants[].phenotype_measured``); the
original download has none, so this figure needs our data. Every scene is shown from the same
viewpoint: the view whose pose is nearest to one chosen in the first scene (lowest altitude,
in front of the plant), so the plants differ and the camera does not.
"""

from __future__ import annotations

from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.data.reader import Scene, View
from davis_ag.errors import UserError
from davis_ag.figures.canvas import FORMATS, Plotted, new_figure, save_formats
from davis_ag.figures.contact_sheet import contact_sheet_figure, draw_boxes
from davis_ag.figures.visibility_plots import plant_xy

#: scene.json key -> (label, unit scale, unit) in the order of the paper's panels.
PHENOTYPES: dict[str, tuple[str, float, str]] = {
    "fruit_radius": ("fruit radius", 100.0, "cm"),
    "leaf_length": ("leaf length", 100.0, "cm"),
    "plant_height": ("plant height", 100.0, "cm"),
}


def measured(scene: Scene) -> dict[str, float]:
    """A scene's measured phenotypes, averaged over its plants (one plant in SP scenes).

    Returns:
        Key to value in metres; empty without scene.json.
    """
    values: dict[str, list[float]] = {}
    for plant in scene.metadata.plants if scene.metadata else []:
        for key, value in (plant.phenotype_measured or {}).items():
            if isinstance(value, (int, float)):
                values.setdefault(key, []).append(float(value))
    return {k: float(np.mean(v)) for k, v in values.items()}


def front_view(scene: Scene, like: tuple[float, ...] | None = None) -> View:
    """The view to compare plants by: nearest to ``like``'s pose, else the lowest-altitude view
    nearest to the spot in front of (south of) the first plant.

    Raises:
        UserError: when no view has a pose.
    """
    posed = [v for v in scene.views.values() if v.pose is not None]
    if not posed:
        raise UserError(f"{scene.annotations_path}: no view has a pose")
    if like is not None:
        return min(posed, key=lambda v: float(np.linalg.norm(np.subtract(_pose(v)[:3], like[:3]))))
    low = min(_pose(v)[2] for v in posed)
    px, py = (plant_xy(scene) or [(0.0, 0.0)])[0]
    bottom = [v for v in posed if abs(_pose(v)[2] - low) < 0.01]
    # In front: as close to due south of the plant as the grid allows, nearest first.
    return min(
        bottom,
        key=lambda v: (
            _pose(v)[1] > py,
            abs(_pose(v)[0] - px) + abs(_pose(v)[1] - py),
            v.name,
        ),
    )


def _pose(view: View) -> tuple[float, ...]:
    """The pose of a view known to have one."""
    assert view.pose is not None
    return view.pose


def plot_phenotypes(
    scenes: list[Scene], out: str | Path, formats: tuple[str, ...] = FORMATS, sheet_of: Scene | None = None
) -> Plotted:
    """For each phenotype, the scenes with the smallest and the largest value side by side, and
    a contact sheet of one scene (``<out>_contact_sheet``).

    Args:
        scenes: The scenes to choose from (ours: they need scene.json).
        out: Output path without suffix.
        formats: File formats to write.
        sheet_of: The scene of the contact sheet (default: the first).

    Returns:
        The paths (phenotypes first, then the contact sheet) and ``{"phenotypes": {key:
        {"smallest": {"scene", "value", "view"}, "largest": {...}}}, "contact_sheet": scene}``.

    Raises:
        UserError: when no scene has measured phenotypes.
    """
    values = {s.id: measured(s) for s in scenes}
    keys = [k for k in PHENOTYPES if any(k in v for v in values.values())]
    if not keys:
        raise UserError(
            f"{scenes[0].path.parent.parent if scenes else 'dataset'}: no scene.json with "
            "measured phenotypes (the original download has none); give a dataset made "
            "by `davis-ag generate`"
        )
    reference = front_view(scenes[0]).pose
    figure = new_figure(8.0, 2.5 * len(keys) + 0.5)
    chosen: dict[str, Any] = {}
    for row, key in enumerate(keys):
        having = sorted((s for s in scenes if key in values[s.id]), key=lambda s: (values[s.id][key], s.id))
        label, scale, unit = PHENOTYPES[key]
        chosen[key] = {}
        for col, (end, scene) in enumerate((("smallest", having[0]), ("largest", having[-1]))):
            view = front_view(scene, reference)
            ax = figure.add_subplot(len(keys), 2, row * 2 + col + 1)
            ax.imshow(view.image(), interpolation="nearest")
            draw_boxes(ax, view, labels=False)
            value = values[scene.id][key]
            ax.set_title(f"{end} {label}: {value * scale:.1f} {unit}\n{scene.id} {view.name}", fontsize=8)
            ax.set_axis_off()
            chosen[key][end] = {"scene": scene.id, "value": value, "view": view.name}
    figure.suptitle(f"measured phenotypes, {len(scenes)} scene(s)", fontsize=9)
    figure.tight_layout()
    paths = save_formats(figure, out, formats)
    sheet = sheet_of or scenes[0]
    base = Path(out).with_suffix("") if Path(out).suffix in (".png", ".svg") else Path(out)
    paths += save_formats(contact_sheet_figure(sheet), base.with_name(f"{base.name}_contact_sheet"), formats)
    return Plotted(paths, {"phenotypes": chosen, "contact_sheet": sheet.id})

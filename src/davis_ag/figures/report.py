"""Figures and a plain HTML report of a dataset and its benchmark (``davis-ag demo``).

Figures (matplotlib Agg, each PNG written through a temporary file and a rename):

- the viewpoint grid per altitude, coloured by the number of boxed fruit (like the paper's
  Fig. 2), from annotations.json poses;
- the distribution of the object exposure rate (OER, eq. 1) over every box (like Fig. 5b), from
  the environment's observation cache (built from the masks when missing);
- the contact sheet and an image beside its instance mask (:mod:`davis_ag.figures.contact_sheet`);
- the Table 4 bar chart (:func:`davis_ag.benchmark.evaluation.plot_results`).

``index.html`` links everything with relative paths, so the report folder can be moved.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import TYPE_CHECKING, Any

import numpy as np

from davis_ag.atomic_files import write_text_atomic
from davis_ag.data.reader import Scene, open_dataset
from davis_ag.errors import UserError
from davis_ag.figures.canvas import new_figure, save_figure
from davis_ag.figures.contact_sheet import draw_contact_sheet, draw_masks

if TYPE_CHECKING:
    from davis_ag.stage_timer import Timer

#: Section V-C: episodes start on a target below this OER.
START_OER = 0.4
#: Scenes whose viewpoint grid the report draws (the first ones).
MAX_GRIDS = 6


def _grid_key(scene: Scene, name: str, pose: tuple[float, ...]) -> tuple[Any, ...]:
    """The camera position a view belongs to: scene.json's grid cell, else the rounded pose."""
    meta = scene.metadata or {}
    cell = meta.get("views", {}).get(name, {}).get("grid")
    if isinstance(cell, list) and len(cell) >= 3:
        return tuple(cell[:3])
    return (round(pose[0], 1), round(pose[1], 1), round(pose[2], 2))


def draw_view_grid(scene: Scene, out_path: str | Path) -> Path:
    """Plot a scene's camera positions per altitude, coloured by the number of boxed fruit.

    Where a position has several headings (MP), the colour is the mean over its headings.

    Args:
        scene: The scene.
        out_path: The PNG to write.

    Returns:
        ``out_path`` as a Path.

    Raises:
        UserError: when no view of the scene has a pose.
    """
    cells: dict[tuple[Any, ...], list[tuple[float, float, float, int]]] = {}
    for view in scene.views.values():
        if view.pose is None:
            continue
        key = _grid_key(scene, view.name, view.pose)
        cells.setdefault(key, []).append((view.pose[0], view.pose[1], view.pose[2], len(view.boxes)))
    if not cells:
        raise UserError(f"{scene.annotations_path}: no view has a pose; cannot draw the grid")
    points = np.array([[np.mean([p[0] for p in v]), np.mean([p[1] for p in v]),
                        np.mean([p[2] for p in v]), np.mean([p[3] for p in v])] for v in cells.values()])
    altitudes = sorted({round(float(z), 2) for z in points[:, 2]})
    figure = new_figure(3.6 * len(altitudes) + 0.8, 3.6)
    vmax = max(float(points[:, 3].max()), 1.0)
    plants = [(p.get("position") or [0, 0])[:2] for p in (scene.metadata or {}).get("plants", [])]
    scatter = None
    for i, z in enumerate(altitudes):
        ax = figure.add_subplot(1, len(altitudes), i + 1)
        rows = points[np.isclose(np.round(points[:, 2], 2), z)]
        scatter = ax.scatter(rows[:, 0], rows[:, 1], c=rows[:, 3], cmap="viridis", vmin=0, vmax=vmax,
                             s=28, edgecolors="none")
        if plants:
            ax.scatter([p[0] for p in plants], [p[1] for p in plants], marker="*", s=120,
                       color="tab:red", label="plant")
        ax.set_title(f"altitude {z:.2f} m ({len(rows)} positions)", fontsize=9)
        ax.set_aspect("equal")
        ax.set_xlabel("x (m)", fontsize=8)
        if i == 0:
            ax.set_ylabel("y (m)", fontsize=8)
        ax.tick_params(labelsize=7)
    if scatter is not None:
        bar = figure.colorbar(scatter, ax=figure.axes, shrink=0.85)
        bar.set_label("boxed fruit per view", fontsize=8)
    figure.suptitle(f"{scene.id}: viewpoints, colour = visible (boxed) fruit", fontsize=9)
    return save_figure(figure, out_path)


def box_oers(scenes: list[Scene], root: Path) -> np.ndarray:
    """The OER of every box of the scenes, from the environment's cache (built if missing).

    Args:
        scenes: The scenes.
        root: Their dataset root.

    Returns:
        One float per box.
    """
    from davis_ag.benchmark.cache import load_scene_cache

    values = [np.asarray(load_scene_cache(s, root).box_oer, dtype=float) for s in scenes]
    return np.concatenate(values) if values else np.zeros(0)


def draw_oer_histogram(oers: np.ndarray, out_path: str | Path, title: str = "") -> Path:
    """Histogram of box OERs with the episode-start threshold marked.

    Args:
        oers: OER per box.
        out_path: The PNG to write.
        title: Figure title.

    Returns:
        ``out_path`` as a Path.
    """
    figure = new_figure(5.0, 3.2)
    ax = figure.add_subplot(1, 1, 1)
    ax.hist(oers, bins=np.linspace(0, 1, 21), color="tab:green", edgecolor="white")
    ax.axvline(START_OER, color="tab:red", linestyle="--", label=f"episode start: OER < {START_OER}")
    below = float(np.mean(oers < START_OER)) if len(oers) else 0.0
    ax.set_xlabel("object exposure rate (OER)")
    ax.set_ylabel("boxes")
    ax.set_title(title or f"{len(oers)} boxes, {below:.0%} below {START_OER}", fontsize=9)
    ax.legend(fontsize=8)
    figure.tight_layout()
    return save_figure(figure, out_path)


def _busiest_view(scene: Scene) -> Any:
    """The view with the most boxes, the largest total box area among those: for the mask figure."""
    return max(scene.views.values(),
               key=lambda v: (len(v.boxes), sum(b.width * b.height for b in v.boxes)))


def _table(header: list[str], rows: list[list[Any]]) -> str:
    """An HTML table with escaped cells."""
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>"
                   for row in rows)
    return f"<table><tr>{head}</tr>{body}</table>"


def _fmt(value: Any) -> str:
    return f"{value:.3f}" if isinstance(value, float) else str(value)


def phenotype_rows(scenes: list[Scene]) -> tuple[list[str], list[list[Any]]]:
    """Measured phenotypes of every plant, from scene.json.

    Args:
        scenes: The scenes.

    Returns:
        ``(header, rows)``; no rows for scenes without scene.json.
    """
    keys: list[str] = []
    plants = []
    for scene in scenes:
        for plant in (scene.metadata or {}).get("plants", []):
            measured = plant.get("phenotype_measured") or {}
            keys += [k for k in measured if k not in keys]
            plants.append((scene.id, plant, measured))
    header = ["scene", "plant", "fruit", *keys]
    rows = [[sid, plant.get("index", ""), plant.get("fruit_count", ""),
             *[_fmt(measured.get(k, "")) for k in keys]] for sid, plant, measured in plants]
    return header, rows


_STYLE = ("body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em}"
          "img{max-width:100%;border:1px solid #ccc}table{border-collapse:collapse;margin:.5em 0}"
          "td,th{border:1px solid #ccc;padding:2px 8px;text-align:right}pre{background:#f4f4f4;"
          "padding:.5em;overflow-x:auto}")


def write_report(root: Path, out_dir: Path, results: dict[str, Any] | None = None,
                 validation: str | None = None, timer: Timer | None = None,
                 generated: list[dict[str, Any]] | None = None, title: str = "DAVIS-Ag report") -> Path:
    """Draw every figure of a dataset and write ``out_dir/index.html``.

    Args:
        root: The dataset root (or group or scene folder).
        out_dir: The report folder (created).
        results: What :func:`davis_ag.benchmark.evaluation.evaluate_agents` returned, for the table and chart.
        validation: The validation summary line.
        timer: Stage timings.
        generated: Per-scene generation statistics (:func:`davis_ag.workflows.demo.generate_scenes`).
        title: Page title.

    Returns:
        The path of index.html.

    Raises:
        UserError: when ``root`` holds no dataset.
    """
    from davis_ag.benchmark.evaluation import format_table, plot_results

    dataset = open_dataset(root)
    scenes = dataset.scenes
    out_dir.mkdir(parents=True, exist_ok=True)
    first = scenes[0]
    parts = [f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
             f"<style>{_STYLE}</style></head><body><h1>{html.escape(title)}</h1>",
             f"<p>Dataset <code>{html.escape(str(dataset.root))}</code>: {len(scenes)} scene(s), "
             f"{sum(len(s.views) for s in scenes)} views.</p>"]
    if validation:
        parts.append(f"<h2>Validation</h2><pre>{html.escape(validation)}</pre>")
    if results:
        plot_results(results, out_dir / "baselines.png")
        parts.append("<h2>Benchmark (Table 4 style)</h2>"
                     f"<pre>{html.escape(format_table(results))}</pre>"
                     "<img src='baselines.png' alt='baselines bar chart'>")
        if (out_dir / "results.json").is_file():
            parts.append("<p><a href='results.json'>results.json</a> holds every session's "
                         "numbers.</p>")
    draw_contact_sheet(first, out_dir / "contact_sheet.png")
    view = _busiest_view(first)
    draw_masks(view, out_dir / "mask.png")
    parts.append(f"<h2>Views of {html.escape(first.id)}</h2><p>Evenly spread views with every "
                 "fruit box:</p><img src='contact_sheet.png' alt='contact sheet'>"
                 f"<p>View {html.escape(view.name)} ({len(view.boxes)} boxes) and its instance "
                 "mask:</p><img src='mask.png' alt='image and instance mask'>")
    parts.append("<h2>Viewpoint grids</h2><p>Camera positions per altitude; colour = boxed fruit "
                 "per view (mean over headings), star = plant (cf. Fig. 2).</p>")
    for i, scene in enumerate(scenes[:MAX_GRIDS]):
        name = f"grid_{i:03d}.png"
        draw_view_grid(scene, out_dir / name)
        parts.append(f"<img src='{name}' alt='viewpoint grid of {html.escape(scene.id)}'>")
    oers = box_oers(scenes, dataset.root)
    draw_oer_histogram(oers, out_dir / "oer.png")
    parts.append("<h2>Object exposure rate</h2><p>OER of every box over all scenes (cf. Fig. 5b); "
                 "episodes start on targets left of the dashed line.</p><img src='oer.png' alt='OER'>")
    header, rows = phenotype_rows(scenes)
    if rows:
        parts.append("<h2>Measured phenotypes (scene.json)</h2>" + _table(header, rows))
    if timer or generated:
        parts.append("<h2>Timing</h2>")
    if timer:
        parts.append(_table(["stage", "seconds", "note"],
                            [[k, f"{v:.1f}", note] for k, v, note in timer.rows()]))
    if generated:
        parts.append(_table(["scene", "views", "grow s", "s per view", "total s"],
                            [[g["scene"], g.get("views", "reused"), _fmt(g.get("grow_s", "")),
                              _fmt(g["views_s"] / g["views"]) if g.get("views") else "",
                              _fmt(g.get("total_s", ""))] for g in generated]))
    parts.append("</body></html>")
    return write_text_atomic(out_dir / "index.html", "\n".join(parts) + "\n")

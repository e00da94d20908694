"""A plain HTML report of a dataset and its benchmark (``davis-ag demo``).

Figures (matplotlib Agg, each file written through a temporary file and a rename):

- the contact sheet and an image beside its instance mask (:mod:`davis_ag.figures.contact_sheet`);
- visible fruit per camera position and altitude for the first scenes (Fig. 2,
  :func:`davis_ag.figures.visibility_plots.plot_visibility`);
- every other figure of the paper the data allows (:func:`davis_ag.figures.plots.paper_figures`,
  PNG and SVG under ``figures/``): altitude changes, OER, actions, an episode, phenotypes;
- the Table 4 bar chart (:func:`davis_ag.figures.result_charts.plot_results`).

``index.html`` links everything with relative paths, so the report folder can be moved.
"""

from __future__ import annotations

import html
from pathlib import Path
from typing import TYPE_CHECKING, Any

from davis_ag.atomic_files import write_json_atomic, write_text_atomic
from davis_ag.data.reader import Scene, open_dataset
from davis_ag.figures.contact_sheet import draw_contact_sheet, draw_masks
from davis_ag.figures.plots import KINDS, paper_figures
from davis_ag.figures.visibility_plots import plot_visibility

if TYPE_CHECKING:
    from davis_ag.stage_timer import Timer

#: Scenes whose viewpoint grid the report draws (the first ones).
MAX_GRIDS = 6


def _busiest_view(scene: Scene) -> Any:
    """The view with the most boxes, the largest total box area among those: for the mask figure."""
    return max(scene.views.values(), key=lambda v: (len(v.boxes), sum(b.width * b.height for b in v.boxes)))


def _paper_figures(root: Path, out_dir: Path, results: dict[str, Any] | None) -> str:
    """Draw the paper's figures into ``out_dir/figures`` and return their HTML section."""
    results_path = out_dir / "results.json" if results else None  # written by write_report
    drawn = paper_figures(root, out_dir / "figures", results_path, kinds=[k for k in KINDS if k != "visibility"])
    parts = [
        "<h2>Figures of the paper</h2><p>Drawn by <code>davis-ag plot KIND</code>; each as PNG and "
        "SVG with the numbers behind it as JSON in <code>figures/</code>.</p>"
    ]
    for kind, plotted in drawn.items():
        if kind == "skipped":
            continue
        parts.append(f"<h3>{html.escape(kind)}: {html.escape(KINDS[kind])}</h3>")
        for path in (p for p in plotted.paths if p.suffix == ".png"):
            rel = path.relative_to(out_dir).as_posix()
            parts.append(f"<img src='{html.escape(rel)}' alt='{html.escape(kind)}'>")
    for kind, reason in drawn["skipped"].data.items():
        parts.append(f"<p>{html.escape(kind)}: not drawn ({html.escape(reason)}).</p>")
    return "\n".join(parts)


def _table(header: list[str], rows: list[list[Any]]) -> str:
    """An HTML table with escaped cells."""
    head = "".join(f"<th>{html.escape(str(h))}</th>" for h in header)
    body = "".join("<tr>" + "".join(f"<td>{html.escape(str(c))}</td>" for c in row) + "</tr>" for row in rows)
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
        for plant in scene.metadata.plants if scene.metadata else []:
            measured = plant.phenotype_measured or {}
            keys += [k for k in measured if k not in keys]
            plants.append((scene.id, plant, measured))
    header = ["scene", "plant", "fruit", *keys]
    rows = [
        [
            sid,
            "" if plant.index is None else plant.index,
            "" if plant.fruit_count is None else plant.fruit_count,
            *[_fmt(measured.get(k, "")) for k in keys],
        ]
        for sid, plant, measured in plants
    ]
    return header, rows


_STYLE = (
    "body{font-family:sans-serif;max-width:1100px;margin:2em auto;padding:0 1em}"
    "img{max-width:100%;border:1px solid #ccc}table{border-collapse:collapse;margin:.5em 0}"
    "td,th{border:1px solid #ccc;padding:2px 8px;text-align:right}pre{background:#f4f4f4;"
    "padding:.5em;overflow-x:auto}"
)


def write_report(
    root: Path,
    out_dir: Path,
    results: dict[str, Any] | None = None,
    validation: str | None = None,
    timer: Timer | None = None,
    generated: list[dict[str, Any]] | None = None,
    title: str = "DAVIS-Ag report",
) -> Path:
    """Draw every figure of a dataset and write ``out_dir/index.html``.

    Args:
        root: The dataset root (or group or scene folder).
        out_dir: The report folder (created).
        results: What :func:`davis_ag.benchmark.evaluation.evaluate_policies` returned (as JSON), for the table and chart.
        validation: The validation summary line.
        timer: Stage timings.
        generated: Per-scene generation statistics (:func:`davis_ag.workflows.stages.generate_scenes`).
        title: Page title.

    Returns:
        The path of index.html.

    Raises:
        UserError: when ``root`` holds no dataset.
    """
    from davis_ag.benchmark.results_table import format_table
    from davis_ag.figures.result_charts import plot_results

    dataset = open_dataset(root)
    scenes = dataset.scenes
    out_dir.mkdir(parents=True, exist_ok=True)
    first = scenes[0]
    parts = [
        f"<!DOCTYPE html><html><head><meta charset='utf-8'><title>{html.escape(title)}</title>"
        f"<style>{_STYLE}</style></head><body><h1>{html.escape(title)}</h1>",
        f"<p>Dataset <code>{html.escape(str(dataset.root))}</code>: {len(scenes)} scene(s), "
        f"{sum(len(s.views) for s in scenes)} views.</p>",
    ]
    if validation:
        parts.append(f"<h2>Validation</h2><pre>{html.escape(validation)}</pre>")
    if results:
        plot_results(results, out_dir / "baselines.png")
        parts.append(
            "<h2>Benchmark (Table 4 style)</h2>"
            f"<pre>{html.escape(format_table(results))}</pre>"
            "<img src='baselines.png' alt='baselines bar chart'>"
        )
        write_json_atomic(out_dir / "results.json", results, indent=2)
        parts.append("<p><a href='results.json'>results.json</a> holds every session's and episode's numbers.</p>")
    draw_contact_sheet(first, out_dir / "contact_sheet.png")
    view = _busiest_view(first)
    draw_masks(view, out_dir / "mask.png")
    parts.append(
        f"<h2>Views of {html.escape(first.id)}</h2><p>Evenly spread views with every "
        "fruit box:</p><img src='contact_sheet.png' alt='contact sheet'>"
        f"<p>View {html.escape(view.name)} ({len(view.boxes)} boxes) and its instance "
        "mask:</p><img src='mask.png' alt='image and instance mask'>"
        "<p>Drive through the scenes with the keyboard: <code>davis-ag view "
        f"{html.escape(str(dataset.root))}</code>, then open http://127.0.0.1:8765/.</p>"
    )
    parts.append(
        "<h2>Visible fruit per camera position</h2><p>Camera positions per altitude, "
        "coloured by the fruit boxed from there (cf. Fig. 2), cross = plant.</p>"
    )
    for i, scene in enumerate(scenes[:MAX_GRIDS]):
        name = f"visibility_{i:03d}.png"
        plot_visibility(scene, out_dir / name, ("png",))
        parts.append(f"<img src='{name}' alt='visible fruit per position in {html.escape(scene.id)}'>")
    parts.append(_paper_figures(Path(root), out_dir, results))
    header, rows = phenotype_rows(scenes)
    if rows:
        parts.append("<h2>Measured phenotypes (scene.json)</h2>" + _table(header, rows))
    if timer or generated:
        parts.append("<h2>Timing</h2>")
    if timer:
        parts.append(_table(["stage", "seconds", "note"], [[k, f"{v:.1f}", note] for k, v, note in timer.rows()]))
    if generated:
        parts.append(
            _table(
                ["scene", "views", "grow s", "s per view", "total s"],
                [
                    [
                        g["scene"],
                        g.get("views", "reused"),
                        _fmt(g.get("grow_s", "")),
                        _fmt(g["views_s"] / g["views"]) if g.get("views") else "",
                        _fmt(g.get("total_s", "")),
                    ]
                    for g in generated
                ],
            )
        )
    parts.append("</body></html>")
    return write_text_atomic(out_dir / "index.html", "\n".join(parts) + "\n")

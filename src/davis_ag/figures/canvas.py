"""Matplotlib figures drawn without pyplot (no global state, safe in threads and workers),
saved atomically as PNG or SVG by the suffix of the path."""

from __future__ import annotations

from pathlib import Path
from typing import TYPE_CHECKING

from davis_ag.atomic_files import atomic_output

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def new_figure(width: float, height: float) -> Figure:
    """A blank figure of ``width`` x ``height`` inches at 100 dpi, with its own Agg canvas."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), dpi=100)
    FigureCanvasAgg(figure)
    return figure


def save_figure(figure: Figure, out_path: str | Path) -> Path:
    """Save ``figure`` to ``out_path`` atomically (format from the suffix; PNG when there is none)."""
    out = Path(out_path)
    fmt = out.suffix.lstrip(".").lower() or "png"
    with atomic_output(out, "wb") as handle:
        figure.savefig(handle, format=fmt)
    return out

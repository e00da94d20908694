"""Matplotlib figures drawn without pyplot (no global state, safe in threads and workers),
saved atomically as PNG or SVG by the suffix of the path."""

from __future__ import annotations

from dataclasses import dataclass, field
from pathlib import Path
from typing import TYPE_CHECKING, Any

from davis_ag.atomic_files import save_figure_atomic as save_figure

if TYPE_CHECKING:
    from matplotlib.figure import Figure


def new_figure(width: float, height: float) -> Figure:
    """A blank figure of ``width`` x ``height`` inches at 100 dpi, with its own Agg canvas."""
    from matplotlib.backends.backend_agg import FigureCanvasAgg
    from matplotlib.figure import Figure

    figure = Figure(figsize=(width, height), dpi=100)
    FigureCanvasAgg(figure)
    return figure


#: Formats ``davis-ag plot`` writes by default.
FORMATS: tuple[str, ...] = ("png", "svg")
#: Formats a figure's path may name by its suffix.
FIGURE_SUFFIXES: tuple[str, ...] = ("png", "svg", "pdf")


def check_figure_path(path: str | Path, flag: str) -> Path:
    """Refuse, before any work, a figure path whose suffix names no format we write.

    Raises:
        UserError: naming the flag and the formats.
    """
    from davis_ag.errors import UserError

    out = Path(path)
    if out.suffix and out.suffix.lower().lstrip(".") not in FIGURE_SUFFIXES:
        raise UserError(
            f"{flag} {out}: a figure is written as {', '.join(FIGURE_SUFFIXES)}; end the name with one of them"
        )
    return out


@dataclass
class Plotted:
    """What a plotting function drew and the numbers behind it.

    Attributes:
        paths: The files written, one per format.
        data: JSON-ready numbers the figure shows (counts, histogram bins, ...), so tests and
            readers can check the picture against the annotations.
    """

    paths: list[Path]
    data: dict[str, Any] = field(default_factory=dict)


def save_formats(figure: Figure, out: str | Path, formats: tuple[str, ...] = FORMATS) -> list[Path]:
    """Save ``figure`` once per format beside ``out`` (its suffix replaced), atomically.

    Args:
        figure: The figure.
        out: The path without (or with any) suffix, e.g. ``figures/oer``.
        formats: Suffixes to write, e.g. ``("png", "svg")``.

    Returns:
        The paths written, in the order of ``formats``.
    """
    base = Path(out)
    if base.suffix.lower().lstrip(".") in FIGURE_SUFFIXES:
        base = base.with_suffix("")
    return [save_figure(figure, base.with_name(f"{base.name}.{fmt}")) for fmt in formats]

"""Atomic writes that pages and pictures go through: measured numbers between markers, figures."""

from __future__ import annotations

from pathlib import Path

import pytest
from matplotlib.figure import Figure

from davis_ag.atomic_files import save_figure_atomic, write_marked_section
from davis_ag.errors import UserError


def test_a_marked_section_is_replaced_and_the_rest_kept(tmp_path: Path) -> None:
    doc = tmp_path / "page.md"
    doc.write_text("top\n<!-- n:start -->\nold\n<!-- n:end -->\nbottom\n<!-- m:start -->\nkeep\n<!-- m:end -->\n")
    write_marked_section(doc, "n", "| a | 1 |")
    assert doc.read_text() == (
        "top\n<!-- n:start -->\n| a | 1 |\n<!-- n:end -->\nbottom\n<!-- m:start -->\nkeep\n<!-- m:end -->\n"
    )


def test_a_page_without_the_markers_is_left_whole(tmp_path: Path) -> None:
    doc = tmp_path / "page.md"
    doc.write_text("no markers here\n")
    with pytest.raises(UserError, match="no <!-- n:start -->"):
        write_marked_section(doc, "n", "text")
    assert doc.read_text() == "no markers here\n"


def test_a_figure_is_saved_in_its_suffix_format_at_its_dpi(tmp_path: Path) -> None:
    figure = Figure(figsize=(2, 1), dpi=100)
    figure.add_subplot().plot([0, 1], [1, 0])
    png = save_figure_atomic(figure, tmp_path / "plot.png", dpi=50)
    assert png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert int.from_bytes(png.read_bytes()[16:20], "big") == 100  # 2 inches at 50 dpi
    assert save_figure_atomic(figure, tmp_path / "plot.svg").read_text().lstrip().startswith("<?xml")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["plot.png", "plot.svg"]  # no temporary left


def test_a_figure_that_cannot_be_written_is_one_clear_error(tmp_path: Path) -> None:
    (tmp_path / "taken").mkdir()  # a folder where the file should go
    with pytest.raises(UserError, match="cannot write the figure"):
        save_figure_atomic(Figure(), tmp_path / "taken")

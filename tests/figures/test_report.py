"""The report's figures and HTML, drawn from the tiny dataset factory (no Helios)."""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from davis_ag.data.reader import open_dataset
from davis_ag.errors import UserError
from davis_ag.figures.benchmark_plots import plot_oer
from davis_ag.figures.report import phenotype_rows, write_report
from davis_ag.figures.visibility_plots import plot_visibility
from davis_ag.stage_timer import Timer
from davis_ag.workflows.stages import run_baselines
from layout_factory import write_tiny_dataset

PNG_MAGIC = b"\x89PNG\r\n\x1a\n"


@pytest.fixture(scope="module")
def tiny_root(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """Two SP strawberry scenes (one train, one test) and one MP scene."""
    root = tmp_path_factory.mktemp("tiny")
    write_tiny_dataset(root, "sp", "strawberry", scenes=2)
    write_tiny_dataset(root, "mp", "strawberry", scenes=1)
    return root


def _is_png(path: Path) -> bool:
    return path.is_file() and path.read_bytes()[:8] == PNG_MAGIC


def test_report_writes_pngs_and_links_resolve(tiny_root: Path, tmp_path: Path) -> None:
    results = run_baselines(tiny_root, "sp", "strawberry", "test", episodes=4, sessions=2)
    timer = Timer()
    with timer.stage("generate"):
        pass
    out = tmp_path / "report"
    index = write_report(
        tiny_root,
        out,
        results=results.as_json(),
        validation="checked 3 scenes: sound",
        timer=timer,
        generated=[{"scene": "Single-Strawberry/000", "skipped": True}],
    )
    assert index == out / "index.html"
    text = index.read_text()
    links = re.findall(r"(?:src|href)='([^']+)'", text)
    images = [link for link in links if link.endswith(".png")]
    assert {
        "contact_sheet.png",
        "mask.png",
        "figures/oer.png",
        "baselines.png",
        "visibility_000.png",
        "figures/actions.png",
        "figures/episode.png",
        "figures/altitude.png",
    } <= set(images)
    for link in images:
        assert not link.startswith("/"), "links must be relative"
        assert _is_png(out / link), link
    assert "OER_tau" in text and "sound" in text
    assert all((out / link).is_file() for link in links)


def test_visibility_one_panel_per_altitude(tiny_root: Path, tmp_path: Path) -> None:
    for scene in open_dataset(tiny_root).scenes:
        plotted = plot_visibility(scene, tmp_path / scene.id.replace("/", "_"), ("png",))
        assert _is_png(plotted.paths[0])
        heights = sorted({round(v.pose[2], 2) for v in scene.views.values()})
        assert [panel["z"] for panel in plotted.data["altitudes"]] == heights
        # Every view lies at exactly one position of its altitude's panel.
        assert sum(len(panel["x"]) for panel in plotted.data["altitudes"]) == len(
            {tuple(round(c * 1000) for c in v.pose[:3]) for v in scene.views.values()}
        )


def test_oer_without_masks_is_one_line(tiny_root: Path, tmp_path: Path) -> None:
    scene = open_dataset(tiny_root).scenes[0]
    for view in scene.views.values():
        view.mask_path.rename(view.mask_path.with_suffix(".hidden"))
    try:
        with pytest.raises(UserError, match="masks") as error:
            plot_oer([scene], tmp_path / "oer", ("png",))
        assert "\n" not in str(error.value)
    finally:
        for view in scene.views.values():
            view.mask_path.with_suffix(".hidden").rename(view.mask_path)


def test_phenotypes_without_scene_json_give_no_rows(tmp_path: Path) -> None:
    from layout_factory import write_original_style_dataset

    root = write_original_style_dataset(tmp_path / "original", "sp", "strawberry", scenes=2)
    scenes = open_dataset(root).scenes
    assert len(scenes) == 2 and all(scene.metadata is None for scene in scenes)
    header, rows = phenotype_rows(scenes)
    assert header == ["scene", "plant", "fruit"] and rows == []


def test_phenotypes_give_one_row_per_plant_of_scene_json(tiny_root: Path) -> None:
    scenes = open_dataset(tiny_root).scenes
    header, rows = phenotype_rows(scenes)
    assert header[:3] == ["scene", "plant", "fruit"]
    assert len(rows) == sum(len(scene.metadata.plants) for scene in scenes) > 0
    assert [row[0] for row in rows] == [s.id for s in scenes for _ in s.metadata.plants]
    assert all(len(row) == len(header) for row in rows)


def test_report_of_a_folder_without_a_dataset_is_a_user_error(tmp_path: Path) -> None:
    with pytest.raises(UserError) as error:
        write_report(tmp_path, tmp_path / "report")
    assert "\n" not in str(error.value)


def test_results_markdown_puts_ours_beside_the_paper(tmp_path: Path) -> None:
    from davis_ag.workflows.reproduce.configs import CONFIGS
    from davis_ag.workflows.reproduce.pages.results import write_results_md
    from davis_ag.workflows.reproduce.state import RunState, StageRecord
    from results_factory import results

    evaluated = results(dict.fromkeys(("LRD", "UDD", "Rand", "Oracle", "A2C"), 0.5), scenes=["Single-Strawberry/002"])
    state = RunState(
        results={"sp": evaluated},
        stages={"sp-strawberry: generate": StageRecord(seconds=12.0, note="1 scene")},
    )
    text = write_results_md(tmp_path / "results.md", CONFIGS["small"], state, tmp_path).read_text()
    assert "| A2C | .500 ± .010 | .520 ± .004 |" in text
    assert "## MP vine" in text and "Not evaluated yet" in text
    assert "CPU cores" in text and "| total | 12 | 0.00 | |" in text

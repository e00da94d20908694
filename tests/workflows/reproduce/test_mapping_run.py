"""The ``mapping`` run's page: written from its results files, pictures drawn, between the markers."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from davis_ag.mapping.evaluation import evaluate_mapping
from davis_ag.workflows.reproduce.configs import CONFIGS
from davis_ag.workflows.reproduce.mapping_run import SEEN_FRACTIONS, write_run_page
from davis_ag.workflows.reproduce.pages.mapping import results_name
from layout_factory import write_tiny_dataset


@pytest.fixture(scope="module")
def run_folder(tmp_path_factory: pytest.TempPathFactory) -> Path:
    out = tmp_path_factory.mktemp("run")
    data = write_tiny_dataset(out / "dataset", "mp", "vine", scenes=1)
    for fraction in SEEN_FRACTIONS:
        results = evaluate_mapping([], data, "mp", "all", 1, 4, 5, crop="vine", seen_fraction=fraction, budget=4)
        results.write(out / "results" / results_name("mp-vine", fraction))
    return out


def test_the_configuration_maps_five_rows_with_the_baselines() -> None:
    config = CONFIGS["mapping"]
    assert config.page == "mapping" and config.learners == ()
    assert {scenario for scenario, _ in config.pairs} == {"row"} and len(config.pairs) == 5
    assert config.scenes_in_words() == "1 row scene(s) of each of 5 crops"


def test_the_page_is_written_between_its_markers_with_pictures(run_folder: Path, tmp_path: Path) -> None:
    page = tmp_path / "docs" / "mapping.md"
    page.parent.mkdir()
    page.write_text(
        "# Row mapping\n\nprose kept\n\n<!-- mapping-run:start -->\nold\n<!-- mapping-run:end -->\n\ntail kept\n"
    )
    write_run_page(page, CONFIGS["mapping"], run_folder, [("mp", "vine")])
    text = page.read_text()
    assert "prose kept" in text and "tail kept" in text and "\nold\n" not in text
    assert "### The ladder" in text and "| 1 | mp-vine |" in text and "| Greedy |" in text
    assert "seen at 0.3: Greedy / Sweep / ceiling" in text
    images = page.parent / "images" / "mapping"
    assert (images / "mp-vine-curves.png").is_file()
    assert (images / "mp-vine-episode-greedy.png").is_file() and (images / "mp-vine-episode-sweep.png").is_file()
    assert "](images/mapping/mp-vine-curves.png)" in text


def test_a_page_without_markers_is_written_whole(run_folder: Path, tmp_path: Path) -> None:
    shutil.rmtree(tmp_path / "x", ignore_errors=True)
    page = tmp_path / "x" / "results.md"
    page.parent.mkdir()
    write_run_page(page, CONFIGS["mapping"], run_folder, [("mp", "vine")])
    assert page.read_text().startswith("# Row mapping\n\n<!-- mapping-run:start -->")

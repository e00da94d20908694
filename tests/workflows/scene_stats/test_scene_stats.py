"""``davis-ag scene-stats``: the views measurement beside Table 3, written into the docs pages."""

from __future__ import annotations

import shutil
from pathlib import Path

import pytest

from davis_ag import cli

DOCS = Path(__file__).parents[3] / "docs"


def test_views_are_measured_beside_table_3_and_written_into_the_pages(tmp_path: Path) -> None:
    docs = tmp_path / "docs"
    shutil.copytree(DOCS, docs, ignore=shutil.ignore_patterns("images", "transfer"))
    (docs / "data" / "scenes-views.json").unlink()
    assert cli.main(["scene-stats", "views", "--docs", str(docs)]) == 0
    # Table 3: 24,510 images over 86 SP strawberry scenes, 79,200 over 44 MP vine scenes.
    table = (docs / "dataset-format.md").read_text()
    assert "| SP, paper (Table 3) | 285 |" in table and "| MP, paper (Table 3) | 1,128 | 1,800 | 1,800 |" in table
    assert "| SP, ours | 285 | 348 | 348 |" in table
    # Each generated table once: scenes.md links to the page that holds it.
    assert "In [dataset-format.md](dataset-format.md)." in (docs / "scenes.md").read_text()
    for marked in ("| SP, ours |", "| crop | plants | fruit per plant"):
        assert sum(page.read_text().count(marked) for page in docs.glob("*.md")) == 1, marked


def test_a_folder_that_is_no_docs_folder_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert cli.main(["scene-stats", "--docs", str(tmp_path)]) != 0
    err = capsys.readouterr().err.strip()
    assert len(err.splitlines()) == 1 and "not the docs folder" in err and not list(tmp_path.iterdir())


def test_a_page_that_is_not_utf8_is_one_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """scene-stats --docs and bench --doc read pages they rewrite: Latin-1 bytes ended in a
    UnicodeDecodeError traceback."""
    docs = tmp_path / "docs"
    shutil.copytree(DOCS, docs, ignore=shutil.ignore_patterns("images", "transfer"))
    page = docs / "plants.md"
    page.write_bytes(page.read_bytes() + "caf\xe9".encode("latin-1"))
    before = page.read_bytes()
    assert cli.main(["scene-stats", "views", "--docs", str(docs)]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "not UTF-8" in err and str(page) in err and page.read_bytes() == before
    assert cli.main(["bench", "--doc", str(page), "--out", str(tmp_path / "b.json")]) == 2
    err = capsys.readouterr().err.strip()
    assert "\n" not in err and "--doc" in err and "not UTF-8" in err and not (tmp_path / "b.json").exists()


def test_bench_flags_parse_and_bad_ones_are_one_line(capsys: pytest.CaptureFixture[str]) -> None:
    args = cli.build_parser().parse_args(["bench", "--crops", "vine,strawberry", "--repeats", "2"])
    assert args.crops == ["vine", "strawberry"] and args.repeats == 2 and args.out.name == "bench.json"
    with pytest.raises(SystemExit) as stopped:
        cli.build_parser().parse_args(["bench", "--crops", "pear"])
    assert stopped.value.code == 2 and "pear" in capsys.readouterr().err


def test_plants_are_measured_for_the_generator_asked_and_the_other_crops_keep_their_rows(tmp_path: Path) -> None:
    """``plants --generators architecture`` grows PlantArchitecture plants into their own file;
    the crops not grown keep their saved rows, and the canopy file is left alone."""
    import json

    docs = tmp_path / "docs"
    shutil.copytree(DOCS, docs, ignore=shutil.ignore_patterns("images", "transfer"))
    canopy_before = (docs / "data" / "scenes-plants.json").read_text()
    saved = json.loads((docs / "data" / "scenes-plants-architecture.json").read_text())
    argv = ["scene-stats", "plants", "--crops", "strawberry", "--count", "1", "--generators", "architecture"]
    assert cli.main([*argv, "--docs", str(docs)]) == 0
    fresh = json.loads((docs / "data" / "scenes-plants-architecture.json").read_text())
    assert [p["index"] for p in fresh["crops"]["strawberry"]] == [0]  # grown anew, one plant
    assert fresh["crops"]["strawberry"][0]["build_s"] is not None  # PlantArchitecture's builds are timed
    assert fresh["crops"]["vine"] == saved["crops"]["vine"] and fresh["crops"]["tomato"] == saved["crops"]["tomato"]
    assert (docs / "data" / "scenes-plants.json").read_text() == canopy_before
    assert "| strawberry | architecture | " in (docs / "plants.md").read_text()

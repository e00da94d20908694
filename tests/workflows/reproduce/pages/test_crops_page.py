"""The crops run: its configuration, its records and docs/crops.md's tables written from them."""

from __future__ import annotations

import json
from dataclasses import asdict
from pathlib import Path

import pytest

from davis_ag.benchmark.results import EvaluationResults
from davis_ag.scene.crop_literature import LITERATURE
from davis_ag.scene.library_crops import LIBRARY_CROPS, LIBRARY_RECIPES
from davis_ag.workflows.reproduce.configs import CONFIGS
from davis_ag.workflows.reproduce.pages.crops import crops_table, ladder_rows, write_crops_md
from davis_ag.workflows.reproduce.state import RunState, run_config
from davis_ag.workflows.scene_stats.library_crops import library_crops_table, library_recipes_table
from results_factory import gap, results

CROPS_RUN = CONFIGS["crops"]


def result(best: float, oracle: float, a2c: float | None, starts: int) -> EvaluationResults:
    """A group's evaluation as reproduce keeps it in state.json."""
    oer = {"LRD": 0.4, "Rand": 0.4, "Best fixed action": best, "Oracle": oracle}
    if a2c is None:
        return results(oer, scenes=["a", "b", "c"], starts=starts)
    paired = gap(a2c - best, a2c - best - 0.01, a2c - best + 0.01)
    return results({**oer, "A2C": a2c}, {"A2C": paired}, ["a", "b", "c"], starts=starts)


def test_the_crops_run_covers_every_library_crop_alone_and_in_its_row() -> None:
    assert CROPS_RUN.pairs == tuple((s, c) for c in LIBRARY_CROPS for s in ("sp", "row"))
    assert (CROPS_RUN.scenes("sp"), CROPS_RUN.scenes("row"), CROPS_RUN.size) == (10, 4, (640, 360))
    assert CROPS_RUN.scenes_in_words() == "10 SP and 4 row scenes of each of 10 crops"
    assert CONFIGS["medium"].scenes_in_words() == "10 SP strawberry and 10 MP vine scenes"
    # state.json keeps each group's results apart (Table 4's runs keep theirs by scenario).
    assert CROPS_RUN.result_key("row", "olive") == "row-olive" and CONFIGS["small"].result_key("sp", "x") == "sp"
    # A resumed run reads its configuration back from state.json, pairs included.
    saved = RunState.model_validate(json.loads(json.dumps({"config": asdict(CROPS_RUN)})))
    assert run_config(saved, Path("state.json")) == CROPS_RUN


def test_the_table_ranks_groups_hardest_first_and_names_those_not_run(tmp_path: Path) -> None:
    state = RunState(
        results={
            "sp-olive": result(best=0.50, oracle=0.70, a2c=0.55, starts=1234),
            "row-apple": result(best=0.30, oracle=0.60, a2c=None, starts=56),
        }
    )
    table = crops_table(CROPS_RUN, state)
    rows = [line for line in table.splitlines() if line.startswith("| ") and "---" not in line][1:]
    assert [row.split(" | ")[0:2] for row in rows] == [["| apple", "row"], ["| olive", "sp"]]
    assert "1,234" in rows[1] and "+.200" in rows[1] and "+.050" in rows[1]  # headroom and A2C's gap
    assert rows[0].rstrip(" |").endswith("–")  # no learner yet: a dash, not a number
    assert "Not evaluated yet: sp-apple, " in table
    # A learner's interval is over the test episodes of its one trained model, and says so.
    assert "bootstrap interval over episodes: the one model trained, seed 0, not another training" in table
    # row-apple's 600 episodes replay its 56 starts; sp-olive's 1,234 are each drawn about once.
    assert "Few starts (row-apple: 600 episodes, 56 starts): their episodes replay" in table
    # The ladder draws the same groups in the same order, the few starts named beside their dots.
    ladder = ladder_rows(CROPS_RUN, state)
    assert [row["label"] for row in ladder] == ["apple row (56 starts)", "olive sp"]
    assert ladder[1]["learners"]["A2C"] == pytest.approx({"mean": 0.55, "low": 0.04, "high": 0.06})
    assert ladder[0]["learners"] == {} and ladder[0]["oracle"] == 0.60
    page = tmp_path / "crops.md"
    page.write_text("# Crops\n\nbefore\n<!-- crops-run:start -->\nold\n<!-- crops-run:end -->\nafter\n")
    write_crops_md(page, CROPS_RUN, state, None)
    text = page.read_text()
    assert text.startswith("# Crops\n\nbefore\n") and text.endswith("after\n") and "old" not in text
    assert "| apple | row |" in text
    # The table drawn beside it, its picture linked from the page.
    assert "![the crops run as a ladder, hardest at the top](images/crops-ladder.png)" in text
    assert (tmp_path / "images" / "crops-ladder.png").stat().st_size > 10_000
    alone = write_crops_md(tmp_path / "run.md", CROPS_RUN, state, None)  # no markers: a page of its own
    assert "Wall time per stage" in alone.read_text()
    # With the run's dataset: the share of views with a fruit boxed, the fewest fruit on a plant and
    # the median box's longer side.
    scene = tmp_path / "run" / "dataset" / "Single-Olive" / "000"
    scene.mkdir(parents=True)
    (scene / "annotations.json").write_text(
        json.dumps(
            {
                "0001.jpeg": {"bounding_boxes": [[1, 1, 2, 5, 3, 0], [9, 9, 4, 1, 4, 0]]},  # x, y, width, height
                "0002.jpeg": {"bounding_boxes": [[1, 1, 7, 6, 3, 0]]},
                "0003.jpeg": {"bounding_boxes": []},
                "0004.jpeg": {"bounding_boxes": []},
            }
        )
    )
    (scene / "scene.json").write_text(json.dumps({"plants": [{"fruit_count": 12}]}))
    state.scene_folders = {"sp-olive": ["Single-Olive/000"]}
    write_crops_md(page, CROPS_RUN, state, tmp_path / "run")
    assert "| olive | sp | 50% / 12 / 5 |" in page.read_text()  # sides 5, 4 and 7


def test_the_measured_crops_sit_beside_the_literature(tmp_path: Path) -> None:
    plant = {
        "fruit_count": 40,
        "phenotype_measured": {"plant_height": 3.6, "fruit_radius": 0.04, "leaf_length": 0.09},
        "library": {"width_m": [2.8, 2.9], "fruit_length_m": 0.081, "fruit_diameter_m": 0.079},
        "primitives": 125_000,
        "build_s": 40.0,
    }
    data = {"plants_per_crop": 2, "machine": "test", "crops": {"apple": [plant, {**plant, "fruit_count": 50}]}}
    path = tmp_path / "scenes-crops.json"
    path.write_text(json.dumps(data))
    lines = library_crops_table(path)
    (row,) = [line for line in lines if line.startswith("| apple |")]
    assert f"40-50 (median 45) [{LITERATURE['apple'].fruit_per_plant}]" in row
    assert "81-81 x 79-79 [-]" in row and "125-125K" in row
    assert any(LITERATURE["apple"].source in line for line in lines)
    assert library_crops_table(tmp_path / "missing.json") == []
    recipes = library_recipes_table()
    assert all(
        any(line.startswith(f"| {name} | {LIBRARY_RECIPES[name].model} |") for line in recipes)
        for name in LIBRARY_RECIPES
    )


def test_the_crops_bench_table_gives_each_scene_beside_the_strawberry() -> None:
    from davis_ag.workflows.bench.crops import crops_table as bench_table

    row = {
        "plants": 12,
        "primitives": 3_816_534,
        "fruit": 322,
        "views_in_scene": 768,
        "grow_s": 150.0,
        "seconds_per_view": 0.9,
        "over_strawberry": 9.0,
        "peak_gb": 10.5,
        "bytes_per_primitive": 2760,
    }
    sp = {**row, "boxes_compared": 30, "max_corner_px": 1, "boxed_by_one": 2}
    crops = {"vsp-vine": {"sp": sp, "row": row}}
    table = bench_table({"image_size": [640, 360], "views": 6, "crops": crops}, (1.0, 2.0))
    assert "| vsp-vine | row | 12 | 3,816,534 | 322 | 768 | 150 | 0.900 | 9.0 | 10.5 (11.5) | 2,760 | – |" in table
    assert "| vsp-vine | sp | 12 | 3,816,534 | 322 | 768 | 150 | 0.900 | 9.0 | 10.5 (1.7) | 2,760 | 30, 1, 2 |" in table


def test_a_crop_measured_again_alone_keeps_the_others_rows(tmp_path: Path) -> None:
    from davis_ag.workflows.bench.crops import merged

    earlier = {"image_size": [640, 360], "crops": {"wye-vine": {"sp": 1}, "apple": {"sp": 2}}}
    report = tmp_path / "bench-crops.json"
    report.write_text(json.dumps({"crops": earlier}))
    fresh = {"image_size": [640, 360], "crops": {"wye-vine": {"sp": 3}}}
    assert merged(report, fresh)["crops"] == {"apple": {"sp": 2}, "wye-vine": {"sp": 3}}  # specs.CROPS's order
    other_size = {**fresh, "image_size": [1280, 720]}
    assert merged(report, other_size)["crops"] == {"wye-vine": {"sp": 3}}
    assert merged(tmp_path / "none.json", fresh)["crops"] == fresh["crops"]


def test_the_page_gives_the_runs_wall_time_by_kind_of_stage(tmp_path: Path) -> None:
    """What a researcher plans a night by: the hours of every sitting, by kind of stage, and where
    they ran; "so far" until every group is evaluated."""
    from davis_ag.workflows.reproduce.clock import CLOCK_FILE
    from davis_ag.workflows.reproduce.state import StageRecord

    run = tmp_path / "run"
    run.mkdir()
    stages = {
        "sp-olive: generate": 5400,
        "sp-olive: validate": 360,
        "sp-olive: train A2C": 1800,
        "sp-olive: train PPO": 3600,
        "sp-olive: evaluate": 720,
    }
    state = RunState(
        results={"sp-olive": result(best=0.5, oracle=0.7, a2c=0.55, starts=99)},
        stages={stage: StageRecord(seconds=seconds, note="") for stage, seconds in stages.items()},
    )
    machine = "2 CPU cores (Some CPU), no GPU"
    sitting = {"started": "2026-11-27T12:00:00+00:00", "code": "x", "machine": machine}
    (run / CLOCK_FILE).write_text(json.dumps({"stages": {s: [{**sitting, "seconds": v}] for s, v in stages.items()}}))
    page = tmp_path / "crops.md"
    page.write_text("<!-- crops-run:start -->\n<!-- crops-run:end -->\n")
    write_crops_md(page, CROPS_RUN, state, run)
    line = "Wall time so far: **3.3 h** on the run's clock, every sitting (generate 1.5, validate 0.1, train 1.5, evaluate 0.2 h)"
    assert f"{line}, on {machine}; wall time" in page.read_text()
    state.results = {CROPS_RUN.result_key(s, c): state.results["sp-olive"] for s, c in CROPS_RUN.pairs}
    write_crops_md(page, CROPS_RUN, state, run)  # every group evaluated: the run's whole time
    assert "Wall time: **3.3 h**" in page.read_text()
    write_crops_md(page, CROPS_RUN, RunState(), run)  # nothing run yet: no line, no picture
    assert "Wall time" not in page.read_text() and "crops-ladder" not in page.read_text()

"""The bench's paper-scale projection counts the paper's dataset and adds up its costs."""

from __future__ import annotations

from pathlib import Path

import pytest

from davis_ag.workflows.bench.report import POOL_GAIN, projection

CROPS = ("strawberry", "tomato", "vine")


def test_the_projection_counts_the_papers_images_and_farms() -> None:
    report = projection({c: 1.0 for c in CROPS}, {c: 0.0 for c in CROPS})
    # Section III-D: ">502K images from over 632 virtual farms"; Table 3's counts add up to 502,542.
    assert report["images"] == 502_542 and report["scenes"] == 632
    assert report["hours_one_machine_one_process"] == pytest.approx(502_542 / 3600, abs=0.1)
    assert report["hours_one_machine"] == pytest.approx(502_542 / 3600 / POOL_GAIN, abs=0.1)


def test_the_grow_and_draw_bound_is_below_the_whole_cost() -> None:
    ours = projection(
        {c: 0.5 for c in CROPS}, {c: 30.0 for c in CROPS}, {c: 0.2 for c in CROPS}, {c: 20.0 for c in CROPS}
    )
    assert 0 < ours["hours_one_machine_grow_and_draw_only"] < ours["hours_one_machine"]
    assert "hours_one_machine_grow_and_draw_only" not in projection({c: 0.5 for c in CROPS}, {c: 30.0 for c in CROPS})


def test_a_paper_crop_not_measured_costs_the_slowest_measured_and_no_library_crop_is_made_up() -> None:
    from davis_ag.workflows.bench.run import fill_unmeasured_paper_crops

    per_view, overhead = {"strawberry": 0.2, "vine": 0.3}, {"strawberry": 2.0, "vine": 3.0}
    assert fill_unmeasured_paper_crops(per_view, overhead) == ["tomato"]
    assert per_view == {"strawberry": 0.2, "vine": 0.3, "tomato": 0.3}
    assert overhead == {"strawberry": 2.0, "vine": 3.0, "tomato": 3.0}
    assert projection(per_view, overhead)["scenes"] > 0  # every group of the paper preset has its costs


def test_a_measured_pool_gain_replaces_the_helios_one() -> None:
    costs = ({c: 1.0 for c in CROPS}, {c: 0.0 for c in CROPS})
    assert projection(*costs, gain=2.0)["hours_one_machine"] == pytest.approx(502_542 / 3600 / 2, abs=0.1)
    assert "measured by this bench" in projection(*costs, gain=2.0)["assumptions"]


def test_the_training_rates_reach_performance_md_and_ppos_line_in_benchmark_md(tmp_path: Path) -> None:
    """What ``make bench`` writes from the learners' rates: the table between performance.md's
    markers and PPO's two settings in one sentence between benchmark.md's, the rest untouched."""
    from davis_ag.workflows.bench.training import LEARNERS, write_training

    rows = [row for row, _, _ in LEARNERS]
    result = {
        "steps": 2048,
        "seed": 0,
        "learners": {
            rows[0]: {"steps_per_second": 50.0, "over_reference": 1.0, "hours_300k": 1.7},
            rows[1]: {"steps_per_second": 25.0, "over_reference": 0.5, "hours_300k": 3.3},
            rows[2]: {"steps_per_second": 10.0, "over_reference": 0.2, "hours_300k": 8.3},
        },
    }
    performance = tmp_path / "performance.md"
    performance.write_text("before\n<!-- bench-training:start -->\nold\n<!-- bench-training:end -->\nafter\n")
    benchmark = tmp_path / "benchmark.md"
    benchmark.write_text("# B\n<!-- ppo-rate:start -->\nold\n<!-- ppo-rate:end -->\nend\n")
    write_training(result, (1.0, 2.0), performance)
    table = performance.read_text()
    assert table.startswith("before\n") and table.endswith("after\n") and "old" not in table
    assert "| PPO (SB3's defaults) | **10.0** | 0.20x | 8.3 |" in table and "load average 1.00 at the start" in table
    line = benchmark.read_text()
    assert "SB3's defaults train at 10.0 steps/s" in line and "the zoo's settings at 25.0 (2.5 times as fast)" in line
    assert line.startswith("# B\n") and line.endswith("end\n")


def test_rates_on_a_gpu_stand_beside_the_cpus_and_ppos_line_keeps_the_cpus(tmp_path: Path) -> None:
    """``davis-ag bench --only training --device cuda`` on a GPU machine: each learner on the CPU,
    then on the GPU, against the CPU's A2C; the page's PPO sentence stays the CPU's."""
    from davis_ag.workflows.bench.training import LEARNERS, ppo_line, training_table

    rates = {"cpu": (50.0, 25.0, 10.0), "cuda": (400.0, 300.0, 150.0)}
    learners = {
        f"{row} on {device}": {
            "algo": algo,
            "device": device,
            "steps_per_second": rate,
            "over_reference": rate / 50.0,
            "hours_300k": round(300_000 / rate / 3600, 1),
        }
        for device in ("cpu", "cuda")
        for (row, algo, _), rate in zip(LEARNERS, rates[device])
    }
    result = {"steps": 2048, "seed": 0, "devices": ["cpu", "cuda"], "learners": learners}
    table = training_table(result, (1.0, 1.0))
    assert "on each device in turn (cpu, cuda;" in table and "| against A2C (ours) on cpu |" in table
    assert "| PPO (the zoo's Atari settings, ours) on cuda | **300.0** | 6.00x | 0.3 |" in table
    assert "SB3's defaults train at 10.0 steps/s" in ppo_line(result)


def test_a_gpu_is_asked_for_the_training_rates_only(capsys: pytest.CaptureFixture[str]) -> None:
    from davis_ag import cli

    assert cli.main(["bench", "--device", "cuda", "--out", "unused.json"]) == 2
    assert "--device cuda is for --only training" in capsys.readouterr().err


@pytest.mark.slow
def test_every_path_of_the_bench_runs_on_a_small_scene(tmp_path: Path) -> None:
    """``make bench`` at a test's size: ours, pyhelios's documented path (its JPEG, boxes and
    masks written), the floor and ours without class images, each timed on the same views."""
    from davis_ag.scene.camera import Camera
    from davis_ag.workflows.bench.run import bench_crop

    result = bench_crop("strawberry", tmp_path, repeats=1, camera=Camera(160, 90), view_count=3)
    assert result["views_timed"] == 2 and result["repeats"] == 1
    assert set(result["seconds_per_view"]) == {"ours", "documented", "floor", "no_classes"}
    assert all(seconds > 0 for seconds in result["seconds_per_view"].values())
    written = {p.name for p in (tmp_path / "strawberry-documented").iterdir()}
    assert {"0001.jpeg", "0003.jpeg"} <= written and any(name.endswith(".json") for name in written)


def test_a_gpu_machines_rates_go_to_the_gpu_sections_and_leave_the_2_core_machines(tmp_path: Path) -> None:
    """``make bench`` on a GPU machine writes the page's ``-gpu`` sections; the 2-core machine's
    tables, and the sentences other pages show of them, stay as they were."""
    from davis_ag.workflows.bench.report import write_continuous
    from davis_ag.workflows.bench.training import LEARNERS, write_training

    rows = {row: {"steps_per_second": 800.0, "over_reference": 1.0, "hours_300k": 0.1} for row, _, _ in LEARNERS}
    training = {"steps": 2048, "seed": 0, "devices": ["cpu", "cuda"], "learners": rows}
    continuous = {
        "steps_per_second": 371.2,
        "cpu_ms_per_step": 2.7,
        "steps": 600,
        "resets": 200,
        "refused_share": 0.62,
        "render_and_label_ms": 1.0,
        "draws_per_step": 1.59,
        "draws_per_reset": 2.93,
        "open_and_first_reset_s": 0.77,
        "target_min": 50.0,
        "gl_renderer": "NVIDIA H200/PCIe/SSE2",
        "triangles": 33576,
        "triangles_drawn": 13570,
    }
    sections = ("bench-training", "bench-continuous", "bench-training-gpu", "bench-continuous-gpu")
    performance = tmp_path / "performance.md"
    performance.write_text("".join(f"<!-- {m}:start -->\nold {m}\n<!-- {m}:end -->\n" for m in sections))
    (tmp_path / "benchmark.md").write_text("<!-- ppo-rate:start -->\nold\n<!-- ppo-rate:end -->\n")
    (tmp_path / "views-on-demand.md").write_text("<!-- continuous-rate:start -->\nold\n<!-- continuous-rate:end -->\n")

    write_training(training, (1.0, 1.0), performance, gpu_machine=True)
    write_continuous(continuous, (1.0, 1.0), performance, gpu_machine=True)
    page = performance.read_text()
    assert "old bench-training\n" in page and "old bench-continuous\n" in page
    assert "old bench-training-gpu" not in page and "old bench-continuous-gpu" not in page
    assert "**371.2**" in page and "drawn by NVIDIA H200/PCIe/SSE2" in page and "**800.0**" in page
    assert "old" in (tmp_path / "benchmark.md").read_text()
    assert "old" in (tmp_path / "views-on-demand.md").read_text()


@pytest.mark.parametrize(
    ("only", "present", "missing"),
    [
        ("all", ["bench"], "bench-gpu"),
        ("all", ["bench-gpu", "bench-training-gpu"], "bench-continuous-gpu"),  # every section it will write
        ("continuous", ["bench-continuous", "bench-gpu"], "bench-continuous-gpu"),
        ("training", ["bench-training", "bench-gpu"], "bench-training-gpu"),
    ],
)
def test_a_gpu_machine_asks_for_the_pages_gpu_sections(
    only: str,
    present: list[str],
    missing: str,
    tmp_path: Path,
    monkeypatch: pytest.MonkeyPatch,
    capsys: pytest.CaptureFixture[str],
) -> None:
    """A page without a GPU section the run would write is refused before minutes of measuring,
    naming the marker, and left as it was."""
    from davis_ag import cli
    from davis_ag.workflows.bench import report as bench_report

    monkeypatch.setattr(bench_report, "is_gpu_machine", lambda: True)
    page = tmp_path / "performance.md"
    text = "".join(f"<!-- {m}:start -->\n<!-- {m}:end -->\n" for m in present)
    page.write_text(text)
    assert cli.main(["bench", "--only", only, "--out", str(tmp_path / "b.json"), "--doc", str(page)]) == 2
    err = capsys.readouterr().err.strip()
    assert f"<!-- {missing}:start -->" in err and "\n" not in err
    assert page.read_text() == text


def test_the_continuous_rate_with_a_robot_is_written_under_its_table() -> None:
    from davis_ag.workflows.bench.report import continuous_table

    result = {
        "steps_per_second": 40.0,
        "cpu_ms_per_step": 20.0,
        "steps": 600,
        "resets": 200,
        "refused_share": 0.5,
        "render_and_label_ms": 10.0,
        "draws_per_step": 1.5,
        "draws_per_reset": 3.0,
        "open_and_first_reset_s": 1.0,
        "target_min": 50.0,
        "triangles": 1000,
        "triangles_drawn": 900,
    }
    assert "camera on" not in continuous_table(result, (1.0, 1.0))  # a report from before the robot
    robot = {"name": "ur10-lift", "steps_per_second": 31.5, "cpu_ms_per_step": 25.0, "refused_share": 0.6}
    text = continuous_table({**result, "robot": robot}, (1.0, 1.0))
    assert "With the camera on ur10-lift" in text and "**31.5 steps/s**" in text and "60% of moves refused" in text

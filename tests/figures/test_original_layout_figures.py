"""Stats, figures and the viewer's scene data on data shaped like the original download: no
scene.json, names without ".jpeg", float boxes, a view without a pose, a missing mask, MP scenes
with 12 headings per position (synthetic, no Helios)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from davis_ag.data.reader import open_dataset
from davis_ag.errors import UserError
from davis_ag.figures.benchmark_plots import plot_oer
from davis_ag.figures.dataset_stats import dataset_statistics, format_statistics
from davis_ag.figures.plots import PlotRequest, make_plot
from davis_ag.figures.viewer_server import scene_payload
from davis_ag.figures.visibility_plots import plot_altitude, plot_visibility
from layout_factory import write_original_style_dataset


@pytest.fixture(scope="module")
def original(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("original")
    write_original_style_dataset(root, "sp", "strawberry", scenes=2, missing_mask=True)
    write_original_style_dataset(root, "mp", "vine", scenes=1)
    return root


def test_stats_without_scene_json(original: Path) -> None:
    stats = dataset_statistics(open_dataset(original))
    groups = stats["table3"]["groups"]
    assert {g: (v["scenes"], v["scenario"], v["crop"]) for g, v in groups.items()} == {
        "Single-Strawberry": (2, "sp", "strawberry"),
        "Multi-Vine": (1, "mp", "vine"),
    }
    sp = stats["fruit"]["Single-Strawberry"]
    assert sp["fruit_per_plant"] is None and sp["visible_fraction"] is None
    firsts = [
        json.loads((original / f"Single-Strawberry/{i:03d}/annotations.json").read_text())["0001"] for i in range(2)
    ]
    assert sp["masks_missing"] == sum(len(f["bounding_boxes"]) for f in firsts)  # views without a mask
    text = format_statistics(stats)
    assert "Multi-Vine" in text and "79,200" in text  # the paper's MP vine images beside ours


def test_figures_from_original_layout(original: Path, tmp_path: Path) -> None:
    dataset = open_dataset(original)
    mp = dataset.scene("Multi-Vine/000")
    plotted = plot_visibility(mp, tmp_path / "mp", ("png",))
    posed = [v for v in mp.views.values() if v.pose is not None]
    # 12 headings share one position: the panels hold positions, not views.
    spots = sum(len(p["x"]) for p in plotted.data["altitudes"])
    assert spots == len({tuple(round(c * 1000) for c in v.pose[:3]) for v in posed}) < len(posed)
    for panel in plotted.data["altitudes"]:
        for x, y, count in zip(panel["x"], panel["y"], panel["count"]):
            here = [v for v in posed if (v.pose[0], v.pose[1], round(v.pose[2], 2)) == (x, y, panel["z"])]
            assert count == len({b.fruit_id for v in here for b in v.boxes})
    assert plot_altitude(mp, tmp_path / "alt", ("png",)).data["columns"] > 0
    oer = plot_oer(dataset.scenes, tmp_path / "oer", ("svg",))
    assert oer.paths[0].suffix == ".svg" and oer.data["masks_missing"] > 0
    with pytest.raises(UserError, match="phenotypes"):
        make_plot(PlotRequest("phenotypes", tmp_path / "ph", dataset=original))


def test_viewer_payload_of_original_layout(original: Path) -> None:
    scene = open_dataset(original).scene("Single-Strawberry/000")
    payload = json.loads(json.dumps(scene_payload(scene)))
    assert payload["views"]["0001.jpeg"]["pose"] is None  # the original's first view had none
    assert payload["views"]["0001.jpeg"]["mask"] is False
    assert payload["plants"] == [[0.0, 0.0]]  # from the scenario when scene.json is absent
    assert all(v["pointers"].keys() == set(payload["actions"]) for v in payload["views"].values())

"""Every ``davis-ag plot`` kind and ``davis-ag stats`` on a small real (Helios) dataset, with the
numbers behind each figure recomputed here from the raw files: annotations.json read with
``json``, masks with PIL, phenotypes from scene.json, actions from the results' episodes."""

from __future__ import annotations

import json
import shutil
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from PIL import Image

from davis_ag import cli
from davis_ag.data.reader import open_dataset

PNG = b"\x89PNG\r\n\x1a\n"


def _scene_dir(root: Path) -> Path:
    return root / "Single-Strawberry" / "000"


def _raw(root: Path) -> dict[str, Any]:
    return json.loads((_scene_dir(root) / "annotations.json").read_text())


def _plot(capsys: pytest.CaptureFixture[str], *args: str) -> dict[str, Any]:
    """Run ``davis-ag plot``; check it wrote PNG, SVG and JSON; return the JSON."""
    assert cli.main(["plot", *args]) == 0
    written = [Path(line.removeprefix("wrote ")) for line in capsys.readouterr().out.splitlines()]
    kinds = {p.suffix for p in written}
    assert {".png", ".svg", ".json"} <= kinds, written
    for path in written:
        if path.suffix == ".png":
            assert path.read_bytes()[:8] == PNG
        if path.suffix == ".svg":
            assert b"<svg" in path.read_bytes()[:400]
    return json.loads(next(p for p in written if p.suffix == ".json").read_text())


def test_visibility_counts_match_the_boxes(real_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    data = _plot(capsys, "visibility", str(real_root), "--out", str(tmp_path / "vis"))
    raw = _raw(real_root)
    expected: dict[tuple[float, float, float], set[int]] = {}
    for entry in raw.values():
        x, y, z = entry["pose"][:3]
        expected.setdefault((round(x, 3), round(y, 3), round(z, 3)), set()).update(
            b[4] for b in entry["bounding_boxes"]
        )
    drawn = {
        (round(x, 3), round(y, 3), round(panel["z"], 3)): count
        for panel in data["altitudes"]
        for x, y, count in zip(panel["x"], panel["y"], panel["count"])
    }
    assert drawn == {k: len(v) for k, v in expected.items()}
    assert len(data["altitudes"]) == 3  # one panel per altitude
    edges = data["edges"]
    for panel in data["altitudes"]:
        assert panel["class"] == [int(np.searchsorted(edges, c, side="right")) for c in panel["count"]]


def test_altitude_histograms_follow_the_up_pointers(
    real_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = _plot(capsys, "altitude", str(real_root), "--out", str(tmp_path / "alt"))
    raw = _raw(real_root)
    heights = sorted({round(e["pose"][2], 2) for e in raw.values()})
    columns = []
    for name, entry in raw.items():
        if entry.get("down"):
            continue
        column, current = {}, name
        while current:
            e = raw[current]
            column[heights.index(round(e["pose"][2], 2))] = {b[4] for b in e["bounding_boxes"]}
            current = e.get("up", "")
        columns.append(column)
    # Every position has one column of views, one per altitude.
    assert data["columns"] == len(columns) == len(raw) // len(heights) > 1
    h1_h2 = [len(c[0]) - len(c[1]) for c in columns]
    new_3 = [len(c[2] - (c[0] | c[1])) for c in columns]
    assert sorted(data["differences"]["|H1|-|H2|"]) == sorted(h1_h2)
    assert sorted(data["novel"]["H3\\(H1∪H2)"]) == sorted(new_3)
    histogram = data["histograms"]["differences"]["|H1|-|H2|"]
    assert histogram["counts"] == np.histogram(h1_h2, bins=histogram["edges"])[0].tolist()
    assert sum(histogram["counts"]) == len(columns)


def test_oer_histogram_matches_masks_and_environment(
    real_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = _plot(capsys, "oer", str(real_root), "--out", str(tmp_path / "oer"))
    values = []
    for name, entry in _raw(real_root).items():
        mask = np.asarray(Image.open(_scene_dir(real_root) / "images" / name.replace(".jpeg", "_seg.png")))
        for x, y, w, h, fruit, _ in entry["bounding_boxes"]:
            values.append(np.count_nonzero(mask[y : y + h, x : x + w] == fruit) / (w * h))
    assert data["boxes"] == len(values) > 0
    assert data["counts"] == np.histogram(values, bins=data["edges"])[0].tolist()
    # The environment's cache computes the same OERs on its own path.
    from davis_ag.benchmark.cache import load_scene_cache

    cache = load_scene_cache(open_dataset(real_root).scenes[0], real_root, tmp_path / "cache")
    assert sorted(cache.box_oer.tolist()) == pytest.approx(sorted(values), abs=1e-6)


def test_actions_count_the_recorded_episodes(
    real_results: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    data = _plot(capsys, "actions", "--results", str(real_results), "--policy", "Rand", "--out", str(tmp_path / "act"))
    results = json.loads(real_results.read_text())
    names = results["protocol"]["actions"]
    assert data["actions"] == names == ["forward", "backward", "left", "right", "up", "down", "done"]
    for policy, summary in results["policies"].items():
        chosen = [a for e in summary["episodes"] for a in e["actions"]]
        assert data["counts"][policy] == [chosen.count(i) for i in range(len(names))]
        assert data["counts"][policy] == [summary["action_counts"][n] for n in names]
    # LRD only ever picks left, right or done (section V-B).
    assert [n for n, c in zip(names, data["counts"]["LRD"]) if c] <= ["left", "right", "done"]
    assert data["choices"] == [e["actions"] for e in results["policies"]["Rand"]["episodes"]]


def test_episode_strip_replays_a_recorded_episode(
    real_root: Path, real_results: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    results = json.loads(real_results.read_text())
    episodes = results["policies"]["Oracle"]["episodes"]
    index = max(range(len(episodes)), key=lambda i: episodes[i]["reward"])
    record = episodes[index]
    data = _plot(
        capsys,
        "episode",
        "--results",
        str(real_results),
        "--policy",
        "Oracle",
        "--episode",
        str(index),
        "--out",
        str(tmp_path / "ep"),
    )
    raw = _raw(real_root)
    assert data["views"] == record["path"]
    assert data["poses"] == [raw[name]["pose"] for name in record["path"]]
    assert data["oer"][0] == pytest.approx(record["oer_0"], abs=1e-6)
    assert data["oer"][-1] == pytest.approx(record["oer_tau"], abs=1e-6)
    # The same episode walked from its start and actions gives the same views.
    names = results["protocol"]["actions"]
    walked = _plot(
        capsys,
        "episode",
        str(real_root),
        "--start",
        record["path"][0],
        "--actions",
        ",".join(names[a] for a in record["actions"]),
        "--target",
        str(record["target_fruit"]),
        "--out",
        str(tmp_path / "walked"),
    )
    assert walked["views"] == record["path"]


def test_phenotypes_and_contact_sheet(real_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    data = _plot(capsys, "phenotypes", str(real_root), "--out", str(tmp_path / "ph"))
    assert (tmp_path / "ph_contact_sheet.png").read_bytes()[:8] == PNG
    plant = json.loads((_scene_dir(real_root) / "scene.json").read_text())["plants"][0]
    for key, ends in data["phenotypes"].items():
        assert ends["smallest"]["value"] == pytest.approx(plant["phenotype_measured"][key])
        view = _raw(real_root)[ends["smallest"]["view"]]
        low = min(e["pose"][2] for e in _raw(real_root).values())
        assert view["pose"][2] == pytest.approx(low) and view["pose"][1] < 0  # in front, lowest


def test_stats_table3_and_fruit(real_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "stats.json"
    assert cli.main(["stats", str(real_root), "--out", str(out)]) == 0
    printed = capsys.readouterr().out
    assert "Table 3" in printed and "Single-Strawberry" in printed and "24,510" in printed
    stats = json.loads(out.read_text())
    raw = _raw(real_root)
    group = stats["table3"]["groups"]["Single-Strawberry"]
    assert (group["scenes"], group["images"]) == (1, len(raw))
    fruit = stats["fruit"]["Single-Strawberry"]
    meta = json.loads((_scene_dir(real_root) / "scene.json").read_text())
    assert fruit["fruit_per_plant"]["mean"] == meta["plants"][0]["fruit_count"]
    per_view = [len(e["bounding_boxes"]) for e in raw.values()]
    assert fruit["boxes_per_view"]["mean"] == pytest.approx(np.mean(per_view))
    assert sum(fruit["oer"]["histogram"]["counts"]) == sum(per_view) == fruit["visible_fraction"]["n"]
    # Refused moves, recomputed from annotations.json's pointers and boxes: from every box (this
    # tiny scene has few starts below OER 0.4), then as stats counts them, from the starts only.
    from davis_ag.benchmark.cache import load_scene_cache
    from davis_ag.benchmark.moves import refused_moves
    from davis_ag.scene.specs import SP_ACTIONS

    cache = load_scene_cache(open_dataset(real_root).scene("Single-Strawberry/000"), real_root)
    for max_oer in (1.01, 0.4):
        starts = [
            (cache.view_names[cache.box_view[r]], int(cache.fruit_ids[cache.box_fruit[r]]))
            for r in range(len(cache.box_oer))
            if cache.box_oer[r] < max_oer and cache.box_pixels[r] >= meta["min_fruit_pixels"]
        ]
        no_view = sum(raw[view][move] == "" for view, _ in starts for move in SP_ACTIONS)
        lost = sum(
            raw[view][move] != "" and fruit_id not in {b[4] for b in raw[raw[view][move]]["bounding_boxes"]}
            for view, fruit_id in starts
            for move in SP_ACTIONS
        )
        counts = refused_moves(cache, SP_ACTIONS, meta["min_fruit_pixels"], max_oer)
        assert (counts.starts, counts.moves, counts.no_view, counts.target_lost) == (
            len(starts),
            6 * len(starts),
            no_view,
            lost,
        )
        assert max_oer < 1 or (len(starts) > 20 and no_view > 0 and lost > 0)
    refused = stats["refused_moves"]["Single-Strawberry"]
    assert (refused["starts"], refused["no_view"], refused["target_lost"]) == (len(starts), no_view, lost)
    assert "moves refused from starts" in printed


@pytest.mark.parametrize(
    "args, words",
    [
        (["plot", "actions", "--out", "X"], "--results"),
        (["plot", "visibility", "--out", "X"], "dataset folder"),
        (["plot", "visibility", "ROOT", "--scene", "Single-Tomato/009", "--out", "X"], "no scene"),
        (["plot", "episode", "ROOT", "--start", "0001", "--actions", "fly", "--out", "X"], "unknown action"),
        (["plot", "oer", "ROOT", "--formats", "gif", "--out", "X"], "--formats"),
        (["plot", "actions", "--results", "OLD", "--out", "X"], "not davis-ag evaluation results"),
        (["stats", "NOWHERE"], "no such folder"),
        # Continuous results (actions are numbers), a file without policies, a loop of up moves:
        # a traceback twice and a figure that never finished.
        (["plot", "actions", "--results", "CONTINUOUS", "--out", "X"], "not grid moves"),
        (["plot", "episode", "ROOT", "--results", "CONTINUOUS", "--out", "X"], "not grid moves"),
        (["plot", "episode", "ROOT", "--results", "EMPTY", "--out", "X"], "holds no policies"),
        (["plot", "altitude", "LOOP", "--out", "X"], "come back to"),
    ],
)
def test_bad_input_is_one_line(
    real_root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str], args: list[str], words: str
) -> None:
    old = tmp_path / "old.json"  # results written before per-episode records existed
    old.write_text(json.dumps({"protocol": {"scenario": "sp"}, "policies": {"LRD": {"oer_tau": {}}}}))
    continuous = tmp_path / "continuous.json"
    episode = {"scene": "Single-Strawberry/000", "actions": [[0.5, -0.2, 0.1]], "views": [], "target": 1}
    continuous.write_text(
        json.dumps(
            {
                "protocol": {"scenario": "sp", "environment": "davis_ag/TVMContinuous-v0"},
                "policies": {"Rand": {"oer_tau": {}, "episodes": [episode]}},
            }
        )
    )
    empty = tmp_path / "empty.json"
    empty.write_text(json.dumps({"protocol": {"scenario": "sp"}, "policies": {}}))
    loop = tmp_path / "loop"
    if "LOOP" in args:  # a copy whose top view's up move leads back to the bottom of its column
        shutil.copytree(real_root, loop)
        path = loop / "Single-Strawberry" / "000" / "annotations.json"
        doc = json.loads(path.read_text())
        top = next(n for n, e in doc.items() if not e.get("up") and e.get("down"))
        bottom = doc[doc[top]["down"]]["down"] or doc[top]["down"]
        doc[top]["up"] = bottom
        path.write_text(json.dumps(doc))
    swap = {
        "ROOT": str(real_root),
        "X": str(tmp_path / "x"),
        "OLD": str(old),
        "NOWHERE": str(tmp_path / "no"),
        "CONTINUOUS": str(continuous),
        "EMPTY": str(empty),
        "LOOP": str(loop),
    }
    assert cli.main([swap.get(a, a) for a in args]) == 2
    err = capsys.readouterr().err.strip()
    assert words in err and "\n" not in err and err.startswith("davis-ag")

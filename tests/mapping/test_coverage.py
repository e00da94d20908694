"""Which fruit a row segment has, which view sees which, the ceiling and the parts of the move graph."""

from __future__ import annotations

import json
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from davis_ag.benchmark.cache import load_scene_cache
from davis_ag.data.reader import open_dataset
from davis_ag.errors import UserError
from davis_ag.formats.scene_file import SceneFile
from davis_ag.mapping.coverage import move_parts, segment_coverage, segment_plants
from davis_ag.scene.specs import crop_spec
from layout_factory import write_tiny_dataset


@pytest.fixture(scope="module")
def tiny_mp(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return write_tiny_dataset(tmp_path_factory.mktemp("mp"), "mp", "vine", scenes=1)


def test_a_fruit_is_seen_where_its_visible_fraction_reaches_the_threshold(tiny_mp: Path) -> None:
    scene = open_dataset(tiny_mp).scenes[0]
    cache = load_scene_cache(scene, tiny_mp)
    coverage = segment_coverage(scene, cache, cache.pointers, threshold=0.5)
    # Recounted from scene.json as a file, not through the model the code reads it with.
    raw = json.loads((tiny_mp / scene.id / "scene.json").read_text())
    ids = sorted(f["id"] for f in raw["fruits"])
    assert coverage.fruit_ids.tolist() == ids  # mp: every plant is the segment's
    expected = np.array(
        [[raw["visible_fraction"].get(name, {}).get(str(f), 0.0) >= 0.5 for f in ids] for name in cache.view_names]
    )
    assert np.array_equal(coverage.seen, expected)
    assert coverage.ceiling == pytest.approx(expected.any(axis=0).mean())
    stricter = segment_coverage(scene, cache, cache.pointers, threshold=0.9)
    assert stricter.seen.sum() <= coverage.seen.sum() and not (stricter.seen & ~coverage.seen).any()


def test_a_threshold_outside_zero_to_one_is_refused(tiny_mp: Path) -> None:
    scene = open_dataset(tiny_mp).scenes[0]
    cache = load_scene_cache(scene, tiny_mp)
    for bad in (0.0, -0.1, 1.5):
        with pytest.raises(UserError, match="outside"):
            segment_coverage(scene, cache, cache.pointers, threshold=bad)


def test_a_row_segment_is_its_own_row_not_the_neighbours() -> None:
    spacing = crop_spec("apple-wall").row.row_spacing
    plants = [
        {"index": 0, "position": [-1.0, 0.0]},
        {"index": 1, "position": [1.0, 0.02]},
        {"index": 2, "position": [0.0, spacing]},  # the neighbouring rows
        {"index": 3, "position": [0.0, -spacing]},
    ]
    scene = SimpleNamespace(
        id="Row-AppleWall/000", scenario="row", crop="apple-wall", metadata=SceneFile.model_validate({"plants": plants})
    )
    assert segment_plants(scene) == {0, 1}
    multi = SimpleNamespace(id="Multi-Vine/000", scenario="mp", crop="vine", metadata=scene.metadata)
    assert segment_plants(multi) == {0, 1, 2, 3}


def test_a_scene_without_its_records_is_refused_in_one_line() -> None:
    scene = SimpleNamespace(id="Single-Strawberry/000", scenario="sp", crop="strawberry", metadata=None)
    with pytest.raises(UserError, match=r"scene\.json"):
        segment_plants(scene)


def test_the_parts_of_a_move_graph_are_the_views_moves_join() -> None:
    # Two alleys: views 0-1-2 joined, 3-4 joined, 5 alone.
    pointers = np.full((6, 2), -1)
    pointers[0, 0], pointers[1, 1] = 1, 0
    pointers[1, 0], pointers[2, 1] = 2, 1
    pointers[3, 0], pointers[4, 1] = 4, 3
    parts = move_parts(pointers)
    assert parts[0] == parts[1] == parts[2]
    assert parts[3] == parts[4] != parts[0]
    assert len(set(parts.tolist())) == 3

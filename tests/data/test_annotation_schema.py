"""Property tests of the annotation and pointer parsers (issue 33, build item 8): whatever an
annotations.json entry holds, parsing gives a well-formed record or a ValueError naming the
problem (which the reader turns into one line), never another exception; and what our writer
writes parses back to itself."""

from __future__ import annotations

import json

from hypothesis import given, settings
from hypothesis import strategies as st

from davis_ag.data.annotation_schema import BOX_LIMIT, Box, ViewRecord, parse_entry
from davis_ag.scene.specs import ALL_ACTIONS

json_values = st.recursive(
    st.none() | st.booleans() | st.integers(-(2**70), 2**70) | st.floats() | st.text(max_size=12),
    lambda inner: st.lists(inner, max_size=6) | st.dictionaries(st.text(max_size=8), inner, max_size=4),
    max_leaves=25,
)
keys = st.one_of(st.text(max_size=12), st.integers(-5, 10_000), st.sampled_from(["0001", "0001.jpeg", "a/b.jpeg"]))
entries = st.dictionaries(st.sampled_from(["bounding_boxes", "pose", *ALL_ACTIONS, "other"]), json_values, max_size=8)


@settings(max_examples=300, deadline=None)
@given(keys, st.one_of(entries, json_values))
def test_any_entry_parses_or_says_why(key: object, entry: object) -> None:
    try:
        record = parse_entry(key, entry)
    except ValueError as error:
        assert str(error)  # the reason, for the one line the reader prints
        return
    assert record.name.endswith(".jpeg") and "/" not in record.name and record.name != ".jpeg"
    assert set(record.pointers) <= set(ALL_ACTIONS)
    for target in record.pointers.values():  # "" is an invalid move, else a view of this folder
        assert target == "" or (target.endswith(".jpeg") and "/" not in target and "\\" not in target)
    for box in record.boxes:
        assert all(
            isinstance(v, int) and -BOX_LIMIT < v < BOX_LIMIT
            for v in (box.xmin, box.ymin, box.width, box.height, box.fruit_id)
        )
    assert record.pose is None or all(isinstance(v, float) for v in record.pose)


boxes = st.builds(
    Box, st.integers(0, 4000), st.integers(0, 4000), st.integers(1, 500), st.integers(1, 500), st.integers(0, 254)
)
names = st.integers(1, 9999).map(lambda n: f"{n:04d}.jpeg")


@given(
    names,
    st.lists(boxes, max_size=5),
    st.dictionaries(st.sampled_from(ALL_ACTIONS), st.one_of(st.just(""), names), max_size=len(ALL_ACTIONS)),
    st.lists(st.floats(-100, 100), min_size=5, max_size=5),
)
def test_what_the_writer_writes_parses_back(
    name: str, written: list[Box], pointers: dict[str, str], pose: list[float]
) -> None:
    entry = json.loads(json.dumps({"bounding_boxes": [b.to_list() for b in written], "pose": pose, **pointers}))
    assert parse_entry(name, entry) == ViewRecord(name, tuple(pose), tuple(written), pointers)

"""Damaged datasets: hypothesis breaks one file of a valid dataset at a time (annotations.json,
scene.json, splits.json, an image, a seg PNG, the observation cache; truncated, wrong types, wrong
sizes, ids out of range, image names with ``..`` or absolute paths, links out of the dataset).

Whatever the damage: ``validate`` returns a report (a problem names the damaged file), the reader
and the environment raise :class:`UserError` (never another exception), and nothing outside the
dataset is opened or changed (an audit hook watches every ``open``).
"""

from __future__ import annotations

import io
import itertools
import json
import os
import shutil
import sys
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from PIL import Image

from davis_ag.benchmark import TVMEnv
from davis_ag.data.reader import open_dataset
from davis_ag.data.validate import validate_dataset
from davis_ag.errors import UserError
from layout_factory import write_tiny_dataset

SCENE = "Single-Strawberry/000"
_counter = itertools.count()
#: Real paths opened under the folder the audit hook watches (set per example).
_WATCHED: list[str] = []
_OPENED: list[str] = []


def _audit(event: str, args: tuple) -> None:
    if event == "open" and _WATCHED and isinstance(args[0], (str, bytes, os.PathLike)):
        path = os.path.realpath(os.fsdecode(args[0]))
        if path.startswith(_WATCHED[0]):
            _OPENED.append(path)


sys.addaudithook(_audit)  # audit hooks cannot be removed; this one only looks while _WATCHED is set

JSON_VALUES = st.recursive(
    st.none()
    | st.booleans()
    | st.integers(-(2**40), 2**40)
    | st.floats(allow_nan=True)
    | st.sampled_from(["", "x", "..", "../0001.jpeg", "/etc/passwd", "0001", "9999.jpeg"]),
    lambda inner: st.lists(inner, max_size=3) | st.dictionaries(st.text(max_size=3), inner, max_size=2),
    max_leaves=6,
)
BAD_NAMES = st.sampled_from(
    [
        "../0001.jpeg",
        "/etc/passwd",
        "..",
        "../../outside/x.jpeg",
        "0001.png",
        "x.jpeg",
        "0001/..",
        "\\..\\x.jpeg",
        "",
        " ",
        "0",
    ]
)


@pytest.fixture(scope="module")
def pristine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    """One valid scene, its observation cache already built inside it."""
    root = write_tiny_dataset(tmp_path_factory.mktemp("pristine") / "data", "sp", "strawberry", scenes=1)
    TVMEnv(root, "sp", "all")
    return root


@pytest.fixture(scope="module")
def sandbox(tmp_path_factory: pytest.TempPathFactory) -> Path:
    return tmp_path_factory.mktemp("sandbox")


# ---------------------------------------------------------------------------------------------
# Damage: each function breaks one thing in a copy and returns the file it broke


def _truncate(path: Path, data: st.DataObject) -> None:
    raw = path.read_bytes()
    path.write_bytes(raw[: data.draw(st.integers(0, max(len(raw) - 1, 0)), label="keep bytes")])


def annotations_damage(root: Path, outside: Path, data: st.DataObject) -> Path:
    path = root / SCENE / "annotations.json"
    kind = data.draw(st.sampled_from(["truncate", "field", "box value", "pointer", "key", "whole"]), label="kind")
    if kind == "truncate":
        _truncate(path, data)
        return path
    doc = json.loads(path.read_text())
    names = sorted(doc)
    name = data.draw(st.sampled_from(names), label="entry")
    if kind == "field":
        doc[name][data.draw(st.sampled_from(["bounding_boxes", "pose", "forward", "up"]))] = data.draw(JSON_VALUES)
    elif kind == "box value":
        boxes = doc[name]["bounding_boxes"] or [[0, 0, 1, 1, 0, 0]]
        box = boxes[0]
        box[data.draw(st.integers(0, 5))] = data.draw(
            st.sampled_from([-1, 10**12, "x", None, 1.5, 255, 1000, True, -(10**9), float("inf")])
        )
        doc[name]["bounding_boxes"] = boxes
    elif kind == "pointer":
        doc[name][data.draw(st.sampled_from(["forward", "backward", "left", "right", "up", "down"]))] = data.draw(
            BAD_NAMES | JSON_VALUES
        )
    elif kind == "key":
        doc[data.draw(BAD_NAMES)] = doc.pop(name)
    else:
        doc = data.draw(JSON_VALUES)
    path.write_text(json.dumps(doc))
    return path


def scene_json_damage(root: Path, outside: Path, data: st.DataObject) -> Path:
    path = root / SCENE / "scene.json"
    if data.draw(st.booleans(), label="truncate"):
        _truncate(path, data)
        return path
    doc = json.loads(path.read_text())
    key = data.draw(st.sampled_from(["camera", "min_fruit_pixels", "seed", "plants", "visible_fraction"]))
    if key == "camera" and data.draw(st.booleans()):
        doc["camera"]["width"] = data.draw(JSON_VALUES)
    else:
        doc[key] = data.draw(JSON_VALUES)
    path.write_text(json.dumps(doc))
    return path


def splits_damage(root: Path, outside: Path, data: st.DataObject) -> Path:
    path = root / "splits.json"
    doc = json.loads(path.read_text())
    doc[data.draw(st.sampled_from(["train", "test"]))] = data.draw(JSON_VALUES)
    path.write_text(json.dumps(doc))
    return path


def pixels_damage(root: Path, outside: Path, data: st.DataObject) -> Path:
    images = root / SCENE / "images"
    stem = f"{data.draw(st.integers(1, 4)):04d}"
    path = images / data.draw(st.sampled_from([f"{stem}.jpeg", f"{stem}_seg.png"]), label="file")
    kind = data.draw(st.sampled_from(["truncate", "size", "rgb", "16 bit", "bytes", "delete"]), label="kind")
    if kind == "truncate":
        _truncate(path, data)
    elif kind == "bytes":
        path.write_bytes(data.draw(st.binary(max_size=64)))
    elif kind == "delete":
        path.unlink()
    else:
        with Image.open(path) as im:
            im.load()
        if kind == "size":
            im = im.resize((im.width + data.draw(st.integers(1, 9)), im.height))
        elif kind == "rgb":
            im = im.convert("RGB")
        else:
            im = Image.fromarray(np.asarray(im.convert("L"), dtype=np.uint16) * 300)
        buffer = io.BytesIO()
        im.save(buffer, format="PNG" if path.suffix == ".png" or im.mode == "I;16" else "JPEG")
        path.write_bytes(buffer.getvalue())
    return path


def cache_damage(root: Path, outside: Path, data: st.DataObject) -> Path:
    folder = root / ".davis_ag_cache" / SCENE
    name = data.draw(st.sampled_from(["meta.json", "tables.npz", "images.npy"]), label="cache file")
    path = folder / name
    kind = data.draw(
        st.sampled_from(
            ["truncate", "link", "table"]
            if name == "tables.npz"
            else ["truncate", "link", "field"]
            if name == "meta.json"
            else ["truncate", "link"]
        )
    )
    if kind == "truncate":
        _truncate(path, data)
    elif kind == "link":
        shutil.copy(path, outside / name)
        path.unlink()
        path.symlink_to(outside / name)
    elif kind == "field":
        doc = json.loads(path.read_text())
        doc[data.draw(st.sampled_from(["views", "image_size", "scene"]))] = data.draw(JSON_VALUES)
        path.write_text(json.dumps(doc))
    else:
        with np.load(path) as npz:
            tables = {k: npz[k] for k in npz.files}
        key = data.draw(st.sampled_from(sorted(tables)))
        tables[key] = data.draw(
            st.sampled_from(
                [
                    tables[key][:1],
                    tables[key] + 10**6,
                    -tables[key] - 5,
                    np.zeros((2, 2, 2), np.int32),
                    tables[key].astype(np.float64) + 0.5,
                ]
            )
        )
        np.savez(path, **tables)
    return path


def link_damage(root: Path, outside: Path, data: st.DataObject) -> Path:
    which = data.draw(
        st.sampled_from(
            ["annotations.json", "scene.json", "images/0001.jpeg", "images/0002_seg.png", "scene folder", "splits.json"]
        ),
        label="linked",
    )
    if which == "scene folder":
        path = root / SCENE
        shutil.copytree(path, outside / "000")
        shutil.rmtree(path)
    else:
        path = (root / which) if which == "splits.json" else root / SCENE / which
        shutil.copy(path, outside / path.name)
        path.unlink()
    target = outside / ("000" if which == "scene folder" else path.name)
    path.symlink_to(target)
    return path


DAMAGE: dict[str, Callable[[Path, Path, st.DataObject], Path]] = {
    "annotations": annotations_damage,
    "scene.json": scene_json_damage,
    "splits": splits_damage,
    "pixels": pixels_damage,
    "cache": cache_damage,
    "link": link_damage,
}


# ---------------------------------------------------------------------------------------------
# Use everything, as a user of the data would


def _read_everything(root: Path) -> None:
    dataset = open_dataset(root)
    _ = dataset.splits
    for scene in dataset.scenes:
        _ = scene.metadata
        for view in scene.views.values():
            view.image()
            view.mask()
            for action in scene.actions:
                view.next(action)


def _play(root: Path) -> None:
    env = TVMEnv(root, "sp", "all")
    for seed in range(3):
        env.reset(seed=seed)
        for action in (0, 2, 4):
            *_, terminated, _, _ = env.step(action)
            if terminated:
                break
    env.step  # noqa: B018 - the environment stays usable


def _only_user_errors(use: Callable[[Path], Any], root: Path) -> str | None:
    """Run ``use``; the message of the UserError it raised, or None; any other exception fails."""
    try:
        use(root)
    except UserError as error:
        assert "\n" not in str(error), str(error)
        return str(error)
    return None


@settings(
    max_examples=50,
    deadline=None,
    derandomize=True,
    suppress_health_check=[HealthCheck.function_scoped_fixture, HealthCheck.too_slow],
)
@given(data=st.data())
def test_damaged_files_give_reports_and_user_errors_only(data: st.DataObject, pristine: Path, sandbox: Path) -> None:
    case = sandbox / f"case-{next(_counter)}"
    root, outside = case / "data", case / "outside"
    shutil.copytree(pristine, root, symlinks=True)
    outside.mkdir()
    kind = data.draw(st.sampled_from(sorted(DAMAGE)), label="damage")
    damaged = DAMAGE[kind](root, outside, data)
    before = {p: p.stat().st_mtime_ns for p in outside.rglob("*")}
    _WATCHED[:] = [os.path.realpath(outside)]
    _OPENED.clear()
    try:
        report = validate_dataset(root)
        read_error = _only_user_errors(_read_everything, root)
        env_error = _only_user_errors(_play, root)
    finally:
        _WATCHED.clear()
    assert not _OPENED, f"opened outside the dataset: {_OPENED}"
    assert {p: p.stat().st_mtime_ns for p in outside.rglob("*")} == before
    if kind == "link":  # named by validate, refused by the reader and the environment
        assert any(
            str(p.path).startswith(str(damaged)) and "outside the dataset" in p.reason for p in report.problems
        ), report.problems
        assert read_error and "outside the dataset" in read_error
        # The environment reads the annotations (the cache's key) and, through a cache built from
        # the untouched pictures, no picture.
        if damaged.name in ("annotations.json", "000"):
            assert env_error and "outside the dataset" in env_error
        else:
            assert env_error is None or "outside the dataset" in env_error
    if kind in ("annotations", "scene.json", "splits", "pixels") and (read_error or env_error) and kind != "splits":
        assert any(str(p.path).startswith(str(damaged.parent)) for p in report.problems), (damaged, report.problems)
    for message in (read_error, env_error):
        if message:
            assert str(root) in message or "split" in message or "start" in message, message
    shutil.rmtree(case)

"""The validation stamp: the same files give the same stamp; any change validation would see gives
another, so a resumed run never keeps a report of data that has changed since."""

from __future__ import annotations

import json
import os
import shutil
from pathlib import Path

import pytest

from davis_ag.data.validation_stamp import validation_stamp
from layout_factory import write_tiny_dataset

GROUP = "Single-Strawberry"


@pytest.fixture(scope="module")
def pristine(tmp_path_factory: pytest.TempPathFactory) -> Path:
    root = tmp_path_factory.mktemp("pristine")
    write_tiny_dataset(root, "sp", "strawberry", scenes=2)
    return root


@pytest.fixture
def dataset(pristine: Path, tmp_path: Path) -> Path:
    return Path(shutil.copytree(pristine, tmp_path / "ds"))


def test_an_unchanged_dataset_keeps_its_stamp_wherever_it_is_read_from(
    dataset: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    first = validation_stamp(dataset / GROUP)
    monkeypatch.chdir(dataset)
    assert validation_stamp(GROUP) == first
    (dataset / ".davis_ag_cache").mkdir()  # the observation cache is not validated
    (dataset / ".davis_ag_cache" / "x.npy").write_bytes(b"1")
    assert validation_stamp(GROUP) == first


def one_view(dataset: Path) -> Path:
    return next((dataset / GROUP / "000" / "images").glob("*.jpeg"))


def rewrite_with_another_time(path: Path) -> None:
    path.write_bytes(path.read_bytes())
    stat = path.stat()
    os.utime(path, ns=(stat.st_atime_ns, stat.st_mtime_ns + 1_000_000_000))


def drop_a_split_entry(dataset: Path) -> None:
    splits = json.loads((dataset / "splits.json").read_text())
    splits["train"] = splits["train"][1:]
    (dataset / "splits.json").write_text(json.dumps(splits))


@pytest.mark.parametrize(
    "change",
    [
        pytest.param(lambda d: one_view(d).write_bytes(one_view(d).read_bytes()[:-10]), id="a view cut short"),
        pytest.param(
            lambda d: rewrite_with_another_time(d / GROUP / "001" / "annotations.json"), id="a file rewritten"
        ),
        pytest.param(lambda d: one_view(d).unlink(), id="a view removed"),
        pytest.param(lambda d: (d / GROUP / "000" / "images" / "extra.jpeg").write_bytes(b"x"), id="a file added"),
        pytest.param(lambda d: shutil.rmtree(d / GROUP / "001"), id="a scene removed"),
        pytest.param(drop_a_split_entry, id="the split edited"),
    ],
)
def test_any_change_validation_would_see_gives_another_stamp(dataset: Path, change) -> None:  # type: ignore[no-untyped-def]
    before = validation_stamp(dataset / GROUP)
    change(dataset)
    assert validation_stamp(dataset / GROUP) != before


def test_another_group_gaining_scenes_leaves_a_groups_stamp(dataset: Path) -> None:
    # A paper-scale run rewrites splits.json with each MP vine scene it makes; SP strawberry's
    # validation must stand meanwhile, or every sitting reads its 24,510 views again.
    before, whole = validation_stamp(dataset / GROUP), validation_stamp(dataset)
    splits = json.loads((dataset / "splits.json").read_text())
    splits["train"].append("Multi-Vine/000")
    (dataset / "splits.json").write_text(json.dumps(splits, indent=2))
    assert validation_stamp(dataset / GROUP) == before
    assert validation_stamp(dataset) != whole  # the whole dataset's validation reads that entry
    splits["seed"] = "not a seed"  # a damage the group's validation reports: a new stamp
    (dataset / "splits.json").write_text(json.dumps(splits, indent=2))
    assert validation_stamp(dataset / GROUP) != before


def test_another_group_recorded_in_dataset_json_leaves_a_groups_stamp(dataset: Path) -> None:
    # Each generate of a new group adds its entry to dataset.json: the crops run validated every
    # finished group again at each sitting while the whole file counted.
    recorded = {"format": "davis-ag-dataset/1", "seed": 0, "groups": {GROUP: {"grid": {"step": 0.25}}}}
    (dataset / "dataset.json").write_text(json.dumps(recorded, indent=2))  # as generate writes it
    before, whole = validation_stamp(dataset / GROUP), validation_stamp(dataset)
    recorded["groups"]["Row-Olive"] = {"grid": {"step": 0.5}}
    (dataset / "dataset.json").write_text(json.dumps(recorded, indent=2))
    assert validation_stamp(dataset / GROUP) == before
    assert validation_stamp(dataset) != whole  # the whole dataset's validation reads the file
    recorded["groups"][GROUP]["grid"]["step"] = 0.123  # its own entry: a new stamp
    (dataset / "dataset.json").write_text(json.dumps(recorded, indent=2))
    assert validation_stamp(dataset / GROUP) != before
    (dataset / "dataset.json").write_text("{ damaged")  # a file no one can read counts by its bytes
    damaged = validation_stamp(dataset / GROUP)
    (dataset / "dataset.json").write_text("{ damaged again")
    assert validation_stamp(dataset / GROUP) != damaged


def test_another_validator_gives_another_stamp(dataset: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    from davis_ag.data import validation_stamp as module

    before = validation_stamp(dataset / GROUP)
    monkeypatch.setattr(module, "VALIDATOR_PACKAGES", ("data",))
    assert validation_stamp(dataset / GROUP) != before


def test_the_validators_code_counts_not_its_comments_or_docstrings() -> None:
    # A docstring reworded in data/ re-read 24,510 paper-scale views at the next sitting; a change of
    # what the code does must still give another stamp.
    from davis_ag.data.validation_stamp import code_of

    code = 'def ok(n):\n    """Say whether n is sound."""\n    return n > 0  # positive\n'
    reworded = '"""A module."""\n\n\ndef ok(n):\n    """Whether n is sound, reworded."""\n\n    return (\n        n > 0\n    )\n'
    assert code_of(reworded) == code_of(code)
    assert code_of(code.replace("n > 0", "n >= 0")) != code_of(code)
    assert code_of('def f():\n    """Only a docstring."""\n') == code_of("def f():\n    pass\n")
    assert code_of('x = "a string that is data, not a docstring"\n') != code_of('x = "another"\n')

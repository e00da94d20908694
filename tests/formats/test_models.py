"""The pydantic models of the dataset's files: what they accept, and one line naming the field otherwise."""

from __future__ import annotations

import pytest
from pydantic import ValidationError

from davis_ag.errors import UserError
from davis_ag.formats.models import (
    MAX_IMAGE_SIDE,
    MAX_SEED,
    AnnotationEntry,
    DatasetFile,
    SplitsFile,
    check_image_size,
    check_seed,
    one_line,
)


def test_one_seed_rule() -> None:
    assert check_seed(0) == 0 and check_seed(MAX_SEED) == MAX_SEED
    for bad in (-1, MAX_SEED + 1, 1.5, True, "7"):
        with pytest.raises(UserError, match=r"^--seed: must be a whole number"):
            check_seed(bad, "--seed")


def test_one_image_size_rule() -> None:
    assert check_image_size("1280x720") == check_image_size([1280, 720]) == (1280, 720)
    with pytest.raises(UserError, match=f"99999x99999: each side must be from 16 to {MAX_IMAGE_SIDE} pixels"):
        check_image_size("99999x99999")
    with pytest.raises(UserError, match="must be WIDTHxHEIGHT"):
        check_image_size("big")


def test_dataset_json_keeps_later_keys_and_defaults_old_ones() -> None:
    old = {
        "seed": 3,
        "image_size": [640, 360],
        "vfov_deg": 45.0,
        "groups": {
            "Single-Tomato": {"grid": {"extent": [3, 3], "step": 0.25, "altitude_levels": [0, 1, 2], "headings": 1}}
        },
        "future": 1,
    }
    read = DatasetFile.model_validate(old).to_json()
    assert (read["renderer"], read["look"], read["plants"], read["future"]) == ("helios", "helios", "architecture", 1)
    with pytest.raises(ValidationError) as caught:
        DatasetFile.model_validate({**old, "image_size": [640]})
    assert one_line(caught.value, "dataset.json").startswith("dataset.json: image_size: ")


def test_splits_json() -> None:
    splits = SplitsFile.model_validate({"seed": 0, "train": ["A/000", "A/001"], "test": ["A/001"]})
    assert splits.in_both() == ["A/001"]
    with pytest.raises(ValidationError) as caught:
        SplitsFile.model_validate({"train": "A/000", "test": []})
    assert one_line(caught.value).startswith("train: ")


def test_annotation_entries_as_we_write_them() -> None:
    entry = {
        "bounding_boxes": [[1, 2, 3, 4, 5, 0]],
        "pose": [0, 0, 0.25, 90, -10],
        "forward": "0002.jpeg",
        "backward": "",
    }
    assert AnnotationEntry.model_validate(entry).to_json() == {**entry, "pose": [0.0, 0.0, 0.25, 90.0, -10.0]}
    # Ids above 254 belong to scenes of more than 255 fruit (16-bit masks: davis_ag.formats.masks).
    assert AnnotationEntry.model_validate({**entry, "bounding_boxes": [[1, 2, 3, 4, 65534, 0]]})
    for change, path in (
        ({"bounding_boxes": [[1, 2, 0, 4, 5, 0]]}, "bounding_boxes.0.2"),
        ({"bounding_boxes": [[1, 2, 3, 4, 65535, 0]]}, "bounding_boxes.0.4"),  # no fruit of a 16-bit mask
        ({"left": "2.jpeg"}, "left"),
        ({"jump": ""}, "jump"),
    ):
        with pytest.raises(ValidationError) as caught:
            AnnotationEntry.model_validate({**entry, **change})
        assert one_line(caught.value).startswith(f"{path}: "), one_line(caught.value)


def test_a_bad_config_is_one_line_naming_the_key_and_what_is_allowed() -> None:
    from davis_ag.formats.models import DatasetConfigFile

    for data, line in (
        ({"groups": [{"scenario": "sp", "crop": "tomato", "scenes": 1, "sceens": 2}]}, "groups.0.sceens: unknown key"),
        (
            {"plants": "bonsai", "groups": [{"scenario": "sp", "crop": "tomato", "scenes": 1}]},
            "plants: must be 'canopy' or 'architecture', not 'bonsai'",
        ),
    ):
        with pytest.raises(ValidationError) as caught:
            DatasetConfigFile.model_validate(data)
        assert one_line(caught.value, "c.yaml") == f"c.yaml: {line}"

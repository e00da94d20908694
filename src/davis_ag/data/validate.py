"""Check that a DAVIS-Ag dataset is sound: schema, files, pointers, boxes against masks.

Every problem found is reported (one ``path: reason`` each) rather than stopping at the first,
so one run lists everything a re-download or regeneration has to fix. What the reader
tolerates in the original download (names without ".jpeg", float boxes, missing pose or
pointer keys, unknown keys) is not a problem; a missing image or mask is.

Box against mask (:mod:`davis_ag.data.pixel_checks`): our writer makes each box exactly the
inclusive pixel extent of its fruit's mask, so scenes with a scene.json (ours) are held to that.
The original README does not say whether its width is ``xmax - xmin`` or ``xmax - xmin + 1``, so
other scenes get one pixel of slack on each edge unless told otherwise.
"""

from __future__ import annotations

import json
import os
import sys
from collections import Counter
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from pydantic import BaseModel, ValidationError

from davis_ag.data.class_checks import class_problems
from davis_ag.data.pixel_checks import (
    boxes_inside,
    camera_size,
    depth_problems,
    image_problems,
    mask_problems,
    read_mask,
)
from davis_ag.formats.scene_file import SceneFile, scene_file_from
from davis_ag.data.reader import (
    ANNOTATIONS,
    NO_FRUIT,
    SCENE_METADATA,
    SPLITS,
    Dataset,
    Scene,
    ViewRecord,
    normalise_view_name,
    open_dataset,
    parse_entry,
)
from davis_ag.data.safe_read import check_inside
from davis_ag.data.validate_pool import in_scene_order
from davis_ag.formats.layout import DATASET_FILE, IMAGES, view_file, view_of_file
from davis_ag.formats.models import AnnotationEntry, DatasetFile, SplitsFile, one_line
from davis_ag.errors import UserError


@dataclass(frozen=True)
class Problem:
    """One thing wrong, and the file it is in."""

    path: Path
    reason: str

    def __str__(self) -> str:
        return f"{_display(self.path)}: {self.reason}"


def _display(path: Path) -> str:
    # Relative to the working directory when inside it: shorter and what the user typed.
    try:
        return os.path.relpath(path) if Path(path).is_relative_to(Path.cwd()) else str(path)
    except (ValueError, OSError):  # another drive on Windows, or a deleted working directory
        return str(path)


@dataclass
class Report:
    """What a validation run looked at and found."""

    scenes: int = 0
    views: int = 0
    boxes: int = 0
    problems: list[Problem] = field(default_factory=list)

    @property
    def ok(self) -> bool:
        """True when no problem was found."""
        return not self.problems

    def summary(self) -> str:
        """One line: the counts and the verdict."""
        verdict = "sound" if self.ok else _plural(len(self.problems), "problem")
        counts = ", ".join(
            _plural(n, what) for n, what in ((self.scenes, "scene"), (self.views, "view"), (self.boxes, "box"))
        )
        return f"checked {counts}: {verdict}"


def _plural(n: int, word: str) -> str:
    return f"{n} {word}" + ("" if n == 1 else "es" if word.endswith("x") else "s")


def _read_json(path: Path) -> tuple[object, str | None]:
    try:
        return json.loads(path.read_text(encoding="utf-8")), None
    except json.JSONDecodeError as error:
        return None, f"not valid JSON (line {error.lineno} column {error.colno}: {error.msg})"
    except (OSError, UnicodeDecodeError) as error:
        return None, f"cannot read ({error})"


def validate_scene(
    scene: Scene,
    quick: bool = False,
    box_tolerance: int | None = None,
    report: Report | None = None,
    on_problem: Callable[[Problem], None] | None = None,
) -> Report:
    """Check one scene folder.

    Args:
        scene: The scene.
        quick: Skip everything that decodes pixels (image and mask sizes, boxes against masks).
        box_tolerance: Pixels a box edge may differ from its mask's extent; ``None`` picks 0 for
            our scenes (with scene.json) and 1 for others.
        report: Add to this report instead of a new one.
        on_problem: Called with each problem as it is found (to print while the run goes on).

    Returns:
        The report.
    """
    report = report if report is not None else Report()
    report.scenes += 1

    def flag(path: Path, reason: str) -> None:
        problem = Problem(path, reason)
        report.problems.append(problem)
        if on_problem:
            on_problem(problem)

    ann_path = scene.path / ANNOTATIONS
    outside = _outside(ann_path, scene.root)
    if outside:
        flag(ann_path, outside)
        return report
    raw, error = _read_json(ann_path)
    if error is None and (not isinstance(raw, dict) or not raw):
        error = "must be a non-empty JSON object keyed by image name"
    if error is not None or not isinstance(raw, dict):
        flag(ann_path, error or "unreadable")
        return report

    metadata: SceneFile | None = None
    if (scene.path / SCENE_METADATA).is_file():
        raw_metadata, error = (
            (None, outside)
            if (outside := _outside(scene.path / SCENE_METADATA, scene.root))
            else _read_json(scene.path / SCENE_METADATA)
        )
        if error is None:
            try:
                metadata = scene_file_from(raw_metadata)
            except ValueError as problem:
                error = str(problem)
        if error:
            flag(scene.path / SCENE_METADATA, error)
    tolerance = box_tolerance if box_tolerance is not None else (0 if metadata is not None else 1)

    records: dict[str, ViewRecord] = {}
    keys: dict[str, str] = {}  # each record's key in annotations.json
    # Names of every entry, readable or not, so a broken entry does not also orphan its files.
    names = {_name_or_key(key) for key in raw}
    for key, entry in raw.items():
        try:
            record = parse_entry(key, entry)
        except ValueError as error:
            flag(ann_path, f"entry {key!r}: {error}")
            continue
        if record.name in records:
            flag(ann_path, f"entry {key!r}: names the same image as another entry")
        records[record.name] = record
        keys[record.name] = key
    report.views += len(raw)

    images = scene.path / IMAGES
    for record in records.values():
        for action, target in record.pointers.items():
            if target and target not in names:
                flag(ann_path, f"{record.name}: {action} points to {target}, which is not a view of this scene")
        report.boxes += len(record.boxes)
        box_problems = _box_schema_problems(record)
        for problem in box_problems:
            flag(ann_path, problem)
        if metadata is not None and not box_problems:  # ours: held to the entry we write
            try:
                AnnotationEntry.model_validate(raw[keys[record.name]])
            except ValidationError as error:
                flag(ann_path, one_line(error, f"entry {keys[record.name]!r}"))
        image, mask = images / record.name, view_file(scene.path, record.name, "mask")
        has_image, has_mask = image.is_file(), mask.is_file()
        for path, present in ((image, has_image), (mask, has_mask)):
            if present and (outside := _outside(path, scene.root)):
                flag(path, outside)
        # A link out of the dataset is never decoded.
        has_image = has_image and not _outside(image, scene.root)
        has_mask = has_mask and not _outside(mask, scene.root)
        if not image.is_file():
            flag(image, f"missing: annotations.json has an entry {record.name} for it")
        if not mask.is_file():
            flag(mask, f"missing: the instance mask of {record.name}")
        depth = view_file(scene.path, record.name, "depth")
        if metadata is not None and metadata.depth and not depth.is_file():
            flag(depth, f"missing: scene.json records depth images but {record.name} has none")
        if quick:
            size = camera_size(metadata)
            if size:
                for problem in boxes_inside(record, size):
                    flag(ann_path, problem)
        elif has_image:
            _check_pixels(scene, record, ann_path, mask if has_mask else None, metadata, tolerance, flag)

    if images.is_dir():
        for path in sorted(images.iterdir()):
            view = view_of_file(path.name)
            if view is not None and view[0] not in names:
                flag(path, "has no entry in annotations.json")
    return report


def _check_pixels(
    scene: Scene,
    record: ViewRecord,
    ann_path: Path,
    mask_path: Path | None,
    metadata: SceneFile | None,
    tolerance: int,
    flag: Callable[[Path, str], None],
) -> None:
    """Decode a view's image, mask, depth and class images, each once, and flag what is wrong."""
    image = scene.path / IMAGES / record.name
    size, problems = image_problems(image, metadata)
    for problem in problems:
        flag(image, problem)
    if size is not None:
        for problem in boxes_inside(record, size):
            flag(ann_path, problem)
    mask = None
    if mask_path is not None:
        mask, unreadable = read_mask(mask_path)
        if unreadable:
            flag(mask_path, unreadable)
        elif size is not None and mask is not None:
            for problem in mask_problems(record, mask, size, tolerance):
                flag(mask_path, problem)
    depth = view_file(scene.path, record.name, "depth")
    if depth.is_file():
        for problem in depth_problems(record, depth, mask, metadata):
            flag(depth, problem)
    classes = view_file(scene.path, record.name, "classes")
    if classes.is_file() and not _outside(classes, scene.root):
        for problem in class_problems(classes, mask):
            flag(classes, problem)


def _outside(path: Path, root: Path | None) -> str | None:
    """Why ``path`` must not be read (it resolves outside the dataset), or None."""
    try:
        check_inside(path, root)
    except UserError as error:
        return str(error).split(": ", 1)[1]
    return None


def _name_or_key(key: str) -> str:
    try:
        return normalise_view_name(key)
    except ValueError:
        return key


def _box_schema_problems(record: ViewRecord) -> list[str]:
    problems = []
    seen: set[int] = set()
    for box in record.boxes:
        where = f"{record.name}: box {box.to_list()[:5]}"
        if box.width < 1 or box.height < 1:
            problems.append(f"{where} has no area")
        if box.xmin < 0 or box.ymin < 0:
            problems.append(f"{where} starts outside the image")
        if not 0 <= box.fruit_id < NO_FRUIT:
            problems.append(f"{where}: fruit id must be 0..254 to fit the uint8 mask")
        if box.fruit_id in seen:
            problems.append(f"{where}: fruit {box.fruit_id} has two boxes in this view")
        seen.add(box.fruit_id)
    return problems


def _check_splits(dataset: Dataset, whole: bool) -> list[Problem]:
    path = dataset.root / SPLITS
    splits, problems = _read_root_file(dataset, SPLITS, SplitsFile)
    if splits is None:
        return problems
    known = {scene.id for scene in dataset.scenes}
    # Only scenes under the opened path are known; a group or scene opened alone sees a subset.
    problems = [
        Problem(path, f"{name} lists {i}, which is not a scene here")
        for name, ids in (("train", splits.train), ("test", splits.test))
        for i in ids
        if whole and i not in known
    ]
    if both := splits.in_both():
        problems.append(Problem(path, f"{len(both)} scene(s) in both train and test, e.g. {both[0]}"))
    return problems


def _unlabelled_scenes(dataset: Dataset, whole: bool) -> list[Problem]:
    """Scene folders beside the dataset's scenes that have images or a scene.json but no readable
    annotations.json: the reader passes over them, so without this a scene whose labels were lost
    would leave the dataset "sound" and a scene short."""
    problems = []
    groups = {scene.path.parent for scene in dataset.scenes}
    if whole:  # a group whose every scene lost its labels holds no scene the reader found
        groups |= {p for p in dataset.root.iterdir() if p.is_dir() and not p.name.startswith(".")}
    for group in sorted(groups):
        try:
            folders = sorted(p for p in group.iterdir() if p.is_dir() and not p.name.startswith("."))
        except OSError:
            continue
        for folder in folders:
            labels = folder / ANNOTATIONS
            if labels.is_file() or not ((folder / IMAGES).is_dir() or (folder / SCENE_METADATA).exists()):
                continue
            what = "a folder" if labels.is_dir() else "unreadable" if os.path.lexists(labels) else "missing"
            problems.append(
                Problem(
                    labels, f"{what}: this scene has images but no labels; make it again (davis-ag generate resumes)"
                )
            )
    return problems


def _read_root_file(dataset: Dataset, name: str, model: type[BaseModel]) -> tuple[Any, list[Problem]]:
    """A JSON file at the dataset's root read through its model: ``(model or None, problems)``;
    ``(None, [])`` where the file is absent."""
    path = dataset.root / name
    if not path.is_file():
        return None, []
    outside = _outside(path, dataset.root)
    data, error = (None, outside) if outside else _read_json(path)
    if error:
        return None, [Problem(path, error)]
    try:
        return model.model_validate(data), []
    except ValidationError as invalid:
        return None, [Problem(path, one_line(invalid))]


def _check_dataset_file(dataset: Dataset) -> list[Problem]:
    """dataset.json (ours), where the root has one: the settings its scenes share."""
    return _read_root_file(dataset, DATASET_FILE, DatasetFile)[1]


def _check_counts(dataset: Dataset, counts: dict[str, int]) -> list[Problem]:
    """Scenes of a group share one grid, so a scene with another view count lost or gained images."""
    problems = []
    by_group: dict[str, list[Scene]] = {}
    for scene in dataset.scenes:
        if scene.id in counts:
            by_group.setdefault(scene.group, []).append(scene)
    for group, scenes in by_group.items():
        common, votes = Counter(counts[s.id] for s in scenes).most_common(1)[0]
        if votes * 2 <= len(scenes):
            continue
        problems += [
            Problem(
                s.path / ANNOTATIONS,
                f"has {counts[s.id]} views but {votes} of the {len(scenes)} scenes of {group} have {common}",
            )
            for s in scenes
            if counts[s.id] != common
        ]
    return problems


def validate_dataset(
    path: str | Path,
    quick: bool = False,
    box_tolerance: int | None = None,
    on_problem: Callable[[Problem], None] | None = None,
    progress: bool = False,
    workers: int = 1,
) -> Report:
    """Check every scene under a dataset root, group folder or scene folder.

    Args:
        path: What to check.
        quick: Skip pixel checks.
        box_tolerance: See :func:`validate_scene`.
        on_problem: Called with each problem as it is found (with ``workers``, as each scene's
            check ends; in scene order either way).
        progress: Show a tqdm bar on stderr (when it is a terminal and there are several scenes).
        workers: Processes checking scenes at once (decoding is the cost; one per core scales
            it), used where the dataset is large enough to repay their start
            (:mod:`davis_ag.data.validate_pool`). The report is the same for any number.

    Returns:
        The :class:`Report`.

    Raises:
        UserError: when the path is not a DAVIS-Ag dataset at all.
    """
    from tqdm import tqdm

    dataset = open_dataset(path)
    report = Report()
    counts: dict[str, int] = {}

    def emit(problem: Problem) -> None:
        report.problems.append(problem)
        if on_problem:
            on_problem(problem)

    whole = Path(path).expanduser().absolute() == dataset.root
    for problem in (
        _check_splits(dataset, whole)
        + (_check_dataset_file(dataset) if whole else [])
        + _unlabelled_scenes(dataset, whole)
    ):
        emit(problem)
    scenes = dataset.scenes
    bar = tqdm(
        total=len(scenes),
        desc="validate",
        unit="scene",
        file=sys.stderr,
        disable=None if progress and len(scenes) > 1 else True,
    )
    tasks = [(scene.path, scene.group, scene.root, quick, box_tolerance) for scene in scenes]
    with in_scene_order(_validate_scene_at, tasks, scenes, workers) as reports:
        for scene, part in zip(scenes, reports):
            report.scenes += part.scenes
            report.views += part.views
            report.boxes += part.boxes
            for problem in part.problems:
                emit(problem)
            if part.views:  # an unreadable annotations.json is reported already
                counts[scene.id] = part.views
            bar.update()
    bar.close()
    for problem in _check_counts(dataset, counts):
        emit(problem)
    return report


def _validate_scene_at(task: tuple[Path, str, Path | None, bool, int | None]) -> Report:
    """:func:`validate_scene` of one scene rebuilt from its folder (in a pool's process, or here)."""
    path, group, root, quick, box_tolerance = task
    return validate_scene(Scene(path, group, root), quick, box_tolerance)

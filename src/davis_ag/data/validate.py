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

import sys
from collections.abc import Callable
from pathlib import Path

from pydantic import ValidationError

from davis_ag.data.class_checks import class_problems
from davis_ag.data.dataset_checks import check_counts, check_dataset_file, check_splits, unlabelled_scenes
from davis_ag.data.pixel_checks import (
    boxes_inside,
    camera_size,
    depth_problems,
    image_problems,
    mask_problems,
    mask_type_problems,
    read_mask,
)
from davis_ag.data.problems import Problem, Report, outside_reason, read_json_file
from davis_ag.data.reader import (
    ANNOTATIONS,
    SCENE_METADATA,
    Scene,
    ViewRecord,
    normalise_view_name,
    open_dataset,
    parse_entry,
)
from davis_ag.data.validate_pool import in_scene_order
from davis_ag.formats.layout import IMAGES, view_file, view_of_file
from davis_ag.formats.masks import MAX_FRUIT_ID, mask_dtype, max_fruit_id
from davis_ag.formats.models import AnnotationEntry, one_line
from davis_ag.formats.scene_file import SceneFile, scene_file_from
from davis_ag.scene.organs import ORGAN_NAMES


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
    outside = outside_reason(ann_path, scene.root)
    if outside:
        flag(ann_path, outside)
        return report
    raw, error = read_json_file(ann_path)
    if error is None and (not isinstance(raw, dict) or not raw):
        error = "must be a non-empty JSON object keyed by image name"
    if error is not None or not isinstance(raw, dict):
        flag(ann_path, error or "unreadable")
        return report

    metadata: SceneFile | None = None
    if (scene.path / SCENE_METADATA).is_file():
        raw_metadata, error = (
            (None, outside)
            if (outside := outside_reason(scene.path / SCENE_METADATA, scene.root))
            else read_json_file(scene.path / SCENE_METADATA)
        )
        if error is None:
            try:
                metadata = scene_file_from(raw_metadata)
            except ValueError as invalid:
                error = str(invalid)
        if error:
            flag(scene.path / SCENE_METADATA, error)
    tolerance = box_tolerance if box_tolerance is not None else (0 if metadata is not None else 1)
    id_limit = _fruit_id_limit(metadata)

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
        box_problems = _box_schema_problems(record, id_limit)
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
            if present and (outside := outside_reason(path, scene.root)):
                flag(path, outside)
        # A link out of the dataset is never decoded.
        has_image = has_image and not outside_reason(image, scene.root)
        has_mask = has_mask and not outside_reason(mask, scene.root)
        if not image.is_file():
            flag(image, f"missing: annotations.json has an entry {record.name} for it")
        if not mask.is_file():
            flag(mask, f"missing: the instance mask of {record.name}")
        depth = view_file(scene.path, record.name, "depth")
        if metadata is not None and metadata.depth and not depth.is_file():
            flag(depth, f"missing: scene.json records depth images but {record.name} has none")
        classes = view_file(scene.path, record.name, "classes")
        if metadata is not None and metadata.classes and not classes.is_file():
            flag(classes, f"missing: scene.json records organ class images but {record.name} has none")
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
        elif mask is not None:
            for problem in mask_type_problems(mask, metadata):
                flag(mask_path, problem)
            if size is not None:
                for problem in mask_problems(record, mask, size, tolerance):
                    flag(mask_path, problem)
    for kind, check in (
        ("depth", lambda path: depth_problems(record, path, mask, metadata)),
        ("classes", lambda path: class_problems(path, mask, _class_table(metadata))),
    ):
        path = view_file(scene.path, record.name, kind)
        if not path.is_file():
            continue
        outside = outside_reason(path, scene.root)  # a link out of the dataset is never decoded
        for problem in [outside] if outside else check(path):
            flag(path, problem)


def _class_table(metadata: SceneFile | None) -> tuple[str, ...]:
    """The class table a scene records (a scene without a structure has none of class 9), or the
    whole table where it records none."""
    table = (metadata.classes or {}).get("table") if metadata is not None else None
    if isinstance(table, list) and table and all(isinstance(name, str) for name in table):
        return tuple(table)
    return ORGAN_NAMES


def _name_or_key(key: str) -> str:
    try:
        return normalise_view_name(key)
    except ValueError:
        return key


def _fruit_id_limit(metadata: SceneFile | None) -> tuple[int, str]:
    """The largest fruit id a scene's boxes may name, and its mask type in words: the rule of
    :mod:`davis_ag.formats.masks` for the fruit count scene.json records, else any 16-bit id."""
    if metadata is not None and metadata.fruits:
        try:
            dtype = mask_dtype(len(metadata.fruits))
        except ValueError:  # more fruit than any mask holds: the mask check says so
            return MAX_FRUIT_ID, "uint16"
        return max_fruit_id(dtype), dtype.name
    return MAX_FRUIT_ID, "uint16"


def _box_schema_problems(record: ViewRecord, id_limit: tuple[int, str] = (MAX_FRUIT_ID, "uint16")) -> list[str]:
    largest, dtype = id_limit
    problems = []
    seen: set[int] = set()
    for box in record.boxes:
        where = f"{record.name}: box {box.to_list()[:5]}"
        if box.width < 1 or box.height < 1:
            problems.append(f"{where} has no area")
        if box.xmin < 0 or box.ymin < 0:
            problems.append(f"{where} starts outside the image")
        if not 0 <= box.fruit_id <= largest:
            problems.append(f"{where}: fruit id must be 0..{largest} to fit the {dtype} mask")
        if box.fruit_id in seen:
            problems.append(f"{where}: fruit {box.fruit_id} has two boxes in this view")
        seen.add(box.fruit_id)
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

    whole = dataset.opened == dataset.root
    for problem in (
        check_splits(dataset, whole)
        + (check_dataset_file(dataset) if whole else [])
        + unlabelled_scenes(dataset, whole)
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
    for problem in check_counts(dataset, counts):
        emit(problem)
    return report


def _validate_scene_at(task: tuple[Path, str, Path | None, bool, int | None]) -> Report:
    """:func:`validate_scene` of one scene rebuilt from its folder (in a pool's process, or here)."""
    path, group, root, quick, box_tolerance = task
    return validate_scene(Scene(path, group, root), quick, box_tolerance)

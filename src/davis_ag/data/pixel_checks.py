"""Checks that decode a view's pixels: its image, its instance mask against its boxes, its depth
image against the fruit centres of scene.json. :func:`davis_ag.data.validate.validate_scene`
decodes each file once and hands the mask to every check that needs it.

Box against mask: our writer makes each box exactly the inclusive pixel extent of its fruit's
mask pixels; the original download's boxes may differ by a pixel (``tolerance``).
"""

from __future__ import annotations

from pathlib import Path

import numpy as np

from davis_ag.data.reader import Box, ViewRecord, boxes_from_mask
from davis_ag.errors import UserError
from davis_ag.formats.layout import read_depth_millimetres
from davis_ag.formats.masks import fruit_pixels, mask_dtype, mask_from_image, no_fruit_value
from davis_ag.formats.scene_file import SceneFile

#: Depth images: surfaces nearer than this cannot be seen (the renderers' near plane), mm.
DEPTH_NEAR_MM = 50
#: A fruit's depth in the image may differ from its centre's by its half size plus this, m.
DEPTH_SLACK_M = 0.02


def camera_size(metadata: SceneFile | None) -> tuple[int, int] | None:
    """The image size scene.json's camera gives, or None without scene.json."""
    return metadata.image_size() if metadata is not None else None


def boxes_inside(record: ViewRecord, size: tuple[int, int]) -> list[str]:
    """One reason per box of ``record`` that reaches past an image of ``size`` (width, height)."""
    width, height = size
    return [
        f"{record.name}: box {b.to_list()[:5]} reaches past the {width}x{height} image"
        for b in record.boxes
        if b.xmax >= width or b.ymax >= height
    ]


def image_problems(image: Path, metadata: SceneFile | None) -> tuple[tuple[int, int] | None, list[str]]:
    """Decode a view's JPEG (at 1/8 scale: every byte is still read, so truncation shows).

    Returns:
        Its ``(width, height)`` (None when it cannot be decoded) and one reason per problem.
    """
    from PIL import Image

    try:
        with Image.open(image) as im:
            size, mode = im.size, im.mode
            im.draft("RGB", (max(1, size[0] // 8), max(1, size[1] // 8)))
            im.load()
    except Exception as error:  # Pillow raises many types for a damaged file
        return None, [f"cannot decode ({error})"]
    problems = [] if mode == "RGB" else [f"must be RGB, got mode {mode}"]
    expected = camera_size(metadata)
    if expected and size != expected:
        problems.append(f"is {size[0]}x{size[1]} but scene.json's camera says {expected[0]}x{expected[1]}")
    return size, problems


def read_mask(mask_path: Path) -> tuple[np.ndarray | None, str | None]:
    """An instance mask as a 2-D uint8 or uint16 array (:mod:`davis_ag.formats.masks`), or None
    and the reason it is not one."""
    from PIL import Image

    try:
        with Image.open(mask_path) as im:
            mode, mask = im.mode, np.asarray(im)
    except Exception as error:
        return None, f"cannot decode ({error})"
    return mask_from_image(mode, mask)


def mask_type_problems(mask: np.ndarray, metadata: SceneFile | None) -> list[str]:
    """A mask's integer type against the rule of :mod:`davis_ag.formats.masks` for the fruit count
    scene.json records (uint8 up to 255 fruit, uint16 above); no check without recorded fruit."""
    if metadata is None or not metadata.fruits:
        return []
    count = len(metadata.fruits)
    try:
        expected = mask_dtype(count)
    except ValueError as error:
        return [str(error)]
    if mask.dtype == expected:
        return []
    return [
        f"is {mask.dtype.name} but scene.json records {count} fruit, whose masks are "
        f"{expected.name} ({no_fruit_value(expected)} = no fruit)"
    ]


def mask_problems(record: ViewRecord, mask: np.ndarray, size: tuple[int, int], tolerance: int) -> list[str]:
    """A mask against its image's size and its view's boxes: every boxed fruit has pixels, every
    fruit's pixels have a box, and each box is its pixels' extent within ``tolerance``."""
    if mask.shape[::-1] != size:
        return [f"is {mask.shape[1]}x{mask.shape[0]} but its image is {size[0]}x{size[1]}"]
    problems = []
    extents = boxes_from_mask(mask)
    boxes = {b.fruit_id: b for b in record.boxes}
    for fid in sorted(set(extents) - set(boxes)):
        problems.append(f"holds fruit {fid}, which has no box in {record.name}")
    for fid, box in boxes.items():
        if fid not in extents:
            problems.append(f"has no pixels of fruit {fid}, which has a box in {record.name}")
        elif not _close(box, extents[fid], tolerance):
            m = extents[fid]
            problems.append(
                f"{record.name}: box of fruit {fid} is {box.to_list()[:4]} but its mask "
                f"pixels span {[m.xmin, m.ymin, m.width, m.height]} (x, y, width, height)"
            )
    return problems


def _close(box: Box, extent: Box, tolerance: int) -> bool:
    edges = zip((box.xmin, box.ymin, box.xmax, box.ymax), (extent.xmin, extent.ymin, extent.xmax, extent.ymax))
    return all(abs(a - b) <= tolerance for a, b in edges)


def depth_problems(
    record: ViewRecord, depth_path: Path, mask: np.ndarray | None, metadata: SceneFile | None
) -> list[str]:
    """Check a depth image: 16-bit, the image's size, a plausible range, and agreement with the
    3-D centres of the fruit scene.json records (where a fruit is boxed in the view).

    Args:
        record: The view's annotation.
        depth_path: ``images/NNNN_depth.png``.
        mask: Its instance mask (:func:`read_mask`), when present and readable.
        metadata: scene.json, when present.

    Returns:
        One reason per problem.
    """
    try:
        depth = read_depth_millimetres(depth_path)
    except UserError as error:  # the reason, without the path the report already names
        return [str(error).removeprefix(f"{depth_path}: ").removesuffix("; regenerate the scene")]
    problems = []
    size = camera_size(metadata)
    if size and depth.shape[::-1] != size:
        problems.append(f"is {depth.shape[1]}x{depth.shape[0]} but scene.json's camera says {size[0]}x{size[1]}")
        return problems
    hit = depth > 0
    if not hit.any():
        problems.append("holds no surface at all (every pixel 0)")
    elif int(depth[hit].min()) < DEPTH_NEAR_MM:
        problems.append(f"holds a surface {int(depth[hit].min())} mm from the camera, nearer than any renderer draws")
    # Against the pose and the fruit's centres only where those are whole (a short pose or a
    # centre without three numbers is reported by the schema checks; a mask holds ids below its
    # no-fruit value).
    if mask is None or metadata is None or record.pose is None or len(record.pose) < 5 or mask.shape != depth.shape:
        return problems
    fruits = {
        f.id: f
        for f in metadata.fruits
        if f.id is not None and 0 <= f.id < no_fruit_value(mask) and f.center is not None and len(f.center) == 3
    }
    x, y, z, yaw, pitch = (float(v) for v in record.pose[:5])
    forward = np.array(
        [
            np.cos(np.radians(pitch)) * np.cos(np.radians(yaw)),
            np.cos(np.radians(pitch)) * np.sin(np.radians(yaw)),
            np.sin(np.radians(pitch)),
        ]
    )
    seen_mm = _median_depth_by_fruit(mask, depth, hit, [b.fruit_id for b in record.boxes if b.fruit_id in fruits])
    for fruit_id in (b.fruit_id for b in record.boxes if b.fruit_id in seen_mm):
        fruit = fruits[fruit_id]
        assert fruit.center is not None  # kept above only with its centre
        expected = float(np.dot(np.subtract(fruit.center, (x, y, z)), forward))
        seen = seen_mm[fruit_id] / 1000.0
        allowed = 0.5 * float(np.linalg.norm(fruit.size or (0.0, 0.0, 0.0))) + DEPTH_SLACK_M
        if abs(seen - expected) > allowed:
            problems.append(
                f"fruit {fruit_id} lies at {seen:.3f} m in the depth image but its centre is "
                f"{expected:.3f} m from the camera (scene.json), more than {allowed:.3f} m apart"
            )
    return problems


def _median_depth_by_fruit(
    mask: np.ndarray, depth: np.ndarray, hit: np.ndarray, fruit_ids: list[int]
) -> dict[int, float]:
    """The median depth (mm) of each fruit's pixels that hit a surface, for the fruits of
    ``fruit_ids`` that have any: one pass over the image, not one per fruit."""
    wanted = np.zeros(no_fruit_value(mask) + 1, dtype=bool)
    wanted[fruit_ids] = True
    seen = np.flatnonzero(fruit_pixels(mask).ravel())  # a few per cent of the image
    labels, values = mask.ravel()[seen], depth.ravel()[seen]
    kept = wanted[labels] & hit.ravel()[seen]
    labels, values = labels[kept], values[kept]
    order = np.argsort(labels, kind="stable")
    labels, values = labels[order], values[order]
    found, starts = np.unique(labels, return_index=True)
    groups = np.split(values, starts[1:])
    return {int(fruit): float(np.median(group)) for fruit, group in zip(found, groups)}

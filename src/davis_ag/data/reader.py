"""Read a DAVIS-Ag dataset: what we generate and the original download alike.

Annotations are read when a scene's views are first asked for, pixels when an image or mask
is. The original README leaves some details open, so the reader accepts image names with or
without ".jpeg" (keys and pointer values), a missing pointer key as an invalid move, float box
values, a missing pose, a missing ``_seg.png`` and unknown keys. Anything it cannot make sense
of raises :class:`~davis_ag.errors.UserError` naming the file and the entry.

The pure parsers and box helpers live in :mod:`davis_ag.data.annotation_schema` and are re-exported
here, so ``from davis_ag.data.reader import Box, exposure_rate`` works.
"""

from __future__ import annotations

import os
from collections.abc import Iterator, Sequence
from dataclasses import dataclass, field
from functools import cached_property
from pathlib import Path
from typing import Any, overload

import numpy as np
from pydantic import ValidationError

from davis_ag.data.annotation_schema import (
    NO_FRUIT,
    Box,
    ViewRecord,
    boxes_from_mask,
    exposure_rate,
    normalise_view_name,
    parse_box,
    parse_entry,
    parse_pose,
)
from davis_ag.data.safe_read import check_inside, load_pixels, read_json
from davis_ag.errors import UserError
from davis_ag.formats.layout import ANNOTATIONS, IMAGES, SCENE_METADATA, read_depth, view_file, view_stem
from davis_ag.formats.layout import SPLITS_FILE as SPLITS
from davis_ag.formats.models import SplitsFile, one_line
from davis_ag.formats.scene_file import SceneFile, parse_scene_file
from davis_ag.scene import specs as config

__all__ = [
    "ANNOTATIONS",
    "NO_FRUIT",
    "SCENE_METADATA",
    "SPLITS",
    "Box",
    "Dataset",
    "NotFoundError",
    "Scene",
    "View",
    "ViewRecord",
    "boxes_from_mask",
    "exposure_rate",
    "normalise_view_name",
    "open_dataset",
    "parse_box",
    "parse_entry",
    "parse_pose",
    "read_json",
]


class NotFoundError(UserError, KeyError):
    """A scene or view that is not in the dataset; also a ``KeyError`` for ``dict``-minded callers."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


def _view_order(name: str) -> tuple[int, str]:
    stem = view_stem(name)
    return (int(stem), name) if stem.isascii() and stem.isdigit() else (1 << 62, name)


@dataclass(eq=False)
class View:
    """One camera view of a scene: its annotation, and its pixels decoded on each call.

    The pixels are methods of one kind: :meth:`image`, :meth:`mask`, :meth:`depth` and
    :meth:`classes` each decode their file when called and keep nothing, so a pass over a whole
    dataset holds one view's pixels at a time.

    Attributes:
        name: Image name, e.g. ``"0001.jpeg"``.
        scene: The scene it belongs to.
        pose: ``(x, y, z, yaw_deg, pitch_deg)``, or ``None`` where the annotation has none.
        boxes: Fruit boxes, in file order.
        pointers: Every action of the scene to the image name it leads to, "" where invalid.
    """

    name: str
    scene: Scene = field(repr=False)
    pose: tuple[float, ...] | None
    boxes: tuple[Box, ...]
    pointers: dict[str, str]

    @property
    def image_path(self) -> Path:
        """Where the RGB image is (``images/0001.jpeg``)."""
        return self.scene.path / IMAGES / self.name

    @property
    def mask_path(self) -> Path:
        """Where the instance mask is (``images/0001_seg.png``), whether or not it exists."""
        return view_file(self.scene.path, self.name, "mask")

    @property
    def depth_path(self) -> Path:
        """Where the depth image is (``images/0001_depth.png``), whether or not it exists."""
        return view_file(self.scene.path, self.name, "depth")

    def depth(self) -> np.ndarray | None:
        """Decode the depth image: ``H x W`` float32 metres along the optical axis, 0 where nothing
        is hit; ``None`` where the dataset has no depth (the original download, ``--no-depth``).

        Raises:
            UserError: when the file exists but cannot be read or is not 16-bit.
        """
        if not self.depth_path.is_file():
            return None
        return read_depth(check_inside(self.depth_path, self.scene.root))

    @property
    def class_path(self) -> Path:
        """Where the organ class image is (``images/0001_class.png``), whether or not it exists."""
        return view_file(self.scene.path, self.name, "classes")

    def classes(self) -> np.ndarray | None:
        """Decode the organ class image: ``H x W`` uint8, one value per class of
        :data:`davis_ag.scene.organs.ORGAN_NAMES` (0 sky, 1 soil, 2 fruit, 3 leaf, 4 stem, 5 trunk,
        6-8 petiole, peduncle, flower, 9 structure);
        ``None`` where the dataset has none (the original download, datasets made before it).

        Raises:
            UserError: when the file exists but cannot be read or is not 8-bit single-channel.
        """
        if not self.class_path.is_file():
            return None
        classes = load_pixels(check_inside(self.class_path, self.scene.root), None)
        if classes.dtype != np.uint8 or classes.ndim != 2:
            raise UserError(
                f"{self.class_path}: a class image must be an 8-bit single-channel PNG; regenerate the scene"
            )
        return classes

    def next(self, action: str) -> View | None:
        """The view an action leads to.

        Args:
            action: One of :data:`davis_ag.scene.specs.ALL_ACTIONS`.

        Returns:
            The target view, or ``None`` where the move is invalid (or the scene lacks the action).

        Raises:
            UserError: for an unknown action or a pointer that names no view of the scene.
        """
        if action not in config.ALL_ACTIONS:
            raise UserError(f"unknown action {action!r}: choose one of {', '.join(config.ALL_ACTIONS)}")
        target = self.pointers.get(action, "")
        if not target:
            return None
        found = self.scene.views.get(target)
        if found is None:
            raise UserError(
                f"{self.scene.path / ANNOTATIONS}: {self.name}: {action} points to {target}, "
                "which is not a view of this scene; run `davis-ag validate` on it"
            )
        return found

    def box(self, fruit_id: int) -> Box | None:
        """The box of a fruit in this view, or ``None`` where the fruit has none."""
        return next((b for b in self.boxes if b.fruit_id == fruit_id), None)

    def image(self) -> np.ndarray:
        """Decode the image.

        Returns:
            ``H x W x 3`` uint8 RGB array.

        Raises:
            UserError: when the file is missing or unreadable.
        """
        return load_pixels(check_inside(self.image_path, self.scene.root), "RGB")

    def mask(self) -> np.ndarray | None:
        """Decode the instance mask.

        Returns:
            ``H x W`` fruit id per pixel, or ``None`` without a mask file: uint8 with 255 for none,
                or uint16 with 65535 for none in a scene of more than 255 fruit
                (:mod:`davis_ag.formats.masks`; ``fruit_pixels(mask)`` is where a fruit is seen).

        Raises:
            UserError: when the file exists but cannot be read.
        """
        if not self.mask_path.is_file():
            return None
        return load_pixels(check_inside(self.mask_path, self.scene.root), None)


@dataclass(eq=False)
class Scene(Sequence["View"]):
    """One scene folder (``<group>/<NNN>``); its annotations load on first use.

    A scene is the sequence of its views in image order: ``scene[0]`` is the first view
    (``scene.view(1)``, ``0001.jpeg``), ``len(scene)`` counts them, ``for view in scene`` walks them.

    Attributes:
        path: The scene folder.
        group: Its group folder's name, e.g. ``Single-Strawberry``.
        root: The dataset root; files resolving outside it are refused (None: no check).
    """

    path: Path
    group: str
    root: Path | None = None

    @property
    def id(self) -> str:
        """``"<group>/<scene>"``, e.g. ``"Single-Strawberry/000"``."""
        return f"{self.group}/{self.path.name}"

    @cached_property
    def _specs(self) -> tuple[config.ScenarioSpec, config.CropSpec] | None:
        return config.parse_group_name(self.group)

    @property
    def scenario(self) -> str | None:
        """``"sp"``, ``"mp"`` or ``"row"`` from the group name; ``None`` for an unknown group name."""
        return self._specs[0].name if self._specs else None

    @property
    def crop(self) -> str | None:
        """The crop's name (``"strawberry"``, ``"apple-wall"``...); ``None`` for an unknown group name."""
        return self._specs[1].name if self._specs else None

    @property
    def annotations_path(self) -> Path:
        """The scene's annotations.json."""
        return self.path / ANNOTATIONS

    def raw_annotations(self) -> dict[str, Any]:
        """The annotations.json object as stored (for validators and converters).

        Raises:
            UserError: when it is unreadable, not JSON or not a JSON object.
        """
        raw = read_json(check_inside(self.annotations_path, self.root), "annotations")
        if not isinstance(raw, dict):
            raise UserError(
                f"{self.annotations_path}: must hold a JSON object keyed by image name, "
                f"got {type(raw).__name__}; re-download or regenerate the scene"
            )
        return raw

    @cached_property
    def views(self) -> dict[str, View]:
        """Every view, name to :class:`View`, in image order.

        Raises:
            UserError: naming the file and entry, when an entry cannot be read.
        """
        records = []
        for key, entry in self.raw_annotations().items():
            try:
                records.append(parse_entry(key, entry))
            except ValueError as error:
                raise UserError(
                    f"{self.annotations_path}: entry {key!r}: {error}; run `davis-ag validate` for every problem"
                ) from None
        records.sort(key=lambda r: _view_order(r.name))
        present = {a for r in records for a in r.pointers}
        actions = tuple(a for a in config.ALL_ACTIONS if a in present)
        if not actions:
            actions = self._specs[0].actions if self._specs else config.SP_ACTIONS
        self._actions = actions
        return {
            r.name: View(r.name, self, r.pose, r.boxes, {a: r.pointers.get(a, "") for a in actions}) for r in records
        }

    @property
    def actions(self) -> tuple[str, ...]:
        """The pointer keys the scene's views carry, in :data:`davis_ag.scene.specs.ALL_ACTIONS` order."""
        _ = self.views
        return self._actions

    def view(self, name: str | int) -> View:
        """Look a view up by ``"0001"``, ``"0001.jpeg"`` or 1-based number ``1``.

        Raises:
            NotFoundError: when the scene has no such view.
        """
        try:
            key = normalise_view_name(name)
        except ValueError as error:
            raise NotFoundError(f"scene {self.id}: {error}") from None
        if key not in self.views:
            names = list(self.views)
            span = f"{names[0]} .. {names[-1]}" if names else "none"
            raise NotFoundError(f"scene {self.id} has no view {name!r} (its views: {span})")
        return self.views[key]

    @cached_property
    def metadata(self) -> SceneFile | None:
        """Our scene.json (seed, camera, plants, fruits, visible_fraction...), read through its model.

        Returns:
            ``None`` where the scene has none (the original download never has).

        Raises:
            UserError: when scene.json exists but does not fit :class:`~davis_ag.formats.scene_file.SceneFile`.
        """
        path = self.path / SCENE_METADATA
        if not path.is_file():
            return None
        return parse_scene_file(read_json(check_inside(path, self.root), "scene metadata"), path)

    @cached_property
    def _ordered(self) -> tuple[View, ...]:
        return tuple(self.views.values())

    @overload
    def __getitem__(self, position: int) -> View: ...

    @overload
    def __getitem__(self, position: slice) -> Sequence[View]: ...

    def __getitem__(self, position: int | slice) -> View | Sequence[View]:
        """The view at a position from 0 (``scene[0]`` is ``0001.jpeg``), or a slice of them; a name
        raises TypeError (names go to :meth:`view`), a position past the last view IndexError."""
        if isinstance(position, str):
            raise TypeError(f"scene[{position!r}]: positions are numbers from 0; use scene.view({position!r})")
        try:
            return self._ordered[position]
        except IndexError:
            raise IndexError(f"scene {self.id} has {len(self)} views: no position {position}") from None

    def __len__(self) -> int:
        return len(self.views)

    def __iter__(self) -> Iterator[View]:
        return iter(self.views.values())

    def __repr__(self) -> str:
        return f"Scene({self.id!r}, path={str(self.path)!r})"


@dataclass(eq=False)
class Dataset:
    """The scenes found under one path.

    Attributes:
        root: The dataset root (the folder holding group folders), also when a group or scene
            folder was opened.
        scenes: The scenes under the opened path, sorted by id.
        opened: The folder opened: the root, a group folder or a scene folder (None: the root).
    """

    root: Path
    scenes: list[Scene]
    opened: Path | None = None

    def scene(self, scene_id: str) -> Scene:
        """Look a scene up by id, e.g. ``"Single-Strawberry/000"``.

        Raises:
            NotFoundError: when no scene has that id.
        """
        for scene in self.scenes:
            if scene.id == scene_id.strip("/").replace("\\", "/"):
                return scene
        known = ", ".join(s.id for s in self.scenes[:3]) + (" ..." if len(self.scenes) > 3 else "")
        raise NotFoundError(f"{self.root}: no scene {scene_id!r} (scenes: {known or 'none'})")

    @cached_property
    def splits(self) -> SplitsFile | None:
        """Our splits.json as its model (``seed``, ``train`` and ``test`` scene ids), or ``None`` without one.

        Raises:
            UserError: when the file exists but does not fit :class:`~davis_ag.formats.models.SplitsFile`.
        """
        path = self.root / SPLITS
        if not path.is_file():
            return None
        data = read_json(check_inside(path, self.root), "splits")
        try:
            return SplitsFile.model_validate(data)
        except ValidationError as error:
            raise UserError(
                f"{one_line(error, str(path))}; fix or delete it (a list of scene ids like "
                '"Single-Strawberry/000" for train and for test)'
            ) from None

    def __len__(self) -> int:
        return len(self.scenes)

    def __iter__(self) -> Iterator[Scene]:
        return iter(self.scenes)


def _scene_dirs(folder: Path) -> list[Path]:
    return sorted(p for p in folder.iterdir() if p.is_dir() and (p / ANNOTATIONS).is_file())


def open_dataset(path: str | os.PathLike[str]) -> Dataset:
    """Open a dataset root, a group folder (``Single-Strawberry``) or a single scene folder.

    Args:
        path: The folder.

    Returns:
        The opened dataset (:class:`Dataset`); nothing but folder names is read yet.

    Raises:
        UserError: when the path does not exist or holds no DAVIS-Ag scene.
    """
    path = Path(os.path.normpath(Path(path).expanduser().absolute()))  # `G/000/..` is G, not a scene
    if not path.exists():
        raise UserError(f"{path}: no such folder; give the dataset root, a group folder or a scene folder")
    if not path.is_dir():
        raise UserError(f"{path}: is a file; give the folder that holds it")
    try:
        if (path / ANNOTATIONS).is_file():
            root, scenes = path.parent.parent, [Scene(path, path.parent.name, path.parent.parent)]
        elif scene_dirs := _scene_dirs(path):
            root, scenes = path.parent, [Scene(p, path.name, path.parent) for p in scene_dirs]
        else:
            scenes = [Scene(s, g.name, path) for g in sorted(path.iterdir()) if g.is_dir() for s in _scene_dirs(g)]
            root = path
    except OSError as error:  # a folder we may not list
        raise UserError(f"{error.filename or path}: cannot list ({error.strerror}); check its permissions") from None
    if not scenes:
        raise UserError(
            f"{path}: not a DAVIS-Ag dataset: no {ANNOTATIONS} in it, in its sub-folders or theirs; "
            f"give the root that holds e.g. Single-Strawberry/000/{ANNOTATIONS}, a group folder "
            "or a scene folder"
        )
    scenes.sort(key=lambda s: s.id)
    return Dataset(root, scenes, path)

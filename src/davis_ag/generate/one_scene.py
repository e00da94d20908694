"""Generate DAVIS-Ag scenes: grow, lay out the grid, draw every view, label it and write it.

Seeds: a dataset seed, the scenario, the crop and the scene's index determine the scene's seed
(:func:`scene_seed`), so any one scene can be regenerated alone; the scene seed drives every
random choice of that scene (phenotypes, Helios seeds, sun, slip) and is saved in scene.json.
"""

from __future__ import annotations

import json
import platform
import time
from collections.abc import Callable
from dataclasses import asdict, dataclass, field, fields
from pathlib import Path
from typing import Any

import numpy as np

from davis_ag.errors import UserError
from davis_ag.formats.layout import published_pointers, view_name
from davis_ag.formats.masks import segmentation_convention
from davis_ag.formats.models import AnnotationEntry
from davis_ag.formats.scene_file import (
    SCENE_FORMAT,
    CameraRecord,
    GeneratorRecord,
    GridRecord,
    RendererRecord,
    SceneFile,
    ViewPlace,
)
from davis_ag.generate.scene_writer import SceneWriter
from davis_ag.labels.fruit_labels import fruit_lookup, label_view, visible_fractions
from davis_ag.provenance import code_version
from davis_ag.render.backends import ANTIALIASING_DESCRIPTIONS, DEFAULT_RENDERER, open_renderer, resolve_look
from davis_ag.render.egl_context import renderer_name
from davis_ag.scene.appearance import draw_appearance, resolve_appearance
from davis_ag.scene.build import build_scene
from davis_ag.scene.camera import Camera
from davis_ag.scene.organs import SKY, scene_organ_names
from davis_ag.scene.specs import (
    CROPS,
    DEFAULT_PLANTS,
    SCENARIOS,
    CropSpec,
    ScenarioSpec,
    camera_altitudes,
    plant_centres,
    scene_folder,
)
from davis_ag.scene.structures import DEFAULT_STRUCTURES, builds_something, check_structures
from davis_ag.scene.view_grid import build_view_grid
from davis_ag.seeds import COVER_STREAM, derived_seed, stream_rng

CONVENTIONS = {
    "units": {"length": "m", "angle": "deg"},
    "world_frame": "x east, y north, z up; ground at z = 0; single plant at the origin, "
    "multi-plant row along x centred on the origin",
    "pose": "[x, y, z, yaw, pitch]: camera position after slip; yaw counter-clockwise from +x; "
    "pitch above the horizon (negative looks down)",
    "box": "[xmin, ymin, width, height, fruit_id, 0]: inclusive pixel extent, row 0 at the top",
    # A scene of more than 255 fruit says uint16 and 65535 (scene_metadata: davis_ag.formats.masks).
    "segmentation": segmentation_convention(0),
    "grid": "staggered lattice: rows step apart along y, numbered from -y, odd rows shifted half a "
    "step along +x; positions within the exclusion radius (2-D) of a stem are left out",
    "actions_sp": "forward +y, backward -y to the next row at the same column index (half a step "
    "sideways on the staggered lattice), right +x, left -x (world-fixed), up/down "
    "between altitudes",
    "actions_mp": "forward along the lattice axis nearest the heading (a row move zigzags as in SP), "
    "backward opposite, left 90 deg counter-clockwise of forward, right clockwise; "
    "rotate_ccw +30 deg, rotate_cw -30 deg",
    "visible_fraction": "visible pixels of a fruit over the pixels it would cover with nothing in front",
    "depth": "images/NNNN_depth.png: uint16 millimetres from the camera plane along the optical axis "
    "(camera-space z), 0 where nothing is hit, 65535 for 65.535 m or more; row 0 at the top",
}


def conventions(organ_names: tuple[str, ...]) -> dict[str, Any]:
    """The conventions a scene.json records, its class table among them."""
    table = ", ".join(f"{value} {name}" for value, name in enumerate(organ_names))
    return {
        **CONVENTIONS,
        "classes": f"images/NNNN_class.png: uint8 organ class per pixel ({table}), from the same pass as the ids",
    }


@dataclass(frozen=True, kw_only=True)
class SceneSettings:
    """How a dataset's scenes are made, whichever scene: shared by :class:`SceneRequest` and the
    dataset config (:class:`davis_ag.generate.run_config.DatasetConfig`), keyword-only so each
    keeps its own positional fields first.

    Attributes:
        renderer: ``opengl`` (ours) or ``helios`` (pyhelios's Visualizer, the reference).
        look: ``default`` or ``helios`` (see :mod:`davis_ag.render.backends`); None: the
            renderer's own (``default`` for ours, ``helios`` for Helios).
        depth: Write ``images/NNNN_depth.png`` for every view.
        antialiasing: Our renderer's antialiasing: ``fxaa``, ``msaa`` or ``none``.
        plants: The plant generator: ``canopy`` (default) or ``architecture``.
        appearance: ``paper`` or ``random`` (:mod:`davis_ag.scene.appearance`).
        structures: ``default`` (a ``row`` scene's trellis, stakes or strings) or ``none``
            (:mod:`davis_ag.scene.structures`).
    """

    renderer: str = DEFAULT_RENDERER
    look: str | None = None
    depth: bool = True
    antialiasing: str = "fxaa"
    plants: str = DEFAULT_PLANTS
    appearance: str = "paper"
    structures: str = DEFAULT_STRUCTURES

    def scene_settings(self) -> dict[str, Any]:
        """These settings alone, as keyword arguments of :class:`SceneRequest`."""
        return {f.name: getattr(self, f.name) for f in fields(SceneSettings)}


@dataclass(frozen=True)
class SceneRequest(SceneSettings):
    """Which scene to make, and how (the :class:`SceneSettings`, by keyword).

    Attributes:
        scenario, crop: What kind of scene.
        index: Scene number within its group (folder ``NNN``).
        dataset_seed: The dataset's seed.
        camera: Image size and field of view.
        classes: Write ``images/NNNN_class.png`` (organ classes) for every view.
    """

    scenario: ScenarioSpec
    crop: CropSpec
    index: int
    dataset_seed: int
    camera: Camera = field(default_factory=Camera)
    classes: bool = field(default=True, kw_only=True)

    def __post_init__(self) -> None:
        resolve_appearance(self.appearance)
        check_structures(self.structures)
        if not builds_something(self.scenario.name, self.crop, self.structures):
            # What the scene gets, not what was asked: a scene with nothing to build is a bare
            # one, and reads back from its scene.json as such.
            object.__setattr__(self, "structures", "none")
        if self.appearance != "paper" and self.renderer != "opengl":
            raise UserError(
                f"appearance {self.appearance} needs our renderer: drop --renderer {self.renderer} "
                "or use --appearance paper"
            )

    @property
    def seed(self) -> int:
        """This scene's own seed."""
        return scene_seed(self.dataset_seed, self.scenario, self.crop, self.index)

    @property
    def min_fruit_pixels(self) -> int:
        """The crop's box threshold at this image size (:meth:`CropSpec.min_fruit_pixels_at`)."""
        return self.crop.min_fruit_pixels_at(self.camera.width, self.camera.height)

    @property
    def folder(self) -> str:
        """Path of the scene folder below the dataset root."""
        return scene_folder(self.scenario, self.crop, self.index)


def scene_seed(dataset_seed: int, scenario: ScenarioSpec, crop: CropSpec, index: int) -> int:
    """Derive a scene's seed from the dataset seed; independent streams for every scene."""
    keys = [dataset_seed, list(SCENARIOS).index(scenario.name), list(CROPS).index(crop.name), index]
    return derived_seed(*keys)


def generate_scene(
    request: SceneRequest,
    root: Path,
    on_view: Callable[[int, int], None] | None = None,
) -> tuple[Path, dict]:
    """Make one scene and write it atomically under ``root``.

    Args:
        request: What to make.
        root: The dataset root.
        on_view: Called with (views done, views in all) after every view, for progress bars.

    Returns:
        The scene folder and timing statistics.
    """
    root = Path(root).absolute()  # Helios moves the working directory while it builds and closes
    started = time.perf_counter()
    model, grid = grow_scene(request)
    return draw_scene(request, model, grid, root, on_view, grow_s=time.perf_counter() - started)


def grow_scene(request: SceneRequest):
    """Grow a scene's plants and lay out its views, drawing from the scene's seed in a fixed order.

    Returns:
        The :class:`~davis_ag.scene.build.SceneModel` and its view grid.
    """
    rng = np.random.default_rng(request.seed)
    appearance = draw_appearance(request.appearance, request.seed)
    model = build_scene(
        request.scenario,
        request.crop,
        rng,
        request.plants,
        soil_texture=appearance.soil,
        structures=request.structures,
        cover_rng=stream_rng(request.seed, COVER_STREAM),
    )
    model.lighting = appearance.lighting(model.lighting)
    grid = build_view_grid(
        request.scenario, request.crop, plant_centres(request.scenario, request.crop), model.aim_height, rng
    )
    return model, grid


def draw_scene(
    request: SceneRequest,
    model,
    grid,
    root: Path,
    on_view: Callable[[int, int], None] | None = None,
    grow_s: float = 0.0,
    views: list | None = None,
) -> tuple[Path, dict]:
    """Draw, label and write every view of a grown scene, then publish the folder atomically.

    Args:
        request: What to make (renderer, look, depth, image size).
        model, grid: From :func:`grow_scene`.
        root: The dataset root.
        on_view: Called with (views done, views in all) after every view.
        grow_s: Seconds spent growing, for scene.json.
        views: Only these viewpoints of the grid (the benchmark); None for all.

    Returns:
        The scene folder and timing statistics.
    """
    root = Path(root).absolute()
    grown = time.perf_counter()
    viewpoints = list(grid.viewpoints if views is None else views)
    lookup = fruit_lookup({f.id: f.uuids for f in model.fruits}, model.uuid_count)
    polygons = {f.id: f.polygons for f in model.fruits}
    fruit_uuids = {f.id: f.uuids for f in model.fruits}
    # Organ class by id-buffer value (UUID + 1; 0 is the sky): the class image is one look-up.
    class_of_id = np.concatenate([[SKY], model.organ_of_uuid()]).astype(np.uint8) if request.classes else None
    camera = request.camera
    scene_dir = root / request.folder
    writer = SceneWriter(scene_dir, resume_key(request, viewpoints), [view_name(v.number) for v in viewpoints])
    # Views a crashed run of this same request left on disk are kept, not drawn again.
    visible: dict[str, dict[str, float]] = {name: record["extras"]["visible"] for name, record in writer.done.items()}
    try:
        look = resolve_look(request.renderer, request.look)
        with open_renderer(
            request.renderer, model.context, camera, model.lighting, look, request.antialiasing
        ) as renderer:
            for done, view in enumerate(viewpoints, 1):
                if view_name(view.number) in writer.done:
                    if on_view:
                        on_view(done, len(viewpoints))
                    continue
                colour, primitive_ids, depth = renderer.render(view, depth=request.depth)
                classes = class_of_id[primitive_ids] if class_of_id is not None else None
                labels = label_view(primitive_ids, lookup, request.min_fruit_pixels)
                draw_silhouette = getattr(renderer, "silhouette_pixels", None)
                silhouette = (
                    (lambda fruit_id, view=view, draw=draw_silhouette: draw(view, fruit_id, fruit_uuids[fruit_id]))
                    if draw_silhouette
                    else None
                )
                fractions = visible_fractions(camera, view, labels, polygons, silhouette)
                entry = AnnotationEntry.model_validate(
                    {
                        "bounding_boxes": labels.boxes,
                        "pose": [round(v, 5) for v in view.pose],
                        **published_pointers(grid, view.index),
                    }
                ).to_json()
                visible[view_name(view.number)] = {str(k): v for k, v in fractions.items()}
                writer.add_view(
                    view_name(view.number),
                    colour,
                    labels.segmentation,
                    entry,
                    depth if request.depth else None,
                    {"visible": visible[view_name(view.number)]},
                    classes=classes,
                )
                if on_view:
                    on_view(done, len(viewpoints))
            writer.wait()  # every image written before the Visualizer's teardown moves the cwd
        drawn = time.perf_counter()
        timing = {
            "grow": round(grow_s, 3),
            "draw_and_label": round(drawn - grown, 3),
            "views_from_an_earlier_run": len(writer.done),
        }
        writer.finish(scene_metadata(request, model, grid, visible, timing))
    except Exception:
        writer.abort()  # an error (a full disk, a bug): give the space back; the next run redoes it
        raise
    except BaseException:
        writer.abort(keep=True)  # a stop (Ctrl-C): the next run resumes from the views written
        raise
    stats = {
        "views": len(viewpoints),
        "grow_s": grow_s,
        "views_s": drawn - grown,
        "total_s": grow_s + time.perf_counter() - grown,
    }
    return scene_dir, stats


def resume_key(request: SceneRequest, viewpoints: list) -> dict:
    """What a scene's views are drawn from: a crashed run's views are reused only when it matches.

    The request, the views asked for and the code version (a changed generator or renderer may
    draw differently, so its views are not mixed with this one's).
    """
    return json.loads(
        json.dumps(
            {
                "request": asdict(request),
                "seed": request.seed,
                "code": code_version(),
                "views": [view_name(view.number) for view in viewpoints],
            },
            default=str,
        )
    )


def scene_metadata(request: SceneRequest, model, grid, visible: dict, timing: dict | None = None) -> SceneFile:
    """Our scene.json: everything the published annotations leave out.

    Args:
        request, model, grid: The scene as asked for, grown and laid out.
        visible: Per view name, per fruit id (text), the fruit's visible fraction.
        timing: Seconds spent growing and drawing.
    """
    import pyhelios

    lighting = model.lighting
    organ_names = scene_organ_names(model.structures is not None)
    record = SceneFile(
        format=SCENE_FORMAT,
        generator=GeneratorRecord(
            name="davis-ag",
            version=code_version(),
            pyhelios3d=pyhelios.__version__,
            python=platform.python_version(),
            # Pixels depend on the OpenGL implementation: `verify` on another one names both.
            # (Helios's Visualizer opens its own display, which $DAVIS_AG_EGL_DEVICE does not choose.)
            gl_renderer=renderer_name() if request.renderer == "opengl" else None,
        ),
        seed=request.seed,
        dataset_seed=request.dataset_seed,
        scenario=request.scenario.name,
        crop=request.crop.name,
        scene=request.folder,
        plant_generator=model.plant_generator,
        conventions={**conventions(organ_names), "segmentation": segmentation_convention(len(model.fruits))},
        camera=CameraRecord.model_validate(request.camera.intrinsics()),
        renderer=RendererRecord(
            name=request.renderer,
            look=resolve_look(request.renderer, request.look),
            antialiasing=ANTIALIASING_DESCRIPTIONS[request.antialiasing]
            if request.renderer == "opengl"
            else "Helios Visualizer, 4x multisampled colour",
        ),
        depth={
            "file": "images/NNNN_depth.png",
            "dtype": "uint16",
            "unit": "mm",
            "axis": "optical (camera-space z)",
            "no_hit": 0,
        }
        if request.depth
        else None,
        classes={"file": "images/NNNN_class.png", "dtype": "uint8", "table": list(organ_names)}
        if request.classes
        else None,
        appearance=draw_appearance(request.appearance, request.seed).summary(),
        lighting={
            "model": "phong_shadowed",
            "sun_elevation_deg": lighting.sun_elevation,
            "sun_azimuth_deg": lighting.sun_azimuth,
            "sun_direction": lighting.direction,
            "sun_strength": lighting.sun_strength,
            "exposure": lighting.exposure,
            "white_balance": list(lighting.white_balance),
            "sky_texture": Path(lighting.sky_texture).name if lighting.sky_texture else None,
        },
        grid=GridRecord(
            extent_m=list(request.scenario.extent),
            step_m=request.scenario.step,
            altitudes_m=camera_altitudes(request.scenario, request.crop),
            headings=request.scenario.headings,
            exclusion_radius_m=request.crop.exclusion_radius,
            aim_height_m=model.aim_height,
            views=len(grid.viewpoints),
        ),
        min_fruit_pixels=request.min_fruit_pixels,
        plants=[plant.summary() for plant in model.plants],
        fruits=[fruit.summary() for fruit in model.fruits],
        views={
            view_name(v.number): ViewPlace(grid=[v.ix, v.iy, v.level, v.heading], nominal=list(v.nominal))
            for v in grid.viewpoints
        },
        visible_fraction=visible,
    )
    # Set only when known, so that a record without them dumps without the keys (``as_written``).
    if timing is not None:
        record.timing_s = timing
    if model.structures is not None:  # only where one was built: a scene without records what it always did
        record.structures = model.structures
    return record

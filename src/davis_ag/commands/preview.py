"""``davis-ag preview``: render a few views of one scene, with fruit boxes drawn, without a dataset.

It grows the same scene ``generate`` would (same dataset seed, index and options give the same
plants, light, appearance and slip) and draws the chosen views, so a researcher can look before
rendering hundreds.
"""

from __future__ import annotations

import argparse

import numpy as np
from PIL import Image, ImageDraw

from davis_ag.atomic_files import atomic_output
from davis_ag.commands import arguments
from davis_ag.errors import UserError
from davis_ag.formats.layout import IMAGE_SUFFIX, JPEG_QUALITY, view_name, view_stem
from davis_ag.formats.outputs import check_outside_datasets, claim_output
from davis_ag.generate.one_scene import SceneRequest, grow_scene
from davis_ag.generate.run_progress import count_views
from davis_ag.labels.fruit_labels import fruit_lookup, label_view, visible_fractions
from davis_ag.render.backends import DEFAULT_RENDERER, open_renderer, resolve_look
from davis_ag.scene.appearance import DEFAULT_APPEARANCE
from davis_ag.scene.camera import Camera
from davis_ag.scene.organs import SKY
from davis_ag.scene.specs import (
    DEFAULT_PLANTS,
    CropSpec,
    ScenarioSpec,
    crop_spec,
    scenario_spec,
    with_strawberry_altitudes,
)
from davis_ag.scene.structures import DEFAULT_STRUCTURES

HELP = "render a few views of one scene with boxes drawn"
DESCRIPTION = __doc__


def add_arguments(parser: argparse.ArgumentParser) -> None:
    """Add ``preview``'s arguments to its ``parser`` (see :mod:`davis_ag.commands`)."""
    parser.add_argument(
        "--crop",
        default="strawberry",
        help="strawberry, tomato, vine or a plant-library crop (generate --help lists them)",
    )
    parser.add_argument("--scenario", default="sp", help="sp, mp or row")
    parser.add_argument("--seed", type=arguments.seed, default=0, help="dataset seed (default 0)")
    parser.add_argument("--index", type=arguments.whole, default=0, help="scene index (default 0)")
    parser.add_argument(
        "--views", type=arguments.number_list, default=[1], help="comma-separated view numbers (default 1)"
    )
    parser.add_argument("--size", type=arguments.image_size, default=(1280, 720), help="image size (default 1280x720)")
    arguments.add_renderer_flags(parser)
    parser.add_argument("--out", type=arguments.path, required=True, help="folder for the pictures")
    parser.add_argument(
        "--classes", action="store_true", help="also write each view's organ classes in colour (NAME-classes.png)"
    )
    parser.add_argument("--force", action="store_true", help="replace pictures an earlier preview wrote")


def run(args: argparse.Namespace) -> int:
    crop = crop_spec(args.crop)
    if args.strawberry_altitudes:
        crop = with_strawberry_altitudes(crop, args.strawberry_altitudes)
    scenario = scenario_spec(args.scenario, crop)
    arguments.check_crop_flags(args, crop, scenario)
    numbers = args.views
    renderer_name = args.renderer or DEFAULT_RENDERER
    look = resolve_look(renderer_name, args.look)
    # Every check before the plant grows (a minute for a vine): the view count needs only the
    # nominal grid, which slip does not change.
    _check_views(numbers, count_views(scenario, crop))
    check_outside_datasets(args.out)
    arguments.prove_writable_folder(args.out)
    stems = [f"{crop.name}-{scenario.name}-{args.index:03d}-{view_stem(view_name(n))}" for n in numbers]
    pictures = [args.out / f"{stem}{suffix}{IMAGE_SUFFIX}" for stem in stems for suffix in ("", "-boxes")]
    if args.classes:
        pictures += [args.out / f"{stem}-classes.png" for stem in stems]
    with claim_output(pictures[0], force=args.force, also=[(p, "--out") for p in pictures[1:]]):  # the output rule
        return _draw(args, scenario, crop, numbers, stems, renderer_name, look)


def _draw(
    args: argparse.Namespace,
    scenario: ScenarioSpec,
    crop: CropSpec,
    numbers: list[int],
    stems: list[str],
    renderer_name: str,
    look: str,
) -> int:
    """Grow the scene and write each chosen view, plain and with its boxes, into the claimed files."""
    request = SceneRequest(
        scenario,
        crop,
        args.index,
        args.seed,
        Camera(*args.size),
        renderer=renderer_name,
        look=look,
        plants=args.plants or DEFAULT_PLANTS,
        appearance=args.appearance or DEFAULT_APPEARANCE,
        structures=args.structures or DEFAULT_STRUCTURES,
    )
    model, grid = grow_scene(request)  # generate's own growth: the same plants, light and slip
    _check_views(numbers, len(grid.viewpoints))
    lookup = fruit_lookup({f.id: f.uuids for f in model.fruits}, model.uuid_count)
    polygons = {f.id: f.polygons for f in model.fruits}
    from davis_ag.figures.label_pictures import class_colours

    # Organ class by id-buffer value (UUID + 1; 0 is the sky), as generate writes NNNN_class.png.
    class_of_id = np.concatenate([[SKY], model.organ_of_uuid()]).astype(np.uint8)
    args.out.mkdir(parents=True, exist_ok=True)
    with open_renderer(
        renderer_name, model.context, request.camera, model.lighting, look, args.antialiasing
    ) as renderer:
        for number in numbers:
            view = grid.viewpoints[number - 1]
            colour, primitive_ids, _ = renderer.render(view, depth=False)
            labels = label_view(primitive_ids, lookup, request.min_fruit_pixels)
            fractions = visible_fractions(request.camera, view, labels, polygons)
            stem = stems[numbers.index(number)]
            with atomic_output(args.out / f"{stem}{IMAGE_SUFFIX}") as handle:
                Image.fromarray(colour).save(handle, format="JPEG", quality=JPEG_QUALITY)
            boxed = Image.fromarray(colour)
            draw = ImageDraw.Draw(boxed)
            for x, y, w, h, fruit_id, _ in labels.boxes:
                draw.rectangle([x, y, x + w - 1, y + h - 1], outline=(255, 220, 0), width=2)
                draw.text((x, max(0, y - 12)), f"{fruit_id}: {fractions[fruit_id]:.2f}", fill=(255, 220, 0))
            with atomic_output(args.out / f"{stem}-boxes{IMAGE_SUFFIX}") as handle:
                boxed.save(handle, format="JPEG", quality=JPEG_QUALITY)
            if args.classes:
                with atomic_output(args.out / f"{stem}-classes.png") as handle:
                    Image.fromarray(class_colours(class_of_id[primitive_ids])).save(handle, format="PNG")
            print(f"{args.out / stem}{IMAGE_SUFFIX}: {len(labels.boxes)} fruit boxed, pose {view.pose}")
    return 0


def _check_views(numbers: list[int], views: int) -> None:
    """Refuse view numbers the scene does not have."""
    bad = [n for n in numbers if not 1 <= n <= views]
    if bad:
        raise UserError(f"--views: view {bad[0]} does not exist: this scene has views 1..{views}")

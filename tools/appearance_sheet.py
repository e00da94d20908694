"""One plant under eight draws of randomised appearance, for docs/appearance.md.

    .venv/bin/python tools/appearance_sheet.py [--view 69] [--size 640x360] [--out docs/images]

Grows the single-plant strawberry scene 000 of dataset seed 0 once, then draws one view under the
appearance of scenes 000..007 with ``--appearance random`` (each drawn from its own scene seed, as
``davis-ag generate`` draws it): the sun, sky, soil, exposure, white balance and sensor noise. The
soil is the same tiles with another image, as ``add_ground`` lays it. Writes
``appearance-random-8.jpeg`` (a 4 x 2 sheet, each tile captioned with its draw) and prints the draws.
"""

from __future__ import annotations

import argparse
import dataclasses
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from davis_ag.generate.one_scene import SceneRequest, grow_scene, scene_seed
from davis_ag.render.opengl import OpenGLRenderer
from davis_ag.render.scene_geometry import read_scene_geometry
from davis_ag.scene.appearance import PAPER_SOIL, draw_appearance
from davis_ag.scene.build import helios_texture
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CROPS, SCENARIOS

DRAWS = 8


def caption(appearance) -> str:
    return (f"{appearance.soil.removesuffix('.jpg')}, {appearance.sky.removeprefix('SkyDome_').removesuffix('.jpg')} "
            f"sky, sun {appearance.sun_elevation:.0f} deg x{appearance.sun_strength:.2f}, "
            f"exp x{appearance.exposure:.2f}, noise {appearance.noise_sigma:.1f}")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--view", type=int, default=69, help="image number of the view (default 69)")
    parser.add_argument("--size", default="640x360", help="tile size (default 640x360)")
    parser.add_argument("--out", type=Path, default=Path("docs/images"))
    args = parser.parse_args()
    width, height = (int(v) for v in args.size.split("x"))
    scenario, crop = SCENARIOS["sp"], CROPS["strawberry"]
    request = SceneRequest(scenario, crop, 0, 0, Camera(width, height))
    model, grid = grow_scene(request)
    view = grid.viewpoints[args.view - 1]
    geometry = read_scene_geometry(model.context)
    paper_soil = helios_texture(PAPER_SOIL)
    tiles = []
    for index in range(DRAWS):
        appearance = draw_appearance("random", scene_seed(0, scenario, crop, index))
        soil = helios_texture(appearance.soil)
        textures = [soil if path == paper_soil else path for path in geometry.texture_files]
        with OpenGLRenderer(dataclasses.replace(geometry, texture_files=textures), request.camera,
                            appearance.lighting(model.lighting)) as renderer:
            colour, _, _ = renderer.render(view, depth=True)
        tile = Image.fromarray(colour)
        text = caption(appearance)
        draw = ImageDraw.Draw(tile)
        draw.rectangle([0, 0, 10 + 6 * len(text), 16], fill=(0, 0, 0))
        draw.text((5, 3), text, fill=(255, 255, 255))
        tiles.append(tile)
        print(f"scene {index:03d}: {text}")
    gap = 6
    sheet = Image.new("RGB", (4 * width + 3 * gap, 2 * height + gap), (255, 255, 255))
    for index, tile in enumerate(tiles):
        sheet.paste(tile, ((index % 4) * (width + gap), (index // 4) * (height + gap)))
    args.out.mkdir(parents=True, exist_ok=True)
    path = args.out / "appearance-random-8.jpeg"
    sheet.save(path, quality=90)
    print(f"written {path}")
    return 0


if __name__ == "__main__":
    np.seterr(all="ignore")
    raise SystemExit(main())

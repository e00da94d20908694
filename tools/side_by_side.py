"""Draw one view with Helios and with our renderer in both looks, side by side, for the README.

    .venv/bin/python tools/side_by_side.py [--crop strawberry] [--view 176] [--out docs/images]

Writes ``renderer-<crop>-helios-vs-ours.jpeg`` (Helios's Visualizer | ours, ``helios`` look) and
``renderer-<crop>-looks.jpeg`` (ours, ``helios`` look | ours, ``default`` look), each half
1280x720, and prints the fidelity figures of the pair.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from davis_ag.generate.one_scene import SceneRequest, grow_scene
from davis_ag.render.backends import open_renderer
from davis_ag.scene.camera import Camera
from davis_ag.scene.specs import CROPS, SCENARIOS


def captioned(image: np.ndarray, text: str) -> Image.Image:
    """The image with a caption in its top-left corner."""
    picture = Image.fromarray(image)
    draw = ImageDraw.Draw(picture)
    draw.rectangle([0, 0, 14 + 7 * len(text), 24], fill=(0, 0, 0))
    draw.text((7, 6), text, fill=(255, 255, 255))
    return picture


def pair(left: Image.Image, right: Image.Image) -> Image.Image:
    """Two pictures side by side."""
    out = Image.new("RGB", (left.width + right.width + 8, left.height), (255, 255, 255))
    out.paste(left, (0, 0))
    out.paste(right, (left.width + 8, 0))
    return out


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--crop", default="strawberry")
    parser.add_argument("--view", type=int, default=176, help="view number of scene 0 (dataset seed 0)")
    parser.add_argument("--out", type=Path, default=Path("docs/images"))
    args = parser.parse_args()
    camera = Camera(1280, 720)
    request = SceneRequest(SCENARIOS["sp"], CROPS[args.crop], 0, 0, camera)
    model, grid = grow_scene(request)
    view = grid.viewpoints[args.view - 1]
    frames = {}
    for name, renderer, look in (("Helios", "helios", "helios"), ("ours, helios look", "opengl", "helios"),
                                 ("ours, default look", "opengl", "default")):
        with open_renderer(renderer, model.context, camera, model.lighting, look) as drawing:
            frames[name] = drawing.render(view)
    reference, ours = frames["Helios"], frames["ours, helios look"]
    print(f"ids differ on {int((reference[1] != ours[1]).sum())} of {reference[1].size} pixels; mean colour "
          f"difference {np.abs(reference[0].astype(np.int16) - ours[0]).mean():.2f}/255")
    args.out.mkdir(parents=True, exist_ok=True)
    stem = f"renderer-{args.crop}"
    pair(*(captioned(frames[k][0], k) for k in ("Helios", "ours, helios look"))).save(
        args.out / f"{stem}-helios-vs-ours.jpeg", quality=88)
    pair(*(captioned(frames[k][0], k) for k in ("ours, helios look", "ours, default look"))).save(
        args.out / f"{stem}-looks.jpeg", quality=88)
    print(f"written {args.out / stem}-helios-vs-ours.jpeg and -looks.jpeg")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())

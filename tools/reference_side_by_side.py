"""Our plants beside the original release's pictures (a tool, not shipped): docs/images/plants-vs-original.jpeg.

For each crop, the view of scene 0 (dataset seed 0) nearest a viewpoint like the original's
picture in ``../shared/ref/`` (distance from the plant and camera altitude, judged by eye from the
picture) is drawn by ``davis-ag preview`` with its fruit boxes, cropped to the picture's aspect
and set beside it: original left, ours right, one row per crop.

Run: ``python tools/reference_side_by_side.py [REF_DIR] [--plants canopy|architecture]``.
"""

from __future__ import annotations

import argparse
import tempfile
from pathlib import Path

import numpy as np
from PIL import Image, ImageDraw

from davis_ag import cli
from davis_ag.atomic_files import atomic_output
from davis_ag.generate.one_scene import SceneRequest, grow_scene
from davis_ag.scene.specs import CROPS, scenario_spec

ROOT = Path(__file__).resolve().parent.parent
#: Crop -> (original picture, distance from the plant m, camera altitude m) of a similar view.
ORIGINALS = {
    "strawberry": ("original-sp-strawberry-boxes.png", 1.0, 0.40),
    "tomato": ("original-sp-tomato-boxes.png", 1.0, 0.70),
    "vine": ("original-sp-vine.png", 1.0, 0.50),
}


def nearest_view(crop: str, distance: float, altitude: float, plants: str) -> int:
    """Number of the scene-0 view nearest the wanted distance and altitude."""
    request = SceneRequest(scenario_spec("sp", CROPS[crop]), CROPS[crop], 0, 0, plants=plants)
    _, grid = grow_scene(request)
    cost = [abs(np.hypot(v.nominal[0], v.nominal[1]) - distance) + abs(v.nominal[2] - altitude)
            + 0.01 * abs(v.nominal[0]) for v in grid.viewpoints]
    return int(np.argmin(cost)) + 1


def fit(image: Image.Image, size: tuple[int, int]) -> Image.Image:
    """Centre-crop to ``size``'s aspect, then resize to it."""
    width, height = image.size
    target = size[0] / size[1]
    if width / height > target:
        keep = round(height * target)
        image = image.crop(((width - keep) // 2, 0, (width + keep) // 2, height))
    else:
        keep = round(width / target)
        image = image.crop((0, (height - keep) // 2, width, (height + keep) // 2))
    return image.resize(size, Image.LANCZOS)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("ref", nargs="?", type=Path, default=ROOT.parent / "shared" / "ref")
    parser.add_argument("--plants", default="canopy")
    parser.add_argument("--out", type=Path, default=ROOT / "docs" / "images" / "plants-vs-original.jpeg")
    args = parser.parse_args()
    rows = []
    with tempfile.TemporaryDirectory() as folder:
        for crop, (picture, distance, altitude) in ORIGINALS.items():
            original = Image.open(args.ref / picture).convert("RGB")
            view = nearest_view(crop, distance, altitude, args.plants)
            out = Path(folder) / crop
            cli.main(["preview", "--crop", crop, "--views", str(view), "--plants", args.plants, "--out", str(out)])
            ours = fit(Image.open(next(out.glob(f"*-{view:04d}-boxes.jpeg"))).convert("RGB"), original.size)
            row = Image.new("RGB", (original.width * 2 + 8, original.height), "white")
            row.paste(original, (0, 0))
            row.paste(ours, (original.width + 8, 0))
            draw = ImageDraw.Draw(row)
            for x, text in ((6, f"original DAVIS-Ag ({crop})"), (original.width + 14, f"ours, --plants {args.plants}, view {view}")):
                draw.rectangle((x - 2, 4, x + 7 * len(text), 20), fill="black")
                draw.text((x, 6), text, fill="white")
            rows.append(row)
    sheet = Image.new("RGB", (rows[0].width, sum(r.height for r in rows) + 8 * (len(rows) - 1)), "white")
    y = 0
    for row in rows:
        sheet.paste(row, (0, y))
        y += row.height + 8
    with atomic_output(args.out) as tmp:
        sheet.save(tmp, format="JPEG", quality=88)
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()

"""A strong appearance shift of exported images: a stand-in for real photographs in tests and demos.

The paper's real strawberry set (Lemsalu et al. 2022) is not public. To exercise the sim-to-real
experiment end to end we hold out other synthetic scenes and change how they look, the way a
real camera in a field differs from our renderer: another colour balance and white point (hue,
saturation, brightness, contrast), a strong light from one side (a gradient across the frame),
defocus blur, sensor noise and a second, harsher JPEG compression. Geometry is untouched, so
the labels stay exact. Numbers measured on such a set are stand-ins, never the paper's.
"""

from __future__ import annotations

import io
from pathlib import Path

import numpy as np

from davis_ag.atomic_files import write_bytes_atomic
from davis_ag.formats.layout import JPEG_QUALITY

#: Image file suffixes that are shifted.
IMAGE_SUFFIXES = (".jpeg", ".jpg", ".png")


def shift_image(rgb: np.ndarray, rng: np.random.Generator) -> np.ndarray:
    """One randomly drawn shift of an ``H x W x 3`` uint8 image (see the module docstring)."""
    from PIL import Image, ImageEnhance, ImageFilter

    image = Image.fromarray(rgb)
    hsv = np.asarray(image.convert("HSV")).astype(np.int16)
    hsv[..., 0] = (hsv[..., 0] + rng.integers(-12, 13)) % 256  # hue, PIL's 0-255 scale
    image = Image.fromarray(hsv.astype(np.uint8), "HSV").convert("RGB")
    image = ImageEnhance.Color(image).enhance(rng.uniform(0.4, 1.6))
    image = ImageEnhance.Contrast(image).enhance(rng.uniform(0.6, 1.4))
    image = ImageEnhance.Brightness(image).enhance(rng.uniform(0.6, 1.3))
    image = image.filter(ImageFilter.GaussianBlur(radius=rng.uniform(0.6, 1.8) * max(image.size) / 320))
    pixels = np.asarray(image).astype(np.float32)
    h, w = pixels.shape[:2]
    angle = rng.uniform(0, 2 * np.pi)
    yy, xx = np.mgrid[0:h, 0:w]
    ramp = ((xx / w - 0.5) * np.cos(angle) + (yy / h - 0.5) * np.sin(angle)) * rng.uniform(0.4, 0.9)
    white = np.array([1.0, rng.uniform(0.85, 1.05), rng.uniform(0.6, 1.0)], dtype=np.float32)  # warm light
    pixels = pixels * (1 + ramp)[..., None] * white
    pixels += rng.normal(0, rng.uniform(2, 8), pixels.shape)
    out = Image.fromarray(np.clip(pixels, 0, 255).astype(np.uint8))
    buffer = io.BytesIO()
    out.save(buffer, "JPEG", quality=int(rng.integers(40, 75)))
    buffer.seek(0)
    return np.asarray(Image.open(buffer).convert("RGB"))


def shift_folder(images_dir: Path, seed: int = 0, progress: bool = True) -> int:
    """Shift every image under a folder in place, each with its own draw.

    Files are replaced atomically, so a hard link to a dataset's image is swapped for a new file
    and the dataset itself is never changed. The format is kept by the file's suffix.

    Args:
        images_dir: Folder searched recursively (e.g. a YOLO export's ``images/``).
        seed: Seeds the draws; image ``i`` in sorted order draws from ``(seed, i)``.
        progress: Show a tqdm bar.

    Returns:
        The number of images shifted.
    """
    from PIL import Image
    from tqdm import tqdm

    paths = sorted(p for p in images_dir.rglob("*") if p.suffix.lower() in IMAGE_SUFFIXES)
    for index, path in enumerate(tqdm(paths, desc="appearance shift", unit="image", disable=not progress)):
        with Image.open(path) as im:
            rgb = np.asarray(im.convert("RGB"))
        shifted = Image.fromarray(shift_image(rgb, np.random.default_rng([seed, index])))
        buffer = io.BytesIO()
        shifted.save(buffer, "PNG" if path.suffix.lower() == ".png" else "JPEG", quality=JPEG_QUALITY)
        write_bytes_atomic(path, buffer.getvalue())
    return len(paths)

"""Texture images for our renderer, in either look: Helios's reduced copies or full resolution.

Helios's Visualizer keeps no texture larger than 2048 pixels a side (it resizes larger ones with
its own bilinear rule) and samples the nearest texel; :func:`load_texture` reproduces that for the
``helios`` look and keeps the full image for the ``default`` look.
"""

from __future__ import annotations

import functools

import numpy as np

#: Helios keeps textures at most this large (Visualizer's ``maximum_texture_size``).
HELIOS_MAX_TEXTURE = 2048


def default_sky_texture() -> str:
    """Helios's default sky (``SkyDome_clouds.jpg``, shipped with pyhelios3d)."""
    from davis_ag.scene.build import helios_texture

    return helios_texture("SkyDome_clouds.jpg")


def helios_resize(image: np.ndarray, width: int, height: int) -> np.ndarray:
    """Resize as Helios's Visualizer does: new pixel (x, y) is the bilinear blend at source
    (x * old_width / width, y * old_height / height), rounded as round(value + 0.5).

    Args:
        image: (h, w, c) uint8.
        width, height: The new size.

    Returns:
        (height, width, c) uint8.
    """
    import cv2

    old_h, old_w = image.shape[:2]
    # warpAffine maps each destination pixel through the inverse of this matrix: src = dst * ratio.
    matrix = np.array([[width / old_w, 0.0, 0.0], [0.0, height / old_h, 0.0]])
    value = cv2.warpAffine(
        image.astype(np.float32), matrix, (width, height), flags=cv2.INTER_LINEAR, borderMode=cv2.BORDER_REPLICATE
    )
    return np.clip(np.round(value + 0.5), 0, 255).astype(np.uint8)


@functools.lru_cache(maxsize=16)
def load_texture(path: str, look: str, size: tuple[int, int] | None = None) -> np.ndarray:
    """An image as RGBA uint8 rows, first row at texture coordinate v = 0, in a look's resolution.

    Kept for the life of the process (every scene uses the same few images).

    Args:
        path: Image file.
        look: ``"helios"`` (at most 2048 a side, Helios's resampling) or ``"default"``.
        size: Resample to this (width, height) (the default look's common layer size).
    """
    import cv2

    data = cv2.imread(path, cv2.IMREAD_UNCHANGED)
    if data is None:
        raise OSError(f"cannot read the texture image {path}")
    if data.ndim == 2:
        data = cv2.cvtColor(data, cv2.COLOR_GRAY2RGB)
    data = cv2.cvtColor(data, cv2.COLOR_BGRA2RGBA if data.shape[2] == 4 else cv2.COLOR_BGR2RGB)
    h, w = data.shape[:2]
    if look == "helios" and (w > HELIOS_MAX_TEXTURE or h > HELIOS_MAX_TEXTURE):
        data = helios_resize(data, min(w, HELIOS_MAX_TEXTURE), min(h, HELIOS_MAX_TEXTURE))
    elif look != "helios" and size is not None and (w, h) != tuple(size):
        data = cv2.resize(data, tuple(size), interpolation=cv2.INTER_AREA if size[0] < w else cv2.INTER_CUBIC)
    if data.shape[2] == 3:
        data = np.dstack([data, np.full(data.shape[:2], 255, np.uint8)])
    # Image rows run top to bottom; texture coordinate v = 0 is the image's bottom row.
    data = np.ascontiguousarray(data[::-1])
    data.flags.writeable = False
    return data


#: Largest side of a texture layer in the default look (the array is one size for all layers).
MAX_LAYER = 4096


def decode_srgb(values: np.ndarray) -> np.ndarray:
    """sRGB-encoded values in [0, 1] to linear light (IEC 61966-2-1)."""
    values = np.asarray(values, dtype=np.float64)
    return np.where(values <= 0.04045, values / 12.92, ((values + 0.055) / 1.055) ** 2.4)


def texture_layers(files: list[str], look: str) -> tuple[np.ndarray, np.ndarray]:
    """The scene's textures as one array of layers, in linear light, for our renderer.

    Args:
        files: The texture images, by index.
        look: ``"helios"`` (Helios's reduced copies, each at its own size in a layer as large as
            the largest) or ``"default"`` (every image resized to the largest, at most
            :data:`MAX_LAYER` a side).

    Returns:
        (layers, height, width, 4) float16 texels, at least one layer; (64, 2) float32, the used
        part of each layer (width, height fractions).
    """
    from PIL import Image

    if look == "helios":
        images = [load_texture(f, "helios") for f in files]
        width = max([i.shape[1] for i in images] + [1])
        height = max([i.shape[0] for i in images] + [1])
    else:
        sizes = []
        for f in files:
            with Image.open(f) as image:
                sizes.append(image.size)
        width = min(MAX_LAYER, max([s[0] for s in sizes] + [1]))
        height = min(MAX_LAYER, max([s[1] for s in sizes] + [1]))
        images = [load_texture(f, "default", (width, height)) for f in files]
    # Half floats in linear light: the shader samples colours it need not decode.
    data = np.zeros((max(1, len(images)), height, width, 4), dtype=np.float16)
    scale = np.ones((64, 2), dtype=np.float32)
    for k, texture in enumerate(images):
        texels = texture.astype(np.float64) / 255.0
        texels[..., :3] = decode_srgb(texels[..., :3])
        data[k, : texture.shape[0], : texture.shape[1]] = texels
        scale[k] = (texture.shape[1] / width, texture.shape[0] / height)
    return data, scale

"""Instance masks (``images/NNNN_seg.png``): the integer type a scene's masks use, and "no fruit".

The rule, owned here and nowhere else:

- A scene of at most 255 fruit (ids 0..254) writes **8-bit** masks: numpy ``uint8``, a PNG of
  mode ``"L"``, 255 = no fruit. Every scene of the paper's crops and of the original download is
  one, and their files are byte for byte what they were before 16-bit masks existed.
- A scene of more fruit (at most 65535, ids 0..65534) writes **16-bit** masks: numpy ``uint16``,
  a PNG of mode ``"I;16"`` (16-bit greyscale), 65535 = no fruit.

No fruit is always the largest value of the mask's type, so a mask alone says how to read it:
readers need not know the scene's fruit count. The validator holds a scene with scene.json to the
rule (:func:`mask_dtype` of its fruit count); other scenes may have either type.

Every place that builds a mask, compares one with "no fruit" or bounds a fruit id goes through
:func:`mask_dtype`, :func:`no_fruit_value`, :func:`max_fruit_id` and :func:`fruit_pixels`.
"""

from __future__ import annotations

from typing import Any

import numpy as np

#: No fruit in an 8-bit mask (the published layout's), and the most fruit such a scene holds.
NO_FRUIT_8 = 255
#: No fruit in a 16-bit mask.
NO_FRUIT_16 = 65535
#: The most fruit a scene with 8-bit masks holds (ids 0..254).
MAX_FRUIT_8 = NO_FRUIT_8
#: The most fruit any scene holds (16-bit masks, ids 0..65534).
MAX_FRUIT = NO_FRUIT_16
#: The largest fruit id any mask holds.
MAX_FRUIT_ID = MAX_FRUIT - 1
#: The two mask types, narrow first.
MASK_DTYPES = (np.dtype(np.uint8), np.dtype(np.uint16))
#: PNG (Pillow) mode of each mask type.
MASK_MODES = {np.dtype(np.uint8): "L", np.dtype(np.uint16): "I;16"}


def mask_dtype(fruit_count: int) -> np.dtype:
    """The mask type of a scene of ``fruit_count`` fruit: uint8 up to 255, uint16 above.

    Raises:
        ValueError: for a negative count or more than :data:`MAX_FRUIT` fruit.
    """
    if not 0 <= fruit_count <= MAX_FRUIT:
        raise ValueError(f"a scene holds 0..{MAX_FRUIT} fruit (16-bit masks), not {fruit_count}")
    return MASK_DTYPES[0] if fruit_count <= MAX_FRUIT_8 else MASK_DTYPES[1]


def _dtype(mask_or_dtype: Any) -> np.dtype:
    dtype = mask_or_dtype.dtype if isinstance(mask_or_dtype, np.ndarray) else np.dtype(mask_or_dtype)
    if dtype not in MASK_DTYPES:
        raise ValueError(f"an instance mask is uint8 or uint16, not {dtype}")
    return dtype


def no_fruit_value(mask_or_dtype: Any) -> int:
    """The value of a pixel with no fruit in a mask (or a mask type): 255 for uint8, 65535 for uint16.

    Raises:
        ValueError: for any other type.
    """
    return int(np.iinfo(_dtype(mask_or_dtype)).max)


def max_fruit_id(mask_or_dtype: Any) -> int:
    """The largest fruit id a mask (or a mask type) holds: 254 for uint8, 65534 for uint16."""
    return no_fruit_value(mask_or_dtype) - 1


def fruit_pixels(mask: np.ndarray) -> np.ndarray:
    """A bool array of ``mask``'s shape: True where a fruit is seen."""
    return mask != no_fruit_value(mask)


def empty_mask(shape: tuple[int, ...], fruit_count: int) -> np.ndarray:
    """A mask of a scene of ``fruit_count`` fruit that shows no fruit anywhere."""
    dtype = mask_dtype(fruit_count)
    return np.full(shape, no_fruit_value(dtype), dtype=dtype)


def segmentation_convention(fruit_count: int) -> str:
    """The words scene.json's ``conventions.segmentation`` gives the masks of a scene of ``fruit_count`` fruit."""
    dtype = mask_dtype(fruit_count)
    return f"{dtype.name} fruit_id per pixel for fruit with a box in the view, {no_fruit_value(dtype)} elsewhere"


def mask_image(mask: np.ndarray) -> Any:
    """The Pillow image a mask is saved as: mode ``"L"`` for uint8, ``"I;16"`` for uint16.

    Raises:
        ValueError: for a mask that is not 2-D uint8 or uint16.
    """
    from PIL import Image

    dtype = _dtype(mask)
    if mask.ndim != 2:
        raise ValueError(f"an instance mask is 2-D, not of shape {mask.shape}")
    if dtype == np.uint8:
        return Image.fromarray(mask, mode="L")  # the published encoding, unchanged
    return Image.fromarray(np.ascontiguousarray(mask, dtype="<u2"))  # Pillow: "I;16"


def mask_from_image(mode: str, pixels: np.ndarray) -> tuple[np.ndarray | None, str | None]:
    """A decoded PNG (its Pillow mode and pixels) as an instance mask, or None and why it is not one.

    Accepted: mode ``"L"`` or ``"P"`` (uint8) and 16-bit greyscale (``"I;16"``, and ``"I"``,
    which older Pillow versions give it, with every value in 0..65535).
    """
    if pixels.ndim == 2 and mode in ("L", "P") and pixels.dtype == np.uint8:
        return pixels, None
    if pixels.ndim == 2 and mode.startswith("I;16") and pixels.dtype.kind == "u" and pixels.dtype.itemsize == 2:
        return pixels.astype(np.uint16, copy=False), None
    if pixels.ndim == 2 and mode == "I" and pixels.size and 0 <= int(pixels.min()) and int(pixels.max()) <= NO_FRUIT_16:
        return pixels.astype(np.uint16), None
    return None, f"must be a uint8 or uint16 single-channel PNG, got mode {mode}"


def as_mask(pixels: np.ndarray) -> np.ndarray:
    """Lenient decoding for the reader: any decoded PNG as an instance mask.

    A mask saved as RGB still carries the id in every channel, so one is kept; 16-bit pixels stay
    uint16 (values above 65535 are clipped to no fruit); everything else becomes uint8.
    """
    if pixels.ndim == 3:
        pixels = pixels[..., 0]
    if pixels.dtype == np.uint16:
        return pixels
    if pixels.dtype.kind in "iu" and pixels.dtype.itemsize > 1:
        # Pillow's "I" (int32) for a 16-bit PNG, in versions that do not give "I;16".
        return np.clip(pixels, 0, NO_FRUIT_16).astype(np.uint16)
    return pixels.astype(np.uint8, copy=False)

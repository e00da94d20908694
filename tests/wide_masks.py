"""Turn a tiny scene of :mod:`layout_factory` into one of more than 255 fruit, with 16-bit masks.

The rule of :mod:`davis_ag.formats.masks`: such a scene writes uint16 masks, 65535 = no fruit.
:func:`widen_scene` shifts every fruit id by ``offset`` (so ids above 255 appear in masks, boxes,
scene.json and its visible fractions) and lists ``offset`` unseen fruit before them in scene.json,
so the scene records more than 255 fruit. Import it as ``from wide_masks import widen_scene``.
"""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
from PIL import Image

from davis_ag.formats.layout import view_file
from davis_ag.formats.masks import NO_FRUIT_8, NO_FRUIT_16, mask_image


def widen_scene(scene_dir: Path, offset: int = 300) -> Path:
    """Rewrite a tiny scene (in place) as a scene of more than 255 fruit; returns ``scene_dir``."""
    annotations_path = scene_dir / "annotations.json"
    annotations = json.loads(annotations_path.read_text())
    for name, entry in annotations.items():
        for box in entry["bounding_boxes"]:
            box[4] += offset
        mask_path = view_file(scene_dir, name, "mask")
        mask = np.asarray(Image.open(mask_path))
        assert mask.dtype == np.uint8
        wide = np.where(mask == NO_FRUIT_8, NO_FRUIT_16, mask.astype(np.uint16) + offset).astype(np.uint16)
        mask_image(wide).save(mask_path, compress_level=1)  # as the writer encodes it
    annotations_path.write_text(json.dumps(annotations, indent=1))
    metadata_path = scene_dir / "scene.json"
    metadata = json.loads(metadata_path.read_text())
    unseen = [{"id": i, "plant": 0, "center": [0.0, 0.0, -5.0], "size": [0.01] * 3} for i in range(offset)]
    metadata["fruits"] = unseen + [{**fruit, "id": fruit["id"] + offset} for fruit in metadata["fruits"]]
    metadata["visible_fraction"] = {
        name: {str(int(k) + offset): v for k, v in per_view.items()}
        for name, per_view in metadata["visible_fraction"].items()
    }
    metadata_path.write_text(json.dumps(metadata, indent=1))
    return scene_dir

"""The per-scene observation cache: contents, reuse, invalidation, no decoding while stepping."""

from __future__ import annotations

import json
from pathlib import Path

import numpy as np
import pytest
from PIL import Image

from davis_ag.benchmark import TVMEnv
from davis_ag.benchmark import cache as cache_module
from davis_ag.benchmark.cache import CACHE_FOLDER, load_scene_cache, scaled_box
from davis_ag.data.reader import View, exposure_rate, open_dataset
from layout_factory import write_tiny_dataset


@pytest.fixture()
def root(tmp_path: Path) -> Path:
    return write_tiny_dataset(tmp_path / "data", "sp", "strawberry", scenes=2)


def test_contents_match_the_reader(root: Path) -> None:
    dataset = open_dataset(root)
    scene = dataset.scenes[0]
    cache = load_scene_cache(scene, dataset.root)
    assert (root / CACHE_FOLDER / scene.id / "images.npy").is_file()
    assert cache.view_names == tuple(scene.views)
    assert cache.images.shape == (len(scene.views), 224, 224, 4)
    assert not cache.images[..., 3].any()
    assert isinstance(cache.images, np.memmap)
    for i, view in enumerate(scene.views.values()):
        expected = np.asarray(Image.fromarray(view.image()).resize((224, 224), Image.BILINEAR))
        assert np.abs(cache.images[i, ..., :3].astype(int) - expected).mean() < 2.0
        for j, action in enumerate(cache_module.ALL_ACTIONS):
            target = view.pointers.get(action, "")
            assert cache.pointers[i, j] == (cache.view_names.index(target) if target else -1)
        mask = view.mask()
        for box in view.boxes:
            column = list(cache.fruit_ids).index(box.fruit_id)
            b = cache.box_index[i, column]
            assert b >= 0 and cache.box_view[b] == i and cache.box_fruit[b] == column
            assert cache.box_oer[b] == pytest.approx(exposure_rate(mask, box), abs=1e-6)
            assert cache.box_pixels[b] == np.count_nonzero(mask == box.fruit_id)
        boxed = {box.fruit_id for box in view.boxes}
        for column, fruit in enumerate(cache.fruit_ids):
            assert (cache.box_index[i, column] >= 0) == (int(fruit) in boxed)


@pytest.mark.parametrize("size", [(1280, 720), (128, 72), (640, 480)])
def test_scaled_box_covers_the_fruit(size: tuple[int, int]) -> None:
    rng = np.random.default_rng(0)
    sx, sy = 224 / size[0], 224 / size[1]
    for _ in range(500):
        x, y = int(rng.integers(size[0])), int(rng.integers(size[1]))
        w, h = int(rng.integers(1, size[0] - x + 1)), int(rng.integers(1, size[1] - y + 1))
        x0, y0, x1, y1 = scaled_box(x, y, w, h, size)
        assert 0 <= x0 <= x1 <= 223 and 0 <= y0 <= y1 <= 223
        assert x0 <= x * sx + 1e-9 and (x1 + 1) >= min((x + w) * sx, 224) - 1e-9
        assert y0 <= y * sy + 1e-9 and (y1 + 1) >= min((y + h) * sy, 224) - 1e-9
    assert scaled_box(0, 0, size[0], size[1], size) == (0, 0, 223, 223)


def test_reused_then_rebuilt_when_annotations_change(root: Path, tmp_path: Path) -> None:
    TVMEnv(root, "sp", "all")
    meta = root / CACHE_FOLDER / "Single-Strawberry/000" / "meta.json"
    stamp = meta.stat().st_mtime_ns
    cache_module._OPEN.clear()  # as a new process would
    TVMEnv(root, "sp", "all")
    assert meta.stat().st_mtime_ns == stamp, "an unchanged scene must not be rebuilt"
    annotations = root / "Single-Strawberry/000/annotations.json"
    data = json.loads(annotations.read_text())
    first = next(iter(data))
    data[first]["bounding_boxes"] = []  # the edit must show in the rebuilt tables
    annotations.write_text(json.dumps(data))
    env = TVMEnv(root, "sp", "all")
    assert json.loads(meta.read_text())["fingerprint"] != ""
    assert meta.stat().st_mtime_ns != stamp
    assert not (env.caches[0].box_view == 0).any()
    leftovers = [p.name for p in meta.parent.parent.iterdir() if p.name.startswith(".")]
    assert leftovers == [], "temporary folders must not be left behind"


def test_cache_dir_option(root: Path, tmp_path: Path) -> None:
    TVMEnv(root, "sp", "all", cache_dir=tmp_path / "elsewhere")
    assert (tmp_path / "elsewhere" / "Single-Strawberry/001" / "tables.npz").is_file()
    assert not (root / CACHE_FOLDER).exists()


def test_a_cache_dir_on_a_dataset_leaves_its_scenes_alone(
    root: Path, tmp_path: Path, capsys: pytest.CaptureFixture[str]
) -> None:
    """A --cache-dir naming a dataset (this one, a copy, the original download) put each scene's
    cache where the scene folder is, took the scene for a stale cache and deleted it."""
    from davis_ag import cli

    before = {p: p.read_bytes() for p in root.rglob("*") if p.is_file()}
    code = cli.main(
        [
            "evaluate",
            "--dataset",
            str(root),
            "--scenario",
            "sp",
            "--episodes",
            "1",
            "--sessions",
            "1",
            "--cache-dir",
            str(root),
            "--out",
            str(tmp_path / "r.json"),
        ]
    )
    err = capsys.readouterr().err.strip()
    assert code == 2 and "not an observation cache" in err and "\n" not in err
    assert {p: p.read_bytes() for p in root.rglob("*") if p.is_file()} == before
    # A stale cache of ours is still replaced.
    TVMEnv(root, "sp", "all", cache_dir=tmp_path / "caches")
    meta = tmp_path / "caches" / "Single-Strawberry/000" / "meta.json"
    meta.write_text(json.dumps({**json.loads(meta.read_text()), "fingerprint": "old"}))
    cache_module._OPEN.clear()  # as a new process finds it
    TVMEnv(root, "sp", "all", cache_dir=tmp_path / "caches")
    assert json.loads(meta.read_text())["fingerprint"] != "old"
    # ... and a damaged one (meta.json cut short) too, in the dataset's own cache folder.
    TVMEnv(root, "sp", "all")
    own = root / CACHE_FOLDER / "Single-Strawberry/000" / "meta.json"
    own.write_text(own.read_text()[:10])
    cache_module._OPEN.clear()
    TVMEnv(root, "sp", "all")
    assert json.loads(own.read_text())["fingerprint"]


def test_steps_never_decode(root: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    env = TVMEnv(root, "sp", "all")

    def forbidden(*args: object, **kwargs: object) -> None:
        raise AssertionError("an image was decoded during an episode")

    monkeypatch.setattr(Image, "open", forbidden)
    monkeypatch.setattr(View, "image", forbidden)
    monkeypatch.setattr(View, "mask", forbidden)
    rng = np.random.default_rng(0)
    env.reset(seed=0)
    for _ in range(300):
        _, _, terminated, _, _ = env.step(int(rng.integers(env.action_space.n)))
        if terminated:
            env.reset()


def test_a_view_cut_short_after_the_cache_was_built_is_noticed(tmp_path: Path) -> None:
    """Issue 33 case 9: a JPEG truncated after the observation cache was built went unnoticed (the
    cache served the old pixels). Now the cache is stale and its rebuild names the file."""
    from davis_ag.errors import UserError

    data = write_tiny_dataset(tmp_path / "sp", "sp", "strawberry", scenes=2, size=(64, 48))
    TVMEnv(data, "sp", "all")
    cache_module._OPEN.clear()  # as a new process would
    image = data / "Single-Strawberry" / "000" / "images" / "0002.jpeg"
    image.write_bytes(image.read_bytes()[:300])
    with pytest.raises(UserError, match=f"{image}: cannot decode"):
        TVMEnv(data, "sp", "all")

"""Contact sheets and mask pictures: real PNGs, atomic writes, clear errors."""

from __future__ import annotations

from pathlib import Path

import pytest
from matplotlib.figure import Figure
from PIL import Image

from davis_ag.data.reader import Scene, open_dataset
from davis_ag.errors import UserError
from davis_ag.figures.contact_sheet import draw_contact_sheet, draw_masks, pick_views
from layout_factory import write_original_style_dataset, write_tiny_dataset


@pytest.fixture(scope="module")
def scene(tmp_path_factory: pytest.TempPathFactory) -> Scene:
    root = write_tiny_dataset(tmp_path_factory.mktemp("cs"), "sp", "tomato", scenes=1)
    return open_dataset(root).scenes[0]


def test_pick_views_spreads_evenly(scene: Scene) -> None:
    names = list(scene.views)
    picked = [v.name for v in pick_views(scene, 5)]
    assert len(picked) == 5 and picked[0] == names[0] and picked[-1] == names[-1]
    assert picked == sorted(picked)
    assert len(pick_views(scene, 10_000)) == len(names)
    assert pick_views(scene, 0) == []


def test_contact_sheet_writes_png(scene: Scene, tmp_path: Path) -> None:
    out = draw_contact_sheet(scene, tmp_path / "sheets" / "scene.png", n_views=6, columns=3)
    assert out == tmp_path / "sheets" / "scene.png"
    with Image.open(out) as im:
        assert im.format == "PNG" and im.width > im.height > 200
    assert [p.name for p in out.parent.iterdir()] == ["scene.png"]


def test_contact_sheet_rejects_bad_sizes(scene: Scene, tmp_path: Path) -> None:
    with pytest.raises(UserError, match="n_views >= 1"):
        draw_contact_sheet(scene, tmp_path / "x.png", n_views=0)
    assert not (tmp_path / "x.png").exists()


def test_failed_write_leaves_old_file_and_no_temp(
    scene: Scene, tmp_path: Path, monkeypatch: pytest.MonkeyPatch
) -> None:
    out = tmp_path / "sheet.png"
    out.write_bytes(b"old")

    def broken(*args: object, **kwargs: object) -> None:
        raise RuntimeError("disk full")

    monkeypatch.setattr(Figure, "savefig", broken)
    with pytest.raises(RuntimeError):
        draw_contact_sheet(scene, out, n_views=2)
    assert out.read_bytes() == b"old" and [p.name for p in tmp_path.iterdir()] == ["sheet.png"]


def test_draw_masks(scene: Scene, tmp_path: Path) -> None:
    view = max(scene, key=lambda v: len(v.boxes))
    out = draw_masks(view, tmp_path / "mask.png")
    with Image.open(out) as im:
        assert im.format == "PNG" and im.width > 2 * im.height


def test_draw_masks_without_mask(tmp_path: Path) -> None:
    root = write_original_style_dataset(tmp_path / "orig", "sp", "strawberry", missing_mask=True)
    view = open_dataset(root).scenes[0].view(1)
    with pytest.raises(UserError, match=r"0001_seg.png: missing"):
        draw_masks(view, tmp_path / "mask.png")

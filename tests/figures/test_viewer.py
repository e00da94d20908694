"""``davis-ag view``: the server refuses every path outside the dataset, and the page, driven in
headless Chromium with the keyboard and the mouse, moves as the annotations' pointers say."""

from __future__ import annotations

import http.client
import json
import os
import shutil
import threading
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import numpy as np
import pytest
from chromium_pipe import Chromium, find_chromium
from PIL import Image

from davis_ag import cli
from davis_ag.figures.viewer_server import server_url, start_server
from layout_factory import write_tiny_dataset


def _serve(root: Path) -> Any:
    server = start_server(root, 0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    return server


@pytest.fixture()
def served(tmp_path: Path) -> Iterator[tuple[Path, int]]:
    """A tiny synthetic dataset (no Helios needed for the server's rules) and the server's port."""
    root = write_tiny_dataset(tmp_path / "data", "sp", "strawberry", scenes=1)
    server = _serve(root)
    yield root, server.server_address[1]
    server.shutdown()
    server.server_close()


def _get(port: int, path: str) -> tuple[int, bytes]:
    """GET a raw path, sent exactly as written (no client-side normalisation)."""
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    connection.putrequest("GET", path, skip_accept_encoding=True)
    connection.endheaders()
    response = connection.getresponse()
    body = response.read()
    connection.close()
    return response.status, body


def test_serves_the_page_the_scene_and_its_files(served: tuple[Path, int]) -> None:
    root, port = served
    status, page = _get(port, "/")
    assert status == 200 and b"DAVIS-Ag viewer" in page
    scenes = json.loads(_get(port, "/api/scenes")[1])["scenes"]
    assert [s["id"] for s in scenes] == ["Single-Strawberry/000"]
    scene = json.loads(_get(port, "/api/scene?id=Single-Strawberry/000")[1])
    raw = json.loads((root / "Single-Strawberry/000/annotations.json").read_text())
    assert scene["order"] == list(raw)
    first = scene["views"]["0001.jpeg"]
    assert first["pose"] == raw["0001.jpeg"]["pose"]
    assert first["boxes"] == [b[:5] for b in raw["0001.jpeg"]["bounding_boxes"]]
    assert first["pointers"]["right"] == raw["0001.jpeg"]["right"]
    assert first["depth"] is False and first["mask"] is True
    status, jpeg = _get(port, "/image/Single-Strawberry/000/0001.jpeg")
    assert status == 200 and jpeg == (root / "Single-Strawberry/000/images/0001.jpeg").read_bytes()
    status, overlay = _get(port, "/overlay/mask/Single-Strawberry/000/0001.jpeg")
    assert status == 200 and overlay[:4] == b"\x89PNG"


def test_organ_classes_are_a_layer_where_the_scene_has_them(served: tuple[Path, int]) -> None:
    root, port = served
    scene = json.loads(_get(port, "/api/scene?id=Single-Strawberry/000")[1])
    assert scene["views"]["0001.jpeg"]["classes"] is False
    assert _get(port, "/overlay/classes/Single-Strawberry/000/0001.jpeg")[0] == 404
    images = root / "Single-Strawberry/000/images"
    with Image.open(images / "0001.jpeg") as image:
        width, height = image.size
    classes = np.zeros((height, width), np.uint8)
    classes[height // 2 :] = 1  # soil below the horizon, a fruit in the middle
    classes[height // 2 - 2 : height // 2 + 2, width // 2 - 2 : width // 2 + 2] = 2
    Image.fromarray(classes, mode="L").save(images / "0001_class.png")
    server = _serve(root)  # a new server: scene payloads are built once
    try:
        port = server.server_address[1]
        assert json.loads(_get(port, "/api/scene?id=Single-Strawberry/000")[1])["views"]["0001.jpeg"]["classes"]
        status, body = _get(port, "/overlay/classes/Single-Strawberry/000/0001.jpeg")
        assert status == 200 and body[:4] == b"\x89PNG"
        import io

        overlay = np.asarray(Image.open(io.BytesIO(body)))
        assert overlay.shape == (height, width, 4)
        assert (overlay[0, 0, 3] == 0) and overlay[-1, 0, 3] > 0  # sky transparent, soil drawn
        assert tuple(overlay[height // 2, width // 2, :3]) == (220, 30, 40)  # fruit red
    finally:
        server.shutdown()
        server.server_close()


def test_no_path_reaches_outside_the_dataset(served: tuple[Path, int], tmp_path: Path) -> None:
    root, port = served
    images = root / "Single-Strawberry/000/images"
    secret = tmp_path / "secret.txt"
    secret.write_text("SECRET")
    (images / "9999.jpeg").symlink_to(secret)  # a symlink inside the scene pointing out
    (root / "Single-Strawberry/777").symlink_to(tmp_path)  # a scene folder that is a symlink out
    crafted = [
        "/image/Single-Strawberry/000/../../../../secret.txt",
        "/image/Single-Strawberry/000/..%2f..%2f..%2f..%2fsecret.txt",
        "/image/Single-Strawberry/000/%2e%2e/annotations.json",
        "/image/Single-Strawberry/%2e%2e/000/0001.jpeg",
        "/image/%2e%2e/%2e%2e/secret.txt",
        "/image/Single-Strawberry/000/%2Fetc%2Fpasswd",
        "/image/Single-Strawberry/000/9999.jpeg",
        "/image/Single-Strawberry/777/secret.txt",
        "/image/Single-Strawberry/000/0001.jpeg/../../annotations.json",
        "//etc/passwd",
        "/etc/passwd",
        "/api/scene?id=../../etc",
        "/api/scene?id=%2Fetc%2Fpasswd",
        "/overlay/mask/Single-Strawberry/000/..%2f..%2fsecret.txt",
        "/overlay/depth/Single-Strawberry/000/0001.jpeg",  # no depth image: nothing to serve
        "http://127.0.0.1/../secret.txt",
    ]
    for path in crafted:
        status, body = _get(port, path)
        assert status == (403 if path.startswith("http://127.0.0.1/") else 404), path  # no port in its Host
        assert b"SECRET" not in body and b"root:" not in body, path


def test_a_linked_images_folder_serves_nothing_from_outside(served: tuple[Path, int], tmp_path: Path) -> None:
    """The file only had to lie in the folder the link points to."""
    root, port = served
    outside = tmp_path / "outside"
    outside.mkdir()
    (outside / "0001.jpeg").write_bytes(b"SECRET")
    images = root / "Single-Strawberry/000/images"
    shutil.move(images, tmp_path / "kept")
    images.symlink_to(outside)
    status, body = _get(port, "/image/Single-Strawberry/000/0001.jpeg")
    assert status == 404 and b"SECRET" not in body


def _get_with(port: int, target: str, host: str | None = None) -> int:
    connection = http.client.HTTPConnection("127.0.0.1", port, timeout=10)
    connection.putrequest("GET", target, skip_host=host is not None, skip_accept_encoding=True)
    if host is not None:
        connection.putheader("Host", host)
    connection.endheaders()
    status = connection.getresponse().status
    connection.close()
    return status


def test_odd_requests_get_an_answer_and_other_hosts_none(served: tuple[Path, int]) -> None:
    """ "GET *" and a bare query ended in an IndexError with no reply; a page of another site whose
    name resolves to 127.0.0.1 (DNS rebinding) could read the dataset through the browser."""
    _, port = served
    assert _get_with(port, "*") == 400 and _get_with(port, "?x=1") == 400
    assert _get_with(port, "/api/scenes", host="attacker.example") == 403
    assert _get_with(port, "/api/scenes", host=f"attacker.example:{port}") == 403
    assert _get_with(port, "/api/scenes", host=f"localhost:{port}") == 200
    assert _get(port, "/api/scenes")[0] == 200  # still serving


def test_view_command_refuses_a_bad_port(served: tuple[Path, int], capsys: pytest.CaptureFixture[str]) -> None:
    root, port = served  # that port is taken by the fixture's server
    assert cli.main(["view", str(root), "--port", str(port)]) == 2
    err = capsys.readouterr().err.strip()
    assert "cannot listen" in err and "\n" not in err


def test_view_command_refuses_an_unknown_scene_at_start(
    served: tuple[Path, int], capsys: pytest.CaptureFixture[str]
) -> None:
    """Issue 33 case 9: ``view --scene nope/123`` was accepted, and the page found nothing."""
    root, _ = served
    assert cli.main(["view", str(root), "--port", "0", "--scene", "nope/123"]) == 2
    err = capsys.readouterr().err.strip()
    assert "no scene 'nope/123'" in err and "\n" not in err


def _with_depth(real_root: Path, folder: Path) -> Path:
    """A copy of the real dataset with a depth image (uint16 mm) beside every view."""
    copy = folder / "with-depth"
    shutil.copytree(real_root, copy, ignore=shutil.ignore_patterns(".davis_ag_cache"))
    for jpeg in (copy / "Single-Strawberry/000/images").glob("*.jpeg"):
        with Image.open(jpeg) as image:
            width, height = image.size
        depth = np.tile(np.linspace(500, 4000, width, dtype=np.uint16), (height, 1))
        Image.fromarray(depth).save(jpeg.with_name(jpeg.stem + "_depth.png"))
    return copy


def _state(browser: Chromium) -> dict[str, Any]:
    """The page's view, pose text and image once the image has loaded."""
    return browser.wait_for(
        "(() => { const p = document.getElementById('photo');"
        " return p.complete && p.naturalWidth > 0 && JSON.stringify({view: viewer.view,"
        " pose: document.getElementById('pose').textContent, src: p.src, width: p.naturalWidth,"
        " message: document.getElementById('message').textContent}); })()"
    )


def test_page_in_headless_chromium(real_root: Path, tmp_path: Path) -> None:
    executable = find_chromium()
    if executable is None:
        pytest.skip(
            "no chromium: install Debian's `chromium` package (the test installs it itself "
            "when run as root with apt-get)"
        )
    raw = json.loads((real_root / "Single-Strawberry/000/annotations.json").read_text())
    start = next(n for n, e in raw.items() if e["right"] and e["up"] and raw[e["right"]]["up"])
    plain, deep = _serve(real_root), _serve(_with_depth(real_root, tmp_path))
    profile = tmp_path / "profile"
    profile.mkdir()
    browser = Chromium(executable, profile)
    try:
        browser.goto(server_url(plain) + f"#scene=Single-Strawberry/000&view={start}")
        browser.wait_for("window.viewer && window.viewer.ready")
        state = json.loads(_state(browser))
        assert state["view"] == start and state["src"].endswith(f"/Single-Strawberry/000/{start}")
        assert state["width"] == 128  # the real image arrived
        assert browser.evaluate("document.getElementById('depth-toggle').classList.contains('hidden')")

        def pose_text(name: str) -> str:
            x, y, z, _yaw, _pitch = raw[name]["pose"]
            return f"pose x={x:.3f} y={y:.3f} z={z:.2f}"

        assert state["pose"].startswith(pose_text(start))
        browser.press("ArrowRight")
        right = raw[start]["right"]
        browser.wait_for(f"viewer.view === {json.dumps(right)}")
        state = json.loads(_state(browser))
        assert state["src"].endswith("/" + right) and state["pose"].startswith(pose_text(right))
        browser.press("r")  # up
        up = raw[right]["up"]
        browser.wait_for(f"viewer.view === {json.dumps(up)}")
        assert json.loads(_state(browser))["pose"].startswith(pose_text(up))
        # A move the annotations forbid leaves the camera where it is and says so.
        invalid = next(a for a in ("up", "forward", "backward", "left", "right") if not raw[up][a])
        key = {"up": "r", "forward": "w", "backward": "s", "left": "a", "right": "d"}[invalid]
        browser.press(key)
        browser.wait_for("document.getElementById('message').textContent.includes('not possible')")
        assert browser.evaluate("viewer.view") == up
        # Masks on: the overlay shows and is a loaded image.
        browser.press("m")
        browser.wait_for(
            "!document.getElementById('mask').classList.contains('hidden') &&"
            " document.getElementById('mask').naturalWidth === 128"
        )
        # A click on the map jumps to that position (same altitude).
        target = browser.evaluate(
            "(() => { const c = [...document.querySelectorAll('#map .spot')]"
            ".find(e => e.getAttribute('data-view') !== viewer.view); const r = c.getBoundingClientRect();"
            " return [c.getAttribute('data-view'), r.x + r.width / 2, r.y + r.height / 2]; })()"
        )
        browser.click(target[1], target[2])
        browser.wait_for(f"viewer.view === {json.dumps(target[0])}")
        assert raw[target[0]]["pose"][2] == pytest.approx(raw[up]["pose"][2])
        shot = browser.screenshot(tmp_path / "viewer.png")
        with Image.open(shot) as picture:
            assert picture.size == (1400, 860)
        if os.environ.get("DAVIS_AG_VIEWER_SCREENSHOT"):  # how docs/images/viewer.png is made
            shutil.copy(shot, os.environ["DAVIS_AG_VIEWER_SCREENSHOT"])
        # With depth images the toggle appears and Z shows them.
        browser.goto(server_url(deep) + f"#scene=Single-Strawberry/000&view={start}")
        browser.wait_for(f"location.port === '{deep.server_address[1]}' && window.viewer && viewer.ready")
        assert not browser.evaluate("document.getElementById('depth-toggle').classList.contains('hidden')")
        browser.press("z")
        browser.wait_for(
            "!document.getElementById('depth').classList.contains('hidden') &&"
            " document.getElementById('depth').naturalWidth === 128"
        )
    finally:
        browser.close()
        for server in (plain, deep):
            server.shutdown()
            server.server_close()

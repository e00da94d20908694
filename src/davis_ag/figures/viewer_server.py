"""``davis-ag view``: a local web page to drive through a scene the way the agent does.

The standard library's threading HTTP server, bound to 127.0.0.1 only. Routes:

- ``/``: the page (:mod:`davis_ag.figures.viewer_page`);
- ``/api/scenes``: the scenes (id, views, actions);
- ``/api/scene?id=GROUP/NNN``: one scene's views (pose, boxes, pointers, which layers exist),
  positions and plants, for the page to move without asking again;
- ``/image/GROUP/NNN/NAME``: a file of the scene's ``images/`` folder (``0001.jpeg``,
  ``0001_seg.png``, ``0001_depth.png``);
- ``/overlay/mask/GROUP/NNN/VIEW`` and ``/overlay/depth/GROUP/NNN/VIEW``: the instance mask
  coloured per fruit with transparent background, and the depth image coloured near to far,
  as PNG.

No path from the browser is joined to a folder: a scene is looked up by its id among the
dataset's scenes, a file name must match :data:`FILE_NAME`, and the file's real path (symlinks
followed) must lie in that scene's ``images/`` folder. Anything else is a 404.
"""

from __future__ import annotations

import io
import json
import re
import threading
from http import HTTPStatus
from http.server import BaseHTTPRequestHandler, ThreadingHTTPServer
from pathlib import Path
from typing import Any
from urllib.parse import parse_qs, unquote, urlsplit

import numpy as np

from davis_ag.data.reader import Dataset, Scene, open_dataset
from davis_ag.errors import UserError
from davis_ag.figures.scene_numbers import altitudes
from davis_ag.figures.visibility_plots import plant_xy
from davis_ag.formats.layout import IMAGES, VIEW_FILES, read_depth_millimetres
from davis_ag.formats.masks import no_fruit_value

#: The only file names served: an image, its mask or its depth image.
FILE_NAME = re.compile(
    r"\d{1,6}("
    + "|".join(re.escape(end) for end in sorted({".jpg", ".png", *(suffix for suffix, _ in VIEW_FILES.values())}))
    + ")"
)
HOST = "127.0.0.1"
_TYPES = {".jpeg": "image/jpeg", ".jpg": "image/jpeg", ".png": "image/png"}


def scene_payload(scene: Scene) -> dict[str, Any]:
    """Everything the page needs to drive through one scene, JSON-ready.

    Args:
        scene: The scene.

    Returns:
        ``{"id", "actions", "altitudes", "plants", "size", "views": {name: {"pose", "boxes",
        "pointers", "mask", "depth", "classes"}}, "order": [names]}``.
    """
    views = {}
    for name, view in scene.views.items():
        views[name] = {
            "pose": list(view.pose) if view.pose is not None else None,
            "boxes": [[b.xmin, b.ymin, b.width, b.height, b.fruit_id] for b in view.boxes],
            "pointers": dict(view.pointers),
            "mask": view.mask_path.is_file(),
            "depth": view.depth_path.is_file(),
            "classes": view.class_path.is_file(),
        }
    image_size = scene.metadata.image_size() if scene.metadata else None
    size = list(image_size) if image_size else None
    return {
        "id": scene.id,
        "actions": list(scene.actions),
        "order": list(scene.views),
        "altitudes": altitudes(scene) if any(v["pose"] for v in views.values()) else [],
        "plants": [list(p) for p in plant_xy(scene)],
        "size": size,
        "views": views,
    }


def mask_overlay(mask: np.ndarray) -> bytes:
    """An RGBA PNG of an instance mask (uint8 or uint16): one colour per fruit id (20 repeating),
    no-fruit transparent."""
    from matplotlib import colormaps
    from PIL import Image

    colours = (np.array([colormaps["tab20"](i) for i in range(20)]) * 255).astype(np.uint8)
    no_fruit = no_fruit_value(mask)
    table = colours[np.arange(no_fruit + 1) % 20]
    table[:, 3] = 170
    table[no_fruit] = 0
    buffer = io.BytesIO()
    Image.fromarray(table[mask], "RGBA").save(buffer, format="PNG")
    return buffer.getvalue()


def depth_picture(depth: np.ndarray) -> bytes:
    """An RGB PNG of a depth image (uint16 mm, 0 = nothing): near yellow to far purple, none black."""
    from matplotlib import colormaps
    from PIL import Image

    valid = depth > 0
    picture = np.zeros((*depth.shape, 3), dtype=np.uint8)
    if valid.any():
        near, far = np.percentile(depth[valid], [1, 99])
        scaled = np.clip((depth.astype(float) - near) / max(far - near, 1.0), 0, 1)
        picture[valid] = (colormaps["viridis_r"](scaled[valid])[:, :3] * 255).astype(np.uint8)
    buffer = io.BytesIO()
    Image.fromarray(picture, "RGB").save(buffer, format="PNG")
    return buffer.getvalue()


def classes_overlay(classes: np.ndarray) -> bytes:
    """An RGBA PNG of an organ class image in the class colours of docs/labels.md, sky transparent."""
    from PIL import Image

    from davis_ag.figures.label_pictures import ORGAN_COLOURS

    table = np.zeros((256, 4), dtype=np.uint8)
    table[: len(ORGAN_COLOURS), :3] = ORGAN_COLOURS
    table[1 : len(ORGAN_COLOURS), 3] = 200
    buffer = io.BytesIO()
    Image.fromarray(table[classes], "RGBA").save(buffer, format="PNG")
    return buffer.getvalue()


class Viewer:
    """The dataset behind the server, with per-scene payloads built once.

    Attributes:
        dataset: The opened dataset.
    """

    def __init__(self, dataset: Dataset) -> None:
        """Args:
        dataset: The dataset to serve.
        """
        self.dataset = dataset
        self._scenes = {s.id: s for s in dataset.scenes}
        self._payloads: dict[str, bytes] = {}
        self._lock = threading.Lock()

    def scene(self, scene_id: str) -> Scene | None:
        """The scene of that exact id, or ``None``."""
        return self._scenes.get(scene_id)

    def payload(self, scene: Scene) -> bytes:
        """:func:`scene_payload` as JSON bytes, built on first request."""
        with self._lock:
            if scene.id not in self._payloads:
                self._payloads[scene.id] = json.dumps(scene_payload(scene)).encode()
            return self._payloads[scene.id]

    def scenes(self) -> bytes:
        """The scene list as JSON bytes."""
        return json.dumps(
            {
                "root": str(self.dataset.root),
                "scenes": [{"id": s.id, "views": len(s.views)} for s in self.dataset.scenes],
            }
        ).encode()

    def file(self, scene: Scene, name: str) -> Path | None:
        """The scene's ``images/<name>`` when the name is allowed and the file, symlinks
        followed, really lies in that folder and in the dataset (a linked images folder or
        scene folder does not take the server out of it); else ``None``."""
        if not FILE_NAME.fullmatch(name):
            return None
        try:
            folder, root = (scene.path / IMAGES).resolve(), Path(self.dataset.root).resolve()
            real = (folder / name).resolve(strict=True)
        except (OSError, RuntimeError):
            return None
        if real.parent != folder or not real.is_relative_to(root) or not real.is_file():
            return None
        return real


def _split_scene(parts: list[str]) -> tuple[str, str] | None:
    """``[group, scene, name]`` -> ``("group/scene", name)``; anything else ``None``."""
    if len(parts) != 3 or any(p in ("", ".", "..") for p in parts):
        return None
    return f"{parts[0]}/{parts[1]}", parts[2]


def make_handler(viewer: Viewer, page: bytes) -> type[BaseHTTPRequestHandler]:
    """A request handler class serving ``viewer``'s dataset and ``page``."""

    class Handler(BaseHTTPRequestHandler):
        server_version = "davis-ag-view"

        def log_message(self, format: str, *args: Any) -> None:
            pass  # a page load is dozens of requests: keep the terminal for the URL

        def _send(self, status: int, body: bytes, kind: str, cache: bool = False) -> None:
            self.send_response(status)
            self.send_header("Content-Type", kind)
            self.send_header("Content-Length", str(len(body)))
            self.send_header("Cache-Control", "max-age=3600" if cache else "no-store")
            self.send_header("X-Content-Type-Options", "nosniff")
            self.end_headers()
            self.wfile.write(body)

        def _missing(self, why: str = "not found") -> None:
            self._send(HTTPStatus.NOT_FOUND, why.encode(), "text/plain; charset=utf-8")

        def do_GET(self) -> None:
            # Only pages that asked for this address: a site rebinding its name to 127.0.0.1
            # sends its own Host, and would otherwise read the dataset through the browser.
            address = self.server.server_address
            assert isinstance(address, tuple)  # an IP server: (host, port)
            port = address[1]
            if self.headers.get("Host", "") not in (f"{HOST}:{port}", f"localhost:{port}"):
                return self._send(HTTPStatus.FORBIDDEN, b"wrong host", "text/plain; charset=utf-8")
            url = urlsplit(self.path)
            if not url.path.startswith("/"):  # "GET *" or a bare query
                return self._send(HTTPStatus.BAD_REQUEST, b"bad request", "text/plain; charset=utf-8")
            # Split first, then decode each segment: an encoded "/" never makes a new segment.
            parts = [unquote(p) for p in url.path.split("/")[1:]]
            try:
                self._route(parts, parse_qs(url.query))
            except UserError as error:  # an unreadable annotation or image: say so, keep serving
                self._send(HTTPStatus.INTERNAL_SERVER_ERROR, str(error).encode(), "text/plain; charset=utf-8")
            except (BrokenPipeError, ConnectionResetError):
                pass
            except Exception as error:
                message = f"{type(error).__name__}: {error}".encode()
                self._send(HTTPStatus.INTERNAL_SERVER_ERROR, message, "text/plain; charset=utf-8")

        def _route(self, parts: list[str], query: dict[str, list[str]]) -> None:
            head, rest = parts[0], parts[1:]
            if head == "" and not rest:
                self._send(HTTPStatus.OK, page, "text/html; charset=utf-8")
            elif head == "api" and rest == ["scenes"]:
                self._send(HTTPStatus.OK, viewer.scenes(), "application/json")
            elif head == "api" and rest == ["scene"]:
                scene = viewer.scene((query.get("id") or [""])[0])
                if scene is None:
                    return self._missing("no such scene")
                self._send(HTTPStatus.OK, viewer.payload(scene), "application/json")
            elif head == "image" and (found := _split_scene(rest)):
                scene = viewer.scene(found[0])
                path = viewer.file(scene, found[1]) if scene else None
                if path is None:
                    return self._missing()
                self._send(HTTPStatus.OK, path.read_bytes(), _TYPES[path.suffix], cache=True)
            elif (
                head == "overlay"
                and rest
                and rest[0] in ("mask", "depth", "classes")
                and (found := _split_scene(rest[1:]))
            ):
                self._overlay(rest[0], *found)
            else:
                self._missing()

        def _overlay(self, layer: str, scene_id: str, view_name: str) -> None:
            scene = viewer.scene(scene_id)
            view = scene.views.get(view_name) if scene else None
            if scene is None or view is None:
                return self._missing()
            if layer == "mask":
                mask = view.mask()
                if mask is None:
                    return self._missing("no mask")
                return self._send(HTTPStatus.OK, mask_overlay(mask), "image/png", cache=True)
            if layer == "classes":
                classes = view.classes() if viewer.file(scene, view.class_path.name) is not None else None
                if classes is None:
                    return self._missing("no organ classes")
                return self._send(HTTPStatus.OK, classes_overlay(classes), "image/png", cache=True)
            path = viewer.file(scene, view.depth_path.name)
            if path is None:
                return self._missing("no depth")
            try:
                depth = read_depth_millimetres(path)
            except UserError:
                return self._missing("damaged depth")
            self._send(HTTPStatus.OK, depth_picture(depth), "image/png", cache=True)

    return Handler


def start_server(root: str | Path, port: int = 0) -> ThreadingHTTPServer:
    """Open the dataset and bind the server to 127.0.0.1 (``port`` 0: any free port).

    Call ``serve_forever()`` on the result (in a thread, for tests) and ``shutdown()`` to stop.

    Args:
        root: Dataset root, group or scene folder.
        port: TCP port; 0 lets the system choose.

    Returns:
        The bound, not yet serving, server; ``server.server_address[1]`` is the port.

    Raises:
        UserError: for a path that holds no dataset or a port that cannot be bound.
    """
    from davis_ag.figures.viewer_page import PAGE

    dataset = open_dataset(root)
    if not 0 <= port <= 65535:
        raise UserError(f"--port {port}: choose 0 (any free port) to 65535")
    handler = make_handler(Viewer(dataset), PAGE.encode())
    try:
        server = ThreadingHTTPServer((HOST, port), handler)
    except OSError as error:
        raise UserError(
            f"{HOST}:{port}: cannot listen ({error.strerror or error}); choose another --port or 0 for any free one"
        ) from None
    server.daemon_threads = True
    return server


def server_url(server: ThreadingHTTPServer) -> str:
    """The page's address, e.g. ``http://127.0.0.1:8765/``."""
    return f"http://{HOST}:{server.server_address[1]}/"

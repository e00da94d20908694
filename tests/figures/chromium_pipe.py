"""Drive headless Chromium from a test through the DevTools protocol over a pipe.

``--remote-debugging-pipe`` makes Chromium read commands on file descriptor 3 and write replies
on 4, each a JSON message ended by a NUL byte: no websocket library, no open port. Only what the
viewer test needs: open a page, evaluate JavaScript, press keys, click, take a screenshot.
"""

from __future__ import annotations

import base64
import json
import os
import shutil
import subprocess
import threading
import time
from pathlib import Path
from typing import Any

FLAGS = [
    "--headless",
    "--no-sandbox",
    "--disable-gpu",
    "--disable-quic",
    "--no-first-run",
    "--disable-background-networking",
    "--disable-component-update",
    "--disable-sync",
    "--hide-scrollbars",
    "--remote-debugging-pipe",
]
#: Key name -> (code, Windows virtual key code) for the keys the viewer uses.
_KEYS = {
    "ArrowUp": ("ArrowUp", 38),
    "ArrowDown": ("ArrowDown", 40),
    "ArrowLeft": ("ArrowLeft", 37),
    "ArrowRight": ("ArrowRight", 39),
    "PageUp": ("PageUp", 33),
    "PageDown": ("PageDown", 34),
}


def find_chromium() -> str | None:
    """The Chromium executable, installing Debian's package when missing and possible.

    Returns:
        Its path, or ``None`` when it is missing and cannot be installed (not root, no apt).
    """
    for name in ("chromium", "chromium-browser"):
        if found := shutil.which(name):
            return found
    if os.geteuid() != 0 or not shutil.which("apt-get"):
        return None
    env = {**os.environ, "DEBIAN_FRONTEND": "noninteractive"}
    install = ["apt-get", "install", "-y", "-q", "chromium"]
    try:  # bounded: a stuck mirror must not hold the suite to CI's limit
        if subprocess.run(install, env=env, capture_output=True, timeout=600).returncode != 0:
            subprocess.run(["apt-get", "update", "-q"], env=env, capture_output=True, timeout=600)
            subprocess.run(install, env=env, capture_output=True, timeout=600)
    except subprocess.TimeoutExpired:
        return None
    return shutil.which("chromium")


class Chromium:
    """One headless Chromium with one page, driven over the DevTools pipe."""

    def __init__(self, executable: str, profile: Path, width: int = 1400, height: int = 860) -> None:
        """Start the browser and open a blank page.

        Args:
            executable: Chromium's path.
            profile: A new, empty folder for the user data.
            width, height: The page's viewport in CSS pixels.
        """
        to_child, self._write = os.pipe()
        self._read, from_child = os.pipe()

        def wire() -> None:  # in the child: our pipes become its fds 3 and 4
            os.dup2(to_child, 3)
            os.dup2(from_child, 4)

        self.process = subprocess.Popen(
            [executable, *FLAGS, f"--user-data-dir={profile}", f"--window-size={width},{height}"],
            preexec_fn=wire,
            pass_fds=(3, 4),
            stdout=subprocess.DEVNULL,
            stderr=subprocess.DEVNULL,
        )
        os.close(to_child)
        os.close(from_child)
        self._next_id = 0
        self._replies: dict[int, dict[str, Any]] = {}
        self._done = threading.Condition()
        threading.Thread(target=self._reader, daemon=True).start()
        try:
            target = self.send("Target.createTarget", {"url": "about:blank"})["targetId"]
            self.session = self.send("Target.attachToTarget", {"targetId": target, "flatten": True})["sessionId"]
            self.send("Page.enable", session=True)
            self.send(
                "Emulation.setDeviceMetricsOverride",
                {"width": width, "height": height, "deviceScaleFactor": 1, "mobile": False},
                session=True,
            )
        except BaseException:
            self.close()  # never leave a browser behind
            raise

    def _reader(self) -> None:
        buffer = b""
        while chunk := os.read(self._read, 1 << 16):
            buffer += chunk
            *messages, buffer = buffer.split(b"\0")
            for raw in messages:
                message = json.loads(raw)
                if "id" in message:
                    with self._done:
                        self._replies[message["id"]] = message
                        self._done.notify_all()

    def send(
        self, method: str, params: dict[str, Any] | None = None, session: bool = False, timeout: float = 30.0
    ) -> dict[str, Any]:
        """Send one command and wait for its reply.

        Raises:
            RuntimeError: when Chromium answers with an error or not in time.
        """
        self._next_id += 1
        ident = self._next_id
        message: dict[str, Any] = {"id": ident, "method": method, "params": params or {}}
        if session:
            message["sessionId"] = self.session
        os.write(self._write, json.dumps(message).encode() + b"\0")
        with self._done:
            if not self._done.wait_for(lambda: ident in self._replies, timeout):
                raise RuntimeError(f"Chromium did not answer {method} in {timeout} s")
            reply = self._replies.pop(ident)
        if "error" in reply:
            raise RuntimeError(f"{method}: {reply['error']}")
        return reply.get("result", {})

    def goto(self, url: str) -> None:
        """Navigate the page."""
        self.send("Page.navigate", {"url": url}, session=True)

    def evaluate(self, expression: str) -> Any:
        """The value of a JavaScript expression in the page (promises awaited)."""
        result = self.send(
            "Runtime.evaluate", {"expression": expression, "returnByValue": True, "awaitPromise": True}, session=True
        )
        if "exceptionDetails" in result:
            raise RuntimeError(f"{expression}: {result['exceptionDetails']}")
        return result["result"].get("value")

    def wait_for(self, expression: str, timeout: float = 60.0) -> Any:
        """Poll a JavaScript expression until it is truthy; its value.

        Raises:
            TimeoutError: when it stays falsy.
        """
        deadline = time.monotonic() + timeout
        while time.monotonic() < deadline:
            value = self.evaluate(expression)
            if value:
                return value
            time.sleep(0.05)
        raise TimeoutError(f"still false after {timeout} s: {expression}")

    def press(self, key: str) -> None:
        """Press and release one key: a letter or one of :data:`_KEYS`."""
        if key in _KEYS:
            code, vk = _KEYS[key]
            down = {"type": "rawKeyDown", "key": key, "code": code, "windowsVirtualKeyCode": vk}
        else:
            down = {
                "type": "keyDown",
                "key": key,
                "code": f"Key{key.upper()}",
                "text": key,
                "windowsVirtualKeyCode": ord(key.upper()),
            }
        self.send("Input.dispatchKeyEvent", down, session=True)
        self.send("Input.dispatchKeyEvent", {**down, "type": "keyUp", "text": ""}, session=True)

    def click(self, x: float, y: float) -> None:
        """Click the left mouse button at page coordinates."""
        for kind in ("mousePressed", "mouseReleased"):
            self.send(
                "Input.dispatchMouseEvent",
                {"type": kind, "x": x, "y": y, "button": "left", "clickCount": 1},
                session=True,
            )

    def screenshot(self, path: Path) -> Path:
        """Save the page as PNG."""
        data = self.send("Page.captureScreenshot", {"format": "png"}, session=True)["data"]
        path.write_bytes(base64.b64decode(data))
        return path

    def close(self) -> None:
        """Close the browser and its pipes."""
        try:
            self.send("Browser.close", timeout=5)
        except (RuntimeError, OSError):
            pass
        try:
            self.process.wait(timeout=10)
        except subprocess.TimeoutExpired:
            self.process.kill()
            self.process.wait()
        for fd in (self._write, self._read):
            try:
                os.close(fd)
            except OSError:
                pass


def screenshot_viewer(dataset: Path, out: Path, view: str | None = None, keys: list[str] | None = None) -> Path:
    """Open ``davis-ag view`` on a dataset in headless Chromium, press keys, save a screenshot.

    Args:
        dataset: The dataset folder.
        out: The PNG to write.
        view: The view to start from (default: the first scene's first).
        keys: Keys to press before the screenshot, e.g. ``["d", "r", "m"]``.

    Returns:
        ``out``.
    """
    import tempfile

    from davis_ag.figures.viewer_server import server_url, start_server

    executable = find_chromium()
    if executable is None:
        raise SystemExit("no chromium: apt-get install chromium")
    server = start_server(dataset, 0)
    threading.Thread(target=server.serve_forever, daemon=True).start()
    with tempfile.TemporaryDirectory() as profile:
        browser = Chromium(executable, Path(profile), width=1280, height=620)
        try:
            browser.goto(server_url(server) + (f"#view={view}" if view else ""))
            browser.wait_for("window.viewer && window.viewer.ready")
            for key in keys or []:
                browser.press(key)
                time.sleep(0.3)
            browser.wait_for("document.getElementById('photo').complete")
            time.sleep(0.5)
            browser.screenshot(out)
        finally:
            browser.close()
            server.shutdown()
            server.server_close()
    return out


if __name__ == "__main__":  # python tests/figures/chromium_pipe.py DATASET OUT.png [VIEW] [KEYS]
    import sys

    args = sys.argv[1:]
    print(
        screenshot_viewer(
            Path(args[0]),
            Path(args[1]),
            args[2] if len(args) > 2 else None,
            args[3].split(",") if len(args) > 3 else None,
        )
    )

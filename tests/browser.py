"""A headless Chromium driven over the DevTools protocol, for the tests of the classroom in a browser.

Only what the tests need: open a page, type keys as a user does, take a screenshot. The protocol is spoken over
the ``websockets`` client the project already depends on, so no browser driver package is needed; Chromium itself
(Debian's ``chromium``) must be installed, and the tests that use this skip, saying so, where it is not.
"""

from __future__ import annotations

import base64
import json
import shutil
import subprocess
import tempfile
import time
import urllib.request
from pathlib import Path
from types import TracebackType
from typing import Any

from websockets.sync.client import ClientConnection, connect

# Keys by the name a test gives, as DevTools wants them: (key, code, windowsVirtualKeyCode).
KEYS = {"Enter": ("Enter", "Enter", 13), "Tab": ("Tab", "Tab", 9), "Escape": ("Escape", "Escape", 27),
        "Backspace": ("Backspace", "Backspace", 8)}


def chromium() -> str | None:
    return next((p for p in (shutil.which(n) for n in ("chromium", "chromium-browser", "google-chrome")) if p), None)


class Browser:
    def __init__(self, width: int = 1400, height: int = 900) -> None:
        exe = chromium()
        if exe is None:
            raise RuntimeError("no chromium on this machine")
        self.profile = Path(tempfile.mkdtemp(prefix="liansuo-chromium-"))
        self.proc = subprocess.Popen(
            [exe, "--headless=new", "--no-sandbox", "--disable-gpu", "--no-first-run", "--disable-extensions",
             f"--window-size={width},{height}", "--remote-debugging-port=0", f"--user-data-dir={self.profile}",
             "about:blank"], stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
        port_file = self.profile / "DevToolsActivePort"
        deadline = time.monotonic() + 30
        while not port_file.exists() or not port_file.read_text().strip():
            if time.monotonic() > deadline or self.proc.poll() is not None:
                self.close()
                raise RuntimeError("chromium did not start")
            time.sleep(0.1)
        port = int(port_file.read_text().split()[0])
        with urllib.request.urlopen(f"http://127.0.0.1:{port}/json/list", timeout=10) as r:
            pages = [t for t in json.load(r) if t.get("type") == "page"]
        self.ws: ClientConnection = connect(pages[0]["webSocketDebuggerUrl"], max_size=None).__enter__()  # close()d
        self._id = 0

    def call(self, method: str, **params: Any) -> dict[str, Any]:
        self._id += 1
        self.ws.send(json.dumps({"id": self._id, "method": method, "params": params}))
        while True:
            msg = json.loads(self.ws.recv(timeout=30))
            if msg.get("id") == self._id:
                if "error" in msg:
                    raise RuntimeError(f"{method}: {msg['error']}")
                result: dict[str, Any] = msg.get("result", {})
                return result

    def open(self, url: str) -> None:
        self.call("Page.enable")
        self.call("Page.navigate", url=url)

    def evaluate(self, expression: str) -> Any:
        return self.call("Runtime.evaluate", expression=expression, returnByValue=True).get("result", {}).get("value")

    def focus(self, selector: str) -> None:
        """Give the keyboard to the element ``selector`` (a terminal page's hidden text area)."""
        self.evaluate(f"document.querySelector({json.dumps(selector)})?.focus()")

    def type(self, text: str) -> None:
        """Type text as a keyboard does, one character at a time."""
        for ch in text:
            self.call("Input.insertText", text=ch)
            time.sleep(0.03)

    def press(self, name: str) -> None:
        key, code, vk = KEYS[name]
        self.call("Input.dispatchKeyEvent", type="rawKeyDown", key=key, code=code, windowsVirtualKeyCode=vk)
        if name == "Enter":
            self.call("Input.dispatchKeyEvent", type="char", text="\r", key=key, code=code, windowsVirtualKeyCode=vk)
        self.call("Input.dispatchKeyEvent", type="keyUp", key=key, code=code, windowsVirtualKeyCode=vk)
        time.sleep(0.05)

    def log_in(self, url: str, **fields: str) -> None:
        """Open the classroom's page and submit its login form (``name`` and ``seat``, or ``password``) as a user
        fills it in; textual-serve's page with the console follows once the server accepts."""
        self.open(url)
        end = time.monotonic() + 30
        while not self.evaluate("!!document.querySelector('form[action=login]')"):
            if time.monotonic() > end:
                raise RuntimeError(f"no login form at {url}")
            time.sleep(0.2)
        role = "instructor" if "password" in fields else "trainee"
        fill = "".join(f"document.querySelector('#{k}').value = {json.dumps(v)};" for k, v in fields.items())
        self.evaluate(f"document.querySelector('input[value={role}]').checked = true; {fill}"
                      "document.querySelector('form[action=login]').submit()")

    def screenshot(self, path: Path) -> None:
        data = self.call("Page.captureScreenshot", format="png")["data"]
        path.write_bytes(base64.b64decode(data))

    def close(self) -> None:
        if hasattr(self, "ws"):
            self.ws.close()
        self.proc.terminate()
        try:
            self.proc.wait(10)
        except subprocess.TimeoutExpired:
            self.proc.kill()
        shutil.rmtree(self.profile, ignore_errors=True)

    def __enter__(self) -> Browser:
        return self

    def __exit__(self, t: type[BaseException] | None, e: BaseException | None, tb: TracebackType | None) -> None:
        self.close()

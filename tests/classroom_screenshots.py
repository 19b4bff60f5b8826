"""The classroom's pictures in docs/classroom.md, taken as a class would see them: ``liansuo serve --web`` and headless
Chromium (tests/browser.py). Run from the checkout::

    python tests/classroom_screenshots.py docs/images

It writes classroom-login.png (the login screen in a browser), classroom-browser.png (a trainee's console with a
route set) and classroom-dashboard.png (the instructor's dashboard with an exercise under way on seat 1).
"""

from __future__ import annotations

import subprocess
import sys
import tempfile
import threading
import time
from pathlib import Path

from browser import Browser

from liansuo.classroom.passwords import hash_password
from liansuo.server.client import ClassroomClient

PASSWORD = "class of 2026"
TEXTAREA = "textarea.xterm-helper-textarea"


def main(out: Path) -> None:
    out.mkdir(parents=True, exist_ok=True)
    with tempfile.TemporaryDirectory() as tmp:
        secret = Path(tmp) / "pw"
        secret.write_text(hash_password(PASSWORD) + "\n", encoding="utf-8")
        proc = subprocess.Popen([sys.executable, "-m", "liansuo.cli", "serve", "jiaopei", "--seats", "3", "--port",
                                 "0", "--web", "--web-port", "0", "--password-file", str(secret), "--reports",
                                 str(Path(tmp) / "reports")], stdout=subprocess.PIPE, text=True)
        try:
            assert proc.stdout is not None
            first = proc.stdout.readline()
            threading.Thread(target=proc.stdout.read, daemon=True).start()
            ws, web = first.split(" on ")[1].split(",")[0], first.split("browsers on ")[1].split()[0]
            shoot(ws, web, out)
        finally:
            proc.terminate()
            proc.wait(10)


def shoot(ws: str, web: str, out: Path) -> None:
    with ClassroomClient.trainee(ws, seat=2, name="Wang"):
        with Browser(1400, 900) as li:
            li.open(web)
            time.sleep(2)
            li.evaluate("document.querySelector('#name').value = 'Li Lei'; document.querySelector('#seat').value = 1")
            li.screenshot(out / "classroom-login.png")
            li.log_in(web, name="Li Lei", seat="1")
            time.sleep(8)
            with ClassroomClient.instructor(ws, PASSWORD) as teacher:
                teacher.request({"type": "exercise", "seats": [1], "name": "jiaopei-cancel-route", "seed": 1})
            time.sleep(3)
            li.focus(TEXTAREA)
            li.press("Escape")  # the exercise's briefing, shown when it starts, read and closed
            time.sleep(1)
            li.type(":cancel X")
            li.press("Enter")
            time.sleep(2)
            li.type(":route X XI")
            li.press("Enter")
            time.sleep(5)
            li.screenshot(out / "classroom-browser.png")
        with ClassroomClient.instructor(ws, PASSWORD) as teacher:
            teacher.request({"type": "exercise", "seats": [2], "name": "jiaopei-filament", "seed": 3})
        with Browser(1400, 600) as tab:
            tab.log_in(web, password=PASSWORD)  # the instructor
            time.sleep(8)
            tab.screenshot(out / "classroom-dashboard.png")


if __name__ == "__main__":
    main(Path(sys.argv[1] if len(sys.argv) > 1 else "docs/images"))

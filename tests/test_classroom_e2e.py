"""The classroom end to end, as a class runs it (docs/classroom.md): ``liansuo serve --web`` in a process of its own,
two trainees at terminal consoles (``liansuo tui --connect``) in a private tmux server, a third in a headless
browser, and the instructor. Nothing here reaches inside the server: what a trainee sees is read off their screen,
what the instructor sees off the wire, and the reports off the disk."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
import threading
import time
from collections.abc import Callable, Iterator
from dataclasses import dataclass
from pathlib import Path

import pytest
from browser import Browser, chromium

from liansuo.classroom.passwords import hash_password
from liansuo.server.client import ClassroomClient

PASSWORD = "correct horse"
TMUX = ["tmux", "-L", f"liansuo-e2e-{os.getpid()}"]


@dataclass
class Class:
    ws: str
    web: str
    reports: Path


def until(condition: Callable[[], bool], seconds: float = 20.0, what: str = "",
          show: Callable[[], str] = lambda: "") -> None:
    """Wait for ``condition``; else fail saying ``what`` was awaited, and what ``show`` shows then (a screen)."""
    deadline = time.monotonic() + seconds
    while time.monotonic() < deadline:
        if condition():
            return
        time.sleep(0.2)
    raise AssertionError(f"not within {seconds:g} s: {what}\n{show()}")


@pytest.fixture(scope="module")
def room(tmp_path_factory: pytest.TempPathFactory) -> Iterator[Class]:
    here = tmp_path_factory.mktemp("class")
    secret = here / "instructor.pw"
    secret.write_text(hash_password(PASSWORD) + "\n", encoding="utf-8")
    proc = subprocess.Popen([sys.executable, "-m", "liansuo.cli", "serve", "jiaopei", "--seats", "3", "--port", "0",
                             "--web", "--web-port", "0", "--password-file", str(secret), "--reports",
                             str(here / "reports")], stdout=subprocess.PIPE,
                            stderr=(here / "serve.err").open("w", encoding="utf-8"), text=True)
    try:
        assert proc.stdout is not None
        first = proc.stdout.readline()
        threading.Thread(target=proc.stdout.read, daemon=True).start()  # the rest (textual-serve's banner), unread
        assert "ws://127.0.0.1:" in first and "browsers on http://" in first, first
        ws = first.split(" on ")[1].split(",")[0]
        web = first.split("browsers on ")[1].split()[0]
        yield Class(ws, web, here / "reports")
    finally:
        proc.terminate()
        proc.wait(10)
        subprocess.run([*TMUX, "kill-server"], capture_output=True)


def console(name: str, url: str, seat: int) -> None:
    """A trainee's terminal console in a tmux session of the private server."""
    command = f"{sys.executable} -m liansuo.cli tui --connect {url} --seat {seat} --name {name}"
    env = {k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES")}  # the console sizes to the pane
    subprocess.run([*TMUX, "new-session", "-d", "-s", name, "-x", "200", "-y", "50", command], check=True, env=env)


def screen(name: str) -> str:
    return subprocess.run([*TMUX, "capture-pane", "-p", "-t", name], capture_output=True, text=True).stdout


def type_in(name: str, line: str) -> None:
    subprocess.run([*TMUX, "send-keys", "-t", name, ":"], check=True)
    time.sleep(0.2)
    subprocess.run([*TMUX, "send-keys", "-t", name, "-l", line], check=True)
    subprocess.run([*TMUX, "send-keys", "-t", name, "Enter"], check=True)


def seat_of(teacher: ClassroomClient, seat: int) -> dict[str, object]:
    """The next summary of a seat the instructor receives (call it until it is fresh: they queue up)."""
    while True:
        msg = teacher._next()
        if msg.get("type") == "seats":
            return next(s for s in msg["seats"] if s["seat"] == seat)


@pytest.mark.skipif(shutil.which("tmux") is None, reason="tmux is not installed: the terminal consoles run in it")
def test_two_trainees_at_terminals_the_instructor_and_a_scored_report(room: Class) -> None:
    console("Li", room.ws, 1)
    console("Wang", room.ws, 2)
    until(lambda: "seat 1" in screen("Li") and "seat 2" in screen("Wang"), what="both consoles up")
    with ClassroomClient.instructor(room.ws, PASSWORD) as teacher:
        until(lambda: seat_of(teacher, 1)["connected"] and seat_of(teacher, 2)["connected"], what="seats taken")
        until(lambda: seat_of(teacher, 1)["trainee"] == "Li", what="seat 1 is Li's")
        # a fault on Li's seat: Li sees the red band's consequence, neither Li nor Wang the fault
        assert teacher.command("fault broken-rail IG", seat=1)["ok"]
        time.sleep(1.0)
        type_in("Li", "route X XI")
        until(lambda: "✗" in screen("Li") and "IG" in screen("Li"), what="Li's route refused over the red band")
        type_in("Li", "occupy 3G")
        until(lambda: "belongs to the instructor" in screen("Li"), what="Li's instructor command refused")
        type_in("Wang", "route X XI")
        until(lambda: "route X-XI selected" in screen("Wang"), what="Wang's route set on Wang's own station")
        for who in ("Li", "Wang"):
            assert "broken" not in screen(who), screen(who)
        until(lambda: seat_of(teacher, 1)["refused"] >= 1, what="Li's refusals counted for the instructor")
        # Li's console is closed and opened again: the seat is held for Li's token, which died with the console;
        # a name alone takes no seat, so the instructor frees it, and Li sits again at the station with its fault
        subprocess.run([*TMUX, "kill-session", "-t", "Li"], check=True)
        until(lambda: not seat_of(teacher, 1)["connected"], what="seat 1 left")
        assert teacher.request({"type": "free", "seats": [1]})["type"] == "ok"
        console("Li", room.ws, 1)
        until(lambda: "seat 1" in screen("Li") and seat_of(teacher, 1)["connected"], what="Li back at seat 1")
        type_in("Li", "route X XI")
        until(lambda: "✗" in screen("Li"), what="the red band is still there for Li")
        # an exercise on Wang's seat, worked at the terminal, scored and reported
        teacher.request({"type": "reset", "seats": [2]})
        reply = teacher.request({"type": "exercise", "seats": [2], "name": "jiaopei-cancel-route", "seed": 1})
        assert reply["type"] == "ok", reply
        until(lambda: "Cancel a wrong route" in screen("Wang"), what="Wang told of the exercise")
        until(lambda: "Esc / Enter closes" in screen("Wang"), what="the briefing in its dialog")
        subprocess.run([*TMUX, "send-keys", "-t", "Wang", "Escape"], check=True)  # read: back to the console
        until(lambda: "Esc / Enter closes" not in screen("Wang"), what="the briefing closed")
        type_in("Wang", "cancel X")
        time.sleep(1.0)
        type_in("Wang", "route X XI")
        until(lambda: "goals met" in screen("Wang"), 30, "Wang's exercise done", lambda: screen("Wang"))
        report = json.loads((room.reports / "seat2-Wang-jiaopei-cancel-route.json").read_text(encoding="utf-8"))
        assert report["trainee"] == "Wang" and report["all_goals_met"] and report["score"]["total"] >= 90
        assert [c["command"] for c in report["commands"]] == ["cancel X", "route X XI"]
        assert (room.reports / "seat2-Wang-jiaopei-cancel-route.html").exists()


TEXTAREA = "textarea.xterm-helper-textarea"  # where the page's terminal takes the keyboard


def log_in(browser: Browser, web: str, teacher: ClassroomClient, name: str, seat: int) -> None:
    """Log in as a trainee on the page, whose console then opens at the seat."""
    browser.log_in(web, name=name, seat=str(seat))
    # the page marks its body once the console process draws (started after the login, at the seat)
    until(lambda: bool(browser.evaluate("document.body.classList.contains('-first-byte')")), 60,
          "the console drawing on the page")
    until(lambda: seat_of(teacher, seat)["connected"] and seat_of(teacher, seat)["trainee"] == name, 20,
          f"{name} at seat {seat} from the browser")


@pytest.mark.skipif(chromium() is None, reason="no Chromium on this machine (Debian: apt-get install chromium): the "
                                                "browser's console is not tried")
def test_a_trainee_in_a_browser_logs_in_and_sets_a_route(room: Class, tmp_path: Path) -> None:
    with Browser(1400, 900) as browser, ClassroomClient.instructor(room.ws, PASSWORD) as teacher:
        log_in(browser, room.web, teacher, "Zhao", 3)
        teacher.request({"type": "watch", "seat": 3})

        def route_set() -> bool:
            snap = teacher.snapshot()
            return snap["seat"] == 3 and any(r["id"] == "X-XI" for r in snap["routes"])

        for attempt in range(3):  # keys typed while a loaded machine is still drawing may be lost: type again
            browser.focus(TEXTAREA)
            browser.type(":route X XI")
            browser.press("Enter")
            try:
                until(route_set, 10, "the browser's route on seat 3")
                break
            except AssertionError:
                if attempt == 2:
                    raise
                browser.press("Escape")
        browser.screenshot(tmp_path / "browser.png")
        assert (tmp_path / "browser.png").stat().st_size > 10_000

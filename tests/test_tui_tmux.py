"""`make run` in a real terminal (tmux, 80x24): the console shows the default station, ctrl+q asks, y quits cleanly.

Skipped when tmux is not installed. By default it runs `make run` in this checkout; with
``LIANSUO_TMUX_FRESH_CLONE=1`` it clones the repository first and lets `make run` build its own .venv (slow: it
installs the dependencies).
"""

from __future__ import annotations

import os
import shlex
import shutil
import subprocess
import time
import uuid
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parent.parent

pytestmark = pytest.mark.skipif(shutil.which("tmux") is None or shutil.which("make") is None,
                                reason="tmux (and make) are needed to run the console in a terminal; "
                                       "install them with 'apt-get install -y tmux make'")


def _tmux(*args: str) -> str:
    return subprocess.run(["tmux", *args], capture_output=True, text=True, check=False).stdout


def _wait_for(session: str, predicate: object, timeout: float) -> str:
    deadline = time.monotonic() + timeout
    screen = ""
    while time.monotonic() < deadline:
        screen = _tmux("capture-pane", "-t", session, "-p")
        if callable(predicate) and predicate(screen):
            return screen
        time.sleep(0.2)
    return screen


def _make_command(repo: Path) -> str:
    stamp, project = repo / ".venv" / ".installed", repo / "pyproject.toml"
    if stamp.exists() and stamp.stat().st_mtime >= project.stat().st_mtime:
        return "make run"
    if (repo / ".venv" / "bin" / "liansuo").exists():
        # an environment installed by hand (pip install -e): don't reinstall it, run the same target
        return "make -o .venv/.installed run"
    return "make run"


def test_make_run_shows_the_station_and_ctrl_q_asks_then_quits(tmp_path: Path) -> None:
    repo = ROOT
    timeout = 60.0
    if os.environ.get("LIANSUO_TMUX_FRESH_CLONE") == "1":
        repo = tmp_path / "clone"
        subprocess.run(["git", "clone", "-q", str(ROOT), str(repo)], check=True)
        timeout = 900.0
    session = f"liansuo-test-{uuid.uuid4().hex[:8]}"
    shell = f"cd {shlex.quote(str(repo))} && {_make_command(repo)}; echo LIANSUO-EXIT=$?; sleep 60"
    env = {k: v for k, v in os.environ.items() if not k.startswith(("TMUX", "TEXTUAL"))}
    env["TERM"] = "xterm-256color"
    subprocess.run(["tmux", "new-session", "-d", "-s", session, "-x", "80", "-y", "24", shell], check=True,
                   env=env)
    try:
        screen = _wait_for(session, lambda s: "IG" in s and "教培站" in s and "总取消" in s, timeout)
        assert "教培站" in screen and "IG" in screen, screen
        assert "Traceback" not in screen
        _tmux("send-keys", "-t", session, "C-q")
        screen = _wait_for(session, lambda s: "Quit the console?" in s, 20.0)
        assert "Quit the console?" in screen and "LIANSUO-EXIT=" not in screen, screen
        _tmux("send-keys", "-t", session, "y")
        screen = _wait_for(session, lambda s: "LIANSUO-EXIT=" in s, 20.0)
        assert "LIANSUO-EXIT=0" in screen, screen
        assert "Traceback" not in screen
    finally:
        _tmux("kill-session", "-t", session)


def _children(pid: int) -> list[int]:
    out = subprocess.run(["ps", "-o", "pid=", "--ppid", str(pid)], capture_output=True, text=True, check=False)
    return [int(x) for x in out.stdout.split()]


def _alive(pid: int) -> bool:
    state = subprocess.run(["ps", "-o", "stat=", "-p", str(pid)], capture_output=True, text=True, check=False)
    return bool(state.stdout.strip()) and not state.stdout.strip().startswith("Z")


def test_closing_the_terminal_of_make_run_ends_the_console() -> None:
    """A terminal window closed under `make run`: make gets the hangup, the console does not (it is make's child),
    and must still end, not read a dead terminal forever with a core busy. On a private tmux server."""
    server, session = f"liansuo-hup-{uuid.uuid4().hex[:8]}", "console"
    tmux = ["tmux", "-L", server]
    env = {k: v for k, v in os.environ.items() if not k.startswith(("TMUX", "TEXTUAL"))}
    env["TERM"] = "xterm-256color"
    subprocess.run([*tmux, "new-session", "-d", "-s", session, "-x", "80", "-y", "24",
                    f"cd {shlex.quote(str(ROOT))} && exec {_make_command(ROOT)}"], check=True, env=env)
    consoles: list[int] = []
    try:
        deadline = time.monotonic() + 60.0
        screen = ""
        while time.monotonic() < deadline and "总取消" not in screen:
            screen = subprocess.run([*tmux, "capture-pane", "-t", session, "-p"], capture_output=True, text=True,
                                    check=False).stdout
            time.sleep(0.2)
        assert "总取消" in screen, screen
        make = int(subprocess.run([*tmux, "list-panes", "-t", session, "-F", "#{pane_pid}"], capture_output=True,
                                  text=True, check=True).stdout.split()[0])
        consoles = [pid for child in _children(make) for pid in [child, *_children(child)]]
        assert consoles, "no console process under make"
        subprocess.run([*tmux, "kill-server"], check=False)  # the terminal goes away
        deadline = time.monotonic() + 10.0
        while time.monotonic() < deadline and any(_alive(pid) for pid in consoles):
            time.sleep(0.2)
        assert not any(_alive(pid) for pid in consoles), "the console outlived its terminal"
    finally:
        subprocess.run([*tmux, "kill-server"], check=False)
        for pid in consoles:
            if _alive(pid):
                os.kill(pid, 9)

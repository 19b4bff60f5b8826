"""``liansuo tui --log FILE`` (issue 46, item 10): the console's warnings and internal errors go to a file as they
happen, while the screen stays on the terminal (``2> FILE`` takes the screen itself: Textual draws on stderr)."""

from __future__ import annotations

import os
import shutil
import subprocess
import sys
import time
import warnings
from pathlib import Path
from typing import Any

import pytest
from test_tui_robustness import headless

import liansuo
from liansuo.cli.main import main
from liansuo.tui.app import ConsoleApp

TMUX = ["tmux", "-L", f"liansuo-log-{os.getpid()}"]


def test_an_internal_error_and_a_warning_are_in_the_log_as_they_happen(
        tmp_path: Path, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    log = tmp_path / "console.log"

    def failing_acknowledge(self: ConsoleApp) -> None:
        raise KeyError("injected")

    monkeypatch.setattr(ConsoleApp, "action_acknowledge", failing_acknowledge)
    seen: dict[str, str] = {}

    async def steps(pilot: Any) -> None:
        await pilot.press("a")
        warnings.warn("a warning while the console runs", UserWarning, stacklevel=1)
        await pilot.pause()
        seen["while running"] = log.read_text(encoding="utf-8")
        await pilot.press("ctrl+q", "y")

    monkeypatch.setattr(ConsoleApp, "run", headless(steps))
    assert main(["tui", "jiaopei", "--paused", "--log", str(log)]) == 1
    running = seen["while running"]
    assert "liansuo tui started" in running
    assert "console error" in running and "Traceback" in running and "KeyError: 'injected'" in running, running
    assert "UserWarning: a warning while the console runs" in running, running
    after = log.read_text(encoding="utf-8")
    assert "the console had 1 internal error and carried on" in after and "liansuo tui closed" in after, after
    assert "KeyError: 'injected'" in capsys.readouterr().err  # stderr still has the report, after the screen


def test_a_log_that_cannot_be_written_is_refused_before_the_console_starts(
        tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["tui", "jiaopei", "--log", str(tmp_path / "no" / "such.log")]) == 2
    err = capsys.readouterr().err
    assert "--log" in err and "no folder" in err and err.count("\n") == 1, err
    assert main(["tui", "--connect", "ws://127.0.0.1:1", "--seat", "1", "--log", str(tmp_path)]) == 2
    err = capsys.readouterr().err
    assert "it is a folder" in err and err.count("\n") == 1, err


def screen(name: str) -> str:
    return subprocess.run([*TMUX, "capture-pane", "-p", "-t", name], capture_output=True, text=True).stdout


@pytest.mark.skipif(shutil.which("tmux") is None, reason="tmux is not installed: the terminal consoles run in it")
def test_with_log_the_terminal_shows_the_console_and_with_2_redirected_it_does_not(tmp_path: Path) -> None:
    src = str(Path(liansuo.__file__).resolve().parents[1])
    env = {**{k: v for k, v in os.environ.items() if k not in ("COLUMNS", "LINES")}, "PYTHONPATH": src}
    log, err = tmp_path / "console.log", tmp_path / "stderr.txt"
    tui = f"{sys.executable} -m liansuo.cli tui jiaopei --paused"
    try:
        for name, command in (("logged", f"{tui} --log {log}"), ("redirected", f"{tui} 2> {err}")):
            subprocess.run([*TMUX, "new-session", "-d", "-s", name, "-x", "140", "-y", "40", "-c", str(tmp_path),
                            command], check=True, env=env)
        deadline = time.monotonic() + 30
        while "事件 Events" not in screen("logged") and time.monotonic() < deadline:
            time.sleep(0.2)
        assert "事件 Events" in screen("logged"), screen("logged")
        while "事件 Events" not in err.read_text(encoding="utf-8", errors="replace") and time.monotonic() < deadline:
            time.sleep(0.2)  # the second console draws a moment later
        assert "事件 Events" in err.read_text(encoding="utf-8", errors="replace")
        assert "事件 Events" not in screen("redirected")  # the screen went to the file
        subprocess.run([*TMUX, "send-keys", "-t", "logged", "C-q"], check=True)
        time.sleep(0.5)
        subprocess.run([*TMUX, "send-keys", "-t", "logged", "y"], check=True)
        deadline = time.monotonic() + 15
        while "closed" not in log.read_text(encoding="utf-8") and time.monotonic() < deadline:
            time.sleep(0.2)
        text = log.read_text(encoding="utf-8")
        assert "liansuo tui started" in text and "liansuo tui closed" in text and "\x1b[" not in text, text
    finally:
        subprocess.run([*TMUX, "kill-server"], capture_output=True)

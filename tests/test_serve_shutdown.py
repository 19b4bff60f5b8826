"""``liansuo serve`` stopped mid-exercise (issue 46, item 10): ctrl+c (SIGINT) or ``kill`` (SIGTERM) writes the report
of every exercise still going, marked as stopped, instead of losing the attempt. The server runs in its own process;
the instructor and the trainee are real websocket clients."""

from __future__ import annotations

import json
import signal
import subprocess
import sys
from pathlib import Path

import pytest

from liansuo.classroom.passwords import hash_password
from liansuo.server.client import ClassroomClient

PASSWORD = "correct horse"


@pytest.mark.parametrize("stop", [signal.SIGINT, signal.SIGTERM], ids=["ctrl+c", "SIGTERM"])
def test_a_server_stopped_mid_exercise_writes_its_partial_report(stop: signal.Signals, tmp_path: Path) -> None:
    secret = tmp_path / "instructor.pw"
    secret.write_text(hash_password(PASSWORD) + "\n", encoding="utf-8")
    reports = tmp_path / "reports"
    proc = subprocess.Popen([sys.executable, "-m", "liansuo.cli", "serve", "jiaopei", "--seats", "2", "--port", "0",
                             "--password-file", str(secret), "--reports", str(reports)], stdout=subprocess.PIPE,
                            stderr=subprocess.PIPE, text=True,
                            preexec_fn=lambda: signal.signal(signal.SIGINT, signal.SIG_DFL))  # as in a terminal
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        assert "ws://127.0.0.1:" in line, line
        url = line.split(" on ")[1].split()[0]
        with ClassroomClient.instructor(url, PASSWORD) as teacher, \
                ClassroomClient.trainee(url, seat=1, name="Li Lei") as li:
            reply = teacher.request({"type": "exercise", "seats": [1], "name": "jiaopei-cancel-route", "seed": 1})
            assert reply["type"] == "ok", reply
            assert li.command("cancel X")["ok"]  # one goal of two: the attempt is under way
            proc.send_signal(stop)
            out, err = proc.communicate(timeout=20)
    finally:
        if proc.poll() is None:
            proc.kill()
            proc.wait(10)
    assert proc.returncode == 0, err
    assert "Traceback" not in err, err
    [written] = sorted(reports.glob("*.json"))
    assert written.name == "seat1-Li-Lei-jiaopei-cancel-route.json" and str(written) in out, out
    report = json.loads(written.read_text(encoding="utf-8"))
    assert report["ended"] == "stopped: the server was stopped before the end" and report["finished"], report
    assert [c["command"] for c in report["commands"]] == ["cancel X"]
    assert not report["all_goals_met"]
    assert "stopped: the server was stopped" in (reports / "seat1-Li-Lei-jiaopei-cancel-route.html").read_text("utf-8")
    assert not list(reports.glob("seat2-*"))  # no exercise on seat 2: no report

"""The classroom reads a command line's name with the command language's own parser (issue 45, item 8): a quoted
or escaped ``run`` is the ``run`` the language would run, so it never moves the server's clock, and a trainee's
quoted instructor command is refused as the plain one is. ``liansuo serve`` in its own process, real websocket
clients on localhost."""

from __future__ import annotations

import subprocess
import sys
from collections.abc import Iterator

import pytest

from liansuo.classroom.passwords import hash_password
from liansuo.server.client import ClassroomClient

PASSWORD = "correct horse"
# each names 'run' to the command language (shlex's quoting, a backslash, a comment, a tab)
RUNS = ("'run' 60s", '"run" 60s', "r\\un 60s", "ru'n' 60s", "run\t60s", "  run 60s # a minute", "'run'")


@pytest.fixture(scope="module")
def url(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    secret = tmp_path_factory.mktemp("serve") / "instructor.pw"
    secret.write_text(hash_password(PASSWORD) + "\n", encoding="utf-8")
    proc = subprocess.Popen([sys.executable, "-m", "liansuo.cli", "serve", "jiaopei", "--seats", "2", "--port", "0",
                             "--password-file", str(secret)], stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                            text=True)
    try:
        assert proc.stdout is not None
        line = proc.stdout.readline()
        assert "ws://127.0.0.1:" in line, line + (proc.stderr.read() if proc.stderr else "")
        yield line.split(" on ")[1].split()[0]
    finally:
        proc.terminate()
        proc.wait(10)


def test_a_quoted_run_from_the_instructor_never_moves_the_clock(url: str) -> None:
    with ClassroomClient.instructor(url, PASSWORD) as teacher:
        assert teacher.request({"type": "clock", "seats": [1], "action": "pause"})["type"] == "ok"
        assert teacher.request({"type": "watch", "seat": 1})["type"] == "ok"
        t0 = teacher.snapshot()["t"]
        for line in RUNS:
            answer = teacher.command(line, seat=1)
            assert not answer["ok"] and "clock runs on the server" in answer["message"], (line, answer)
        assert teacher.snapshot()["t"] == t0  # not a minute later: no run reached the simulation
        assert teacher.command("route X XI", seat=1)["ok"]  # the instructor's other commands still run


def test_a_trainees_quoted_instructor_command_is_refused(url: str) -> None:
    with ClassroomClient.trainee(url, seat=2, name="Wang") as wang:
        for line in (*RUNS, "'fault' broken-rail IG", '"train" T1 at IIAG', "occ\\upy 3DG"):
            answer = wang.command(line)
            assert not answer["ok"], (line, answer)
            assert "instructor" in answer["message"] or "clock" in answer["message"], (line, answer)
        assert wang.command("'route' X XI")["ok"]  # an operator's command, quoted, is still one


def test_a_trainees_typo_is_told_as_one_and_not_counted(url: str) -> None:
    """Issue 46, item 4, over the wire: the seat's refused count, which the instructor's dashboard shows, takes no
    typo; an instructor's command from the seat does count."""
    with ClassroomClient.trainee(url, seat=1, name="Zhao") as zhao:
        answer = zhao.command("rout X XI")
        assert not answer["ok"] and answer["message"].startswith("unknown command 'rout'; did you mean 'route'?")
        assert not zhao.command("fault broken-rail IG")["ok"]
    with ClassroomClient.instructor(url, PASSWORD) as teacher:
        assert teacher.seats()[0]["refused"] == 1  # the instructor's command only

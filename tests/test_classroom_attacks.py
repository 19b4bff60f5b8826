"""The classroom under attack (issue 45): a seat taken by a name, a log that grows without end. ``liansuo serve``
runs in its own process and the attackers are raw websocket clients on localhost, as on a school's LAN
(docs/classroom.md, "Security")."""

from __future__ import annotations

import json
import subprocess
import sys
import time
import tracemalloc
from collections.abc import Iterator
from pathlib import Path

import pytest
from websockets.exceptions import ConnectionClosed
from websockets.sync.client import connect

from liansuo.classroom.assessment import KEPT
from liansuo.classroom.passwords import hash_password
from liansuo.server.classroom import LOG_LINES, MAX_LINE, Classroom
from liansuo.server.client import ClassroomClient, ClassroomError

PASSWORD = "correct horse"


def serve(folder: Path, *extra: str) -> tuple[subprocess.Popen[str], str]:
    secret = folder / "instructor.pw"
    secret.write_text(hash_password(PASSWORD) + "\n", encoding="utf-8")
    proc = subprocess.Popen([sys.executable, "-m", "liansuo.cli", "serve", "jiaopei", "--seats", "3", "--port", "0",
                             "--password-file", str(secret), "--reports", str(folder / "reports"), *extra],
                            stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True)
    assert proc.stdout is not None
    line = proc.stdout.readline()
    assert "ws://127.0.0.1:" in line, line + (proc.stderr.read() if proc.stderr else "")
    return proc, line.split(" on ")[1].split()[0]


@pytest.fixture
def url(tmp_path: Path) -> Iterator[str]:
    """A fresh server for each test: a lockout or a flood never reaches the next test."""
    proc, where = serve(tmp_path)
    try:
        yield where
    finally:
        proc.terminate()
        proc.wait(10)


def hello(url: str, message: dict[str, object]) -> dict[str, object]:
    """One raw hello and the server's first reply to it."""
    with connect(url) as ws:
        ws.send(json.dumps({"type": "hello", **message}))
        reply: dict[str, object] = json.loads(ws.recv(timeout=30))
        return reply


# ---- 1. seats are bound to their token ----------------------------------------------------------------------------
def test_a_name_never_takes_a_seat_its_token_does_and_the_instructor_frees_it(url: str) -> None:
    li = ClassroomClient.trainee(url, seat=1, name="Li")
    token = li.token
    assert li.command("route X XI")["ok"]
    li.close()
    time.sleep(0.3)
    # the attacker knows Li's name (the old lobby listed it) but not the token
    for attempt in ({"name": "Li"}, {"name": "Li", "token": "0" * 32}, {"name": ""}, {"name": "Li", "token": ""}):
        reply = hello(url, {"role": "trainee", "seat": 1, **attempt})
        assert reply["type"] == "error", (attempt, reply)
        assert "held for its trainee, who takes it back with the seat's token" in str(reply["message"]), reply
        assert "Li" not in str(reply["message"])  # nor does a refusal name the trainee
    with ClassroomClient.trainee(url, seat=1, name="Li", token=token) as back:  # Li's token: back at Li's station
        assert back.welcome["seat"] == 1 and back.token == token
        assert "X-XI" in {r["id"] for r in back.snapshot()["routes"]}
    time.sleep(0.3)
    with ClassroomClient.instructor(url, PASSWORD) as teacher:
        reply = teacher.request({"type": "free", "seats": [1]})
        assert reply["type"] == "ok" and "freed" in str(reply["message"]), reply
        seats = next(m for m in iter(teacher._next, None) if m.get("type") == "seats")["seats"]
        assert seats[0]["trainee"] == "" and not seats[0]["connected"]
    with ClassroomClient.trainee(url, seat=1, name="Zhou") as zhou:  # a newcomer sits at the freed seat
        assert zhou.token != token
        with pytest.raises(ClassroomError, match="seat 1 is taken"):  # Li's old token holds it no more
            ClassroomClient.trainee(url, seat=1, name="Li", token=token)


def test_a_freed_seat_is_taken_from_the_client_that_sat_there(url: str) -> None:
    with connect(url) as ws, ClassroomClient.instructor(url, PASSWORD) as teacher:
        ws.send(json.dumps({"type": "hello", "role": "trainee", "seat": 2, "name": "Wang"}))
        assert json.loads(ws.recv(timeout=10))["type"] == "welcome"
        assert teacher.request({"type": "free", "seats": [2]})["type"] == "ok"
        with pytest.raises(ConnectionClosed) as closed:
            while True:
                ws.recv(timeout=10)
        assert closed.value.rcvd is not None and "the instructor freed seat 2" in closed.value.rcvd.reason
    reply = hello(url, {"role": "trainee", "seat": 1, "name": "Wang"})
    assert reply["type"] == "welcome"
    assert teacher_free_refused(url)


def teacher_free_refused(url: str) -> bool:
    """A trainee may not free seats: only the instructor."""
    with ClassroomClient.trainee(url, seat=3, name="Qian") as qian:
        reply = qian.request({"type": "free", "seats": "all"})
        return reply["type"] == "error" and "instructor" in str(reply["message"])


def test_the_lobby_names_nobody_and_a_name_with_control_characters_is_refused(url: str) -> None:
    with ClassroomClient.trainee(url, seat=2, name="Wang Fang"):
        with connect(url) as ws:
            ws.send('{"type": "lobby"}')
            raw = ws.recv(timeout=10)
        lobby = json.loads(raw)
        assert "Wang" not in str(raw)
        assert [(s["seat"], s["taken"], s["connected"]) for s in lobby["seats"]] == [
            (1, False, False), (2, True, True), (3, False, False)]
        for name in ("\x1b[2J\x1b]0;pwned\x07Li", "Li\u202eiL", "Li\nLi", "Li\x9bLi"):
            reply = hello(url, {"role": "trainee", "seat": 1, "name": name})
            assert reply["type"] == "error" and "letters, digits, spaces and punctuation" in str(reply["message"])
            assert "\x1b" not in json.dumps(reply, ensure_ascii=False)
    with ClassroomClient.trainee(url, seat=1, name="  李雷 (Li Lei)  ") as li, \
            ClassroomClient.instructor(url, PASSWORD) as teacher:
        seats = next(m for m in iter(teacher._next, None) if m.get("type") == "seats")["seats"]
        assert seats[0]["trainee"] == "李雷 (Li Lei)" and li.welcome["seat"] == 1


# ---- 2. bounded memory ----------------------------------------------------------------------------------------------
def test_a_hundred_thousand_commands_keep_the_log_at_its_bound() -> None:
    room = Classroom("jiaopei", 1)
    try:
        room.start_exercise([1], "jiaopei-cancel-route", seed=1)
        seat = room.seat(1)
        line = "route NOSUCH X # " + "x" * (MAX_LINE - 20)  # refused by the interlocking, never ends the exercise
        tracemalloc.start()
        try:
            for _ in range(10_000):
                room.command(1, "trainee", line)
            before = tracemalloc.get_traced_memory()[0]
            for _ in range(90_000):
                room.command(1, "trainee", line)
            grown = tracemalloc.get_traced_memory()[0] - before
        finally:
            tracemalloc.stop()
        a = seat.desk.assessment
        assert a is not None and not a.finished
        print(f"\n100,000 commands of {len(line)} characters: memory grew {grown / 1e3:.0f} kB over the last 90,000")
        assert len(seat.log) == LOG_LINES and seat.commands == 100_000 and seat.refused == 100_000
        assert len(a.entries) == KEPT and a.report()["commands_not_kept"] == 100_000 - KEPT
        assert a.progress()["refused"] == 100_000
        assert grown < 1_000_000, f"{grown} bytes more after 90,000 commands: something keeps every command"
    finally:
        room.close()


def test_an_over_long_command_line_is_refused_over_the_wire(url: str) -> None:
    with ClassroomClient.trainee(url, seat=1, name="Li") as li:
        for length in (MAX_LINE + 1, 1990, 60_000):
            reply = li.command("route X XI # " + "x" * (length - 13))
            assert reply["type"] == "answer" and reply["ok"] is False, reply
            assert f"at most {MAX_LINE} characters, not {length}" in str(reply["message"]), reply
        assert li.command("route X XI # " + "x" * (MAX_LINE - 13))["ok"]  # at the limit: run
        li.ws.send(json.dumps({"type": "command", "id": 1, "line": "x" * 70_000}))  # past the 64 KiB message limit
        with pytest.raises(ConnectionClosed):
            while True:
                li.ws.recv(timeout=10)

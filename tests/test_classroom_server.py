"""The classroom server end to end: ``liansuo serve`` in its own process, trainees and the instructor as real
websocket clients (docs/classroom.md). What a trainee's seat receives is read from the wire."""

from __future__ import annotations

import json
import subprocess
import sys
import time
from collections.abc import Iterator
from pathlib import Path

import pytest
from websockets.sync.client import ClientConnection, connect

from liansuo.classroom.passwords import hash_password, instructor_hash, matches
from liansuo.classroom.snapshot import EventCursor
from liansuo.server.client import ClassroomClient, ClassroomError

PASSWORD = "correct horse"


@pytest.fixture(scope="module")
def url(tmp_path_factory: pytest.TempPathFactory) -> Iterator[str]:
    secret = tmp_path_factory.mktemp("serve") / "instructor.pw"
    secret.write_text(hash_password(PASSWORD) + "\n", encoding="utf-8")
    proc = subprocess.Popen([sys.executable, "-m", "liansuo.cli", "serve", "jiaopei", "--seats", "3", "--port", "0",
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


@pytest.fixture(autouse=True)
def free_seats(url: str) -> Iterator[None]:
    """Each test finds every seat free: the instructor frees them after it (a seat is never taken by a name)."""
    yield
    with ClassroomClient.instructor(url, PASSWORD) as teacher:
        assert teacher.request({"type": "free", "seats": "all"})["type"] == "ok"


def test_a_trainee_cannot_send_the_instructors_commands(url: str) -> None:
    with ClassroomClient.trainee(url, seat=2, name="Wang") as wang:
        for line in ("fault broken-rail IG", "faults", "train T1 at IIAG", "occupy 3DG", "repair broken-rail IG",
                     "run 10min", "expect section IG free"):
            answer = wang.command(line)
            assert not answer["ok"], line
            assert "instructor" in answer["message"] or "clock" in answer["message"], answer
        assert wang.command("route X XI")["ok"]


def test_an_injected_fault_never_reaches_the_other_seat_nor_the_faulted_trainees_log(url: str) -> None:
    with ClassroomClient.instructor(url, PASSWORD) as teacher, ClassroomClient.trainee(url, seat=1, name="Li") as li, \
            ClassroomClient.trainee(url, seat=2, name="Wang") as wang:
        assert teacher.command("fault broken-rail IG", seat=1)["ok"]
        time.sleep(1.0)
        for _ in range(4):
            li.snapshot()
            wang.snapshot()
        assert li.last is not None and wang.last is not None
        assert li.last["sections"]["IG"][0] is True  # the red band, as the track relay shows it
        assert wang.last["sections"]["IG"][0] is False  # the other seat's station is untouched
        for client in (li, wang):
            seen = json.dumps(client.events)
            assert "broken" not in seen and "fault" not in seen, seen
        answer = li.command("fault-release IG")  # an operator's command: the interlocking answers it
        assert answer["type"] == "answer" and "instructor" not in answer["message"], answer
        teacher.request({"type": "watch", "seat": 1})
        teacher.snapshot()
        assert any("fault injected" in text for _, _, text in teacher.events)
        assert teacher.command("repair broken-rail IG", seat=1)["ok"]


def test_a_seat_is_taken_back_with_its_token_and_by_nobody_else(url: str) -> None:
    first = ClassroomClient.trainee(url, seat=3, name="Zhao")
    token = first.token
    with pytest.raises(ClassroomError, match="seat 3 is taken"):
        ClassroomClient.trainee(url, seat=3, name="Qian")
    first.close()
    time.sleep(0.3)
    for name in ("Qian", "Zhao", ""):  # nor by its trainee's name, nor by a client that gives no name
        with pytest.raises(ClassroomError, match=r"held for its trainee.*token.*instructor to free"):
            ClassroomClient.trainee(url, seat=3, name=name)
    with pytest.raises(ClassroomError, match="held for its trainee"):
        ClassroomClient.trainee(url, seat=3, name="Zhao", token="0" * 32)
    with pytest.raises(ClassroomError, match="no seat 4"):
        ClassroomClient.trainee(url, seat=4)
    with ClassroomClient.trainee(url, seat=3, name="Zhao", token=token) as back:
        assert back.welcome["seat"] == 3
        assert back.command("cancel X")["type"] == "answer"


def test_bad_messages_get_an_error_reply_and_the_server_carries_on(url: str) -> None:
    with ClassroomClient.trainee(url, seat=2, name="Wang") as c:
        for raw in ("{", "[]", '{"type": "command"}', '{"type": "command", "id": -1, "line": "x"}',
                    '{"type": "clock", "seats": "all", "action": "pause"}', '{"type": "hello", "role": "trainee"}',
                    json.dumps({"type": "command", "id": 1, "seat": 1, "line": "cancel X"}), '"\\u0000"'):
            c.ws.send(raw)
            reply = _reply(c)
            assert reply["type"] == "error", (raw, reply)
        assert c.command("route X XI")["type"] == "answer"


def test_every_reply_carries_the_id_of_its_message_and_none_without_one(url: str) -> None:
    def reply(ws: ClientConnection) -> dict[str, object]:
        while True:
            msg = json.loads(ws.recv(timeout=5))
            if msg["type"] not in ("snapshot", "seats"):
                return dict(msg)

    with connect(url) as ws:
        ws.send(json.dumps({"type": "lobby", "id": 7}))
        assert reply(ws)["id"] == 7
    with connect(url) as ws:
        ws.send(json.dumps({"type": "hello", "id": 8, "role": "trainee", "seat": 1, "name": "Li"}))
        assert (welcome := reply(ws))["type"] == "welcome" and welcome["id"] == 8, welcome
        cases: list[tuple[dict[str, object], str]] = [
            ({"type": "command", "id": 2**53, "line": "route X XI"}, "answer"),
            ({"type": "watch", "id": 0, "seat": 1}, "error"),  # the instructor's
            ({"type": "command", "id": 11, "line": 5}, "error"),  # unreadable, its id readable
            ({"type": "command", "line": "cancel X"}, "answer")]
        for raw, kind in cases:
            ws.send(json.dumps(raw))
            got = reply(ws)
            assert got["type"] == kind and got.get("id") == raw.get("id"), (raw, got)
            assert "id" in got or "id" not in raw, got
        for bad in (True, -1, 2**53 + 1, "12"):  # not an id: refused, and not echoed
            ws.send(json.dumps({"type": "command", "id": bad, "line": "cancel X"}))
            got = reply(ws)
            assert got["type"] == "error" and "id" not in got and "id" in str(got["message"]), (bad, got)
    with connect(url) as ws:
        ws.send(json.dumps({"type": "hello", "id": 9, "role": "trainee", "seat": 99}))
        assert (refused := reply(ws))["type"] == "error" and refused["id"] == 9, refused


def _reply(c: ClassroomClient) -> dict[str, object]:
    while True:
        msg = c._next()
        if msg.get("type") not in ("snapshot", "seats"):
            return msg


def test_the_instructor_needs_the_password_and_runs_the_clocks(url: str) -> None:
    with pytest.raises(ClassroomError, match="wrong instructor password"):
        ClassroomClient.instructor(url, "guess")
    with connect(url) as ws:  # a first message that is not a hello
        ws.send('{"type": "command", "id": 1, "line": "route X XI"}')
        assert "hello" in json.loads(ws.recv(timeout=5))["message"]
    with ClassroomClient.instructor(url, PASSWORD) as teacher:
        assert teacher.request({"type": "clock", "seats": [2], "action": "pause"})["type"] == "ok"
        t0 = teacher.request({"type": "watch", "seat": 2}) and teacher.snapshot()["t"]
        time.sleep(0.6)
        assert teacher.snapshot()["t"] == t0  # paused
        assert teacher.request({"type": "clock", "seats": "all", "action": "run", "speed": 4})["type"] == "ok"
        time.sleep(0.6)
        assert teacher.snapshot()["t"] > t0
        assert teacher.request({"type": "clock", "seats": [9], "action": "run"})["type"] == "error"
        seats = teacher.request({"type": "clock", "seats": "all", "speed": 1.0})
        assert seats["type"] == "ok"


def test_the_password_is_kept_hashed() -> None:
    stored = hash_password(PASSWORD)
    assert PASSWORD not in stored and stored.startswith("scrypt$")
    assert matches(PASSWORD, stored) and not matches("correct horse ", stored) and not matches(PASSWORD, "junk")


def test_no_password_means_no_server(tmp_path: Path, monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.delenv("LIANSUO_INSTRUCTOR_PASSWORD", raising=False)
    with pytest.raises(ValueError, match="LIANSUO_INSTRUCTOR_PASSWORD"):
        instructor_hash(None)
    with pytest.raises(ValueError, match="cannot read"):
        instructor_hash(tmp_path / "missing")


def test_a_team_shares_one_station_and_its_clock() -> None:
    from liansuo.server.classroom import Classroom

    team = Classroom("jiaopei", 3, shared=True)
    try:
        assert team.command(1, "trainee", "route X XI").ok
        team.advance(8.0)
        assert "X-XI" in {r.id for r in team.seat(3).sim.view.routes()}  # seat 3 sees seat 1's route
        team.set_clock([2], paused=True)
        t = team.seat(1).sim.t
        team.advance(2.0)
        assert team.seat(1).sim.t == t and team.snapshot(3, "trainee", EventCursor())["paused"] is True
        team.reset([1])
        assert not team.seat(2).sim.view.routes()
    finally:
        team.close()
    alone = Classroom("jiaopei", 2)
    try:
        assert alone.command(1, "trainee", "route X XI").ok
        alone.advance(8.0)
        assert not alone.seat(2).sim.view.routes()
    finally:
        alone.close()


def test_serving_browsers_on_every_address_needs_the_address_they_reach(capsys: pytest.CaptureFixture[str],
                                                                       tmp_path: Path) -> None:
    from liansuo.cli.main import main

    secret = tmp_path / "pw"
    secret.write_text(hash_password(PASSWORD) + "\n", encoding="utf-8")
    assert main(["serve", "--web", "--host", "0.0.0.0", "--password-file", str(secret)]) == 2
    err = capsys.readouterr().err
    assert "give --public-url http://ADDRESS:8000" in err and err.count("\n") == 1
    assert main(["serve", "--web", "--public-url", "10.0.0.5:8000", "--password-file", str(secret)]) == 2
    assert "an http:// or https:// address" in capsys.readouterr().err


@pytest.mark.parametrize("how", ["terminate", "kill"])
def test_the_browsers_page_ends_with_the_server_however_it_ends(how: str, tmp_path: Path) -> None:
    import socket

    secret = tmp_path / "pw"
    secret.write_text(hash_password(PASSWORD) + "\n", encoding="utf-8")
    proc = subprocess.Popen([sys.executable, "-m", "liansuo.cli", "serve", "--port", "0", "--web", "--web-port", "0",
                             "--password-file", str(secret)], stdout=subprocess.PIPE, stderr=subprocess.DEVNULL,
                            text=True)
    assert proc.stdout is not None
    first = proc.stdout.readline()
    port = int(first.split("browsers on ")[1].split()[0].rsplit(":", 1)[1])

    def listening() -> bool:
        with socket.socket() as s:
            return s.connect_ex(("127.0.0.1", port)) == 0

    deadline = time.monotonic() + 20
    while not listening():
        assert time.monotonic() < deadline, "the browsers' page never came up"
        time.sleep(0.2)
    getattr(proc, how)()  # SIGTERM: the server stops it; SIGKILL: it notices its server is gone
    proc.wait(10)
    deadline = time.monotonic() + 10
    while listening():
        assert time.monotonic() < deadline, f"the browsers' page outlived its server ({how})"
        time.sleep(0.2)

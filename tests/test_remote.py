"""The classroom's clients (``liansuo tui --connect``) against a real classroom server: the trainee's console on a
seat, what it shows and never shows, the instructor's dashboard and a seat opened from it, and the fail-safe picture
while the connection is down (docs/classroom.md). The server runs in a thread of the test; the consoles are driven as
a user drives them (Textual's Pilot)."""

from __future__ import annotations

import asyncio
import itertools
import socket
import threading
import time
from collections.abc import Callable, Iterator
from pathlib import Path
from typing import Any

import pytest
from consoletest import SIZE, footer, message, run
from textual.widgets import Static

from liansuo.classroom.passwords import hash_password
from liansuo.remote.app import RemoteConsoleApp
from liansuo.remote.dashboard import DashboardScreen
from liansuo.remote.link import ServerLink
from liansuo.remote.sim import ENDED, LOST
from liansuo.server.classroom import Classroom
from liansuo.server.client import ClassroomClient
from liansuo.server.websocket import ClassroomServer
from liansuo.tui.briefing import BriefingScreen
from liansuo.tui.commands import console_commands
from liansuo.tui.grid import Ref
from liansuo.tui.paint import BAND_COLOUR, glyph

PASSWORD = "correct horse"
class Server:
    """A classroom server in a thread of its own, stopped and started again on the same port at will."""

    def __init__(self, seats: int = 2, reports: Path | None = None, **limits: float) -> None:
        self.classroom = Classroom("jiaopei", seats, reports=reports)
        self.server = ClassroomServer(self.classroom, hash_password(PASSWORD), **limits)  # type: ignore[arg-type]
        self.loop = asyncio.new_event_loop()
        self.thread = threading.Thread(target=self.loop.run_forever, daemon=True)
        self.thread.start()
        self.task: asyncio.Task[None] | None = None
        self.port = self.start(0)

    @property
    def url(self) -> str:
        return f"ws://127.0.0.1:{self.port}"

    def start(self, port: int) -> int:
        async def begin() -> int:
            ready: asyncio.Future[int] = self.loop.create_future()
            self.task = asyncio.create_task(self.server.serve("127.0.0.1", port, ready))
            return await ready

        return asyncio.run_coroutine_threadsafe(begin(), self.loop).result(10)

    def stop(self) -> None:
        async def end() -> None:
            assert self.task is not None
            self.task.cancel()
            await asyncio.gather(self.task, return_exceptions=True)

        asyncio.run_coroutine_threadsafe(end(), self.loop).result(10)

    def close(self) -> None:
        self.stop()
        self.loop.call_soon_threadsafe(self.loop.stop)
        self.thread.join(5)
        self.classroom.close()


@pytest.fixture
def server(tmp_path: Path) -> Iterator[Server]:
    s = Server(reports=tmp_path / "reports")
    try:
        yield s
    finally:
        s.close()


async def until(pilot: Any, condition: Callable[[], bool], seconds: float = 8.0) -> None:
    """Let the console run until ``condition`` holds (its clock takes the server's snapshots)."""
    for _ in range(int(seconds / 0.1)):
        if condition():
            return
        await pilot.pause(0.1)
    assert condition()


def band(app: RemoteConsoleApp, section: str) -> str:
    """The colour the diagram draws a section's band in now."""
    d = app.diagram
    d.update_view()
    assert d.layout_ is not None
    g = d.layout_.at(*d.layout_.targets[Ref("section", section)])
    assert g is not None
    _, style = glyph(d.frame(), g, set())
    return str(style.color.name if style.color else "")


def log(app: RemoteConsoleApp) -> str:
    return "\n".join(app.log_panel.lines_text)


async def type_line(pilot: Any, line: str) -> None:
    await pilot.press("colon", *[{" ": "space"}.get(c, c) for c in line], "enter")
    await pilot.pause()


@run
async def test_a_trainee_sees_a_fault_as_the_cbi_shows_it_and_never_the_fault(server: Server) -> None:
    app = RemoteConsoleApp(ServerLink(server.url, {"role": "trainee", "seat": 1, "name": "Li"}))
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await until(pilot, lambda: app.remote.live and band(app, "IG") == BAND_COLOUR["free"])
        with ClassroomClient.instructor(server.url, PASSWORD) as teacher:
            assert teacher.command("fault broken-rail IG", seat=1)["ok"]
        await until(pilot, lambda: band(app, "IG") == BAND_COLOUR["occupied"])
        await type_line(pilot, "route X XI")
        assert "IG" in message(app) and "✗" in message(app), message(app)  # the interlocking's own refusal
        await until(pilot, lambda: app.remote.t > 1.0)
        seen = log(app) + message(app)
        assert "broken" not in seen and "fault " not in seen, seen
        assert app.instructor_panel is None


@run
async def test_a_trainees_instructor_command_is_refused_with_the_reason(server: Server) -> None:
    app = RemoteConsoleApp(ServerLink(server.url, {"role": "trainee", "seat": 1, "name": "Li"}))
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await type_line(pilot, "fault broken-rail IG")
        assert "belongs to the instructor" in message(app), message(app)
        assert "refused" in log(app)
        assert server.classroom.seat(1).sim.field.faults == {}  # nothing reached the server's simulation
        assert server.classroom.seat(1).refused == 1  # the server judged it, and counts it for the instructor
        await pilot.press("escape")  # from the command bar back to the diagram
        keys = footer(app)  # the trainee's own keys: no clock, no F2 and no F3 (issue 46, item 5)
        assert "? help" in keys and "space" not in keys and "F2" not in keys and "F3" not in keys, keys
        titles = [c.title for c in console_commands(app)]  # nor in the command palette (item 7)
        assert "route X XI" in titles and "pause / run" not in titles and "instructor panel" not in titles, titles
        await pilot.press("f2")
        assert "instructor's console" in message(app) and app.instructor_panel is None, message(app)
        await pilot.press("space")
        assert "the instructor pauses and runs it" in message(app), message(app)
        await pilot.press("f3")
        assert "dashboard is the instructor's" in message(app) and app.screen is app.screen_stack[0], message(app)
        assert not server.classroom.seat(1).desk.paused


@run
async def test_a_route_set_on_the_trainees_console_is_locked_on_the_server(server: Server) -> None:
    app = RemoteConsoleApp(ServerLink(server.url, {"role": "trainee", "seat": 2, "name": "Wang"}))
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await type_line(pilot, "route X XI")
        assert "✓" in message(app), message(app)
        with ClassroomClient.instructor(server.url, PASSWORD) as teacher:
            teacher.request({"type": "watch", "seat": 2})
            for _ in range(8):
                snap = teacher.snapshot()
                if snap["seat"] == 2 and any(r["id"] == "X-XI" for r in snap["routes"]):
                    break
            assert any(r["id"] == "X-XI" for r in snap["routes"]), snap["routes"]
        await until(pilot, lambda: band(app, "IG") == BAND_COLOUR["locked"])


@run
async def test_the_instructor_opens_a_seat_from_the_dashboard_and_faults_it(server: Server) -> None:
    with ClassroomClient.trainee(server.url, seat=1, name="Li"):
        app = RemoteConsoleApp(ServerLink(server.url, {"role": "instructor", "password": PASSWORD}))
        async with app.run_test(size=SIZE) as pilot:
            await pilot.pause()
            assert isinstance(app.screen, DashboardScreen)
            dash = app.screen
            await until(pilot, lambda: len(dash._shown) == 2)
            assert dash._shown[0][:3] == ("1", "Li", "yes") and dash._shown[1][0] == "2"
            await pilot.press("down", "enter")  # seat 2
            await until(pilot, lambda: not isinstance(app.screen, DashboardScreen) and app.remote.seat == 2)
            await until(pilot, lambda: app.remote.live and band(app, "IG") == BAND_COLOUR["free"])
            await type_line(pilot, "fault broken-rail IG")
            assert "✓" in message(app), message(app)
            await until(pilot, lambda: band(app, "IG") == BAND_COLOUR["occupied"])
            assert server.classroom.seat(2).sim.field.faults and not server.classroom.seat(1).sim.field.faults
            await until(pilot, lambda: "fault" in log(app))  # the instructor sees every event of the seat
            await pilot.press("f3")
            assert isinstance(app.screen, DashboardScreen)
            await pilot.press("p")  # the selected seat (2)
            await until(pilot, lambda: server.classroom.seat(2).desk.paused)
            assert not server.classroom.seat(1).desk.paused
            await pilot.press("x")
            await until(pilot, lambda: not server.classroom.seat(2).sim.field.faults)
            await pilot.press("R")
            await until(pilot, lambda: not server.classroom.seat(2).desk.paused)


@run
async def test_connection_lost_shows_the_fail_safe_picture_and_comes_back(server: Server) -> None:
    app = RemoteConsoleApp(ServerLink(server.url, {"role": "trainee", "seat": 1, "name": "Li"}))
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await until(pilot, lambda: app.remote.live and band(app, "IG") == BAND_COLOUR["free"])
        server.stop()
        await until(pilot, lambda: band(app, "IG") == BAND_COLOUR["occupied"])
        assert LOST in str(app.status_bar.content)
        assert all(pos is None for pos, _ in app.diagram.frame().turnouts.values())
        assert not any(lit for lamps in app.diagram.frame().lamps.values() for _, lit in lamps)
        await type_line(pilot, "route X XI")
        assert "connection to the classroom server lost" in message(app), message(app)
        server.start(server.port)
        await until(pilot, lambda: app.link.connected and band(app, "IG") == BAND_COLOUR["free"])
        assert LOST not in str(app.status_bar.content)
        await type_line(pilot, "route X XI")
        assert "✓" in message(app), message(app)


def test_a_late_reply_never_answers_the_next_request(tmp_path: Path) -> None:
    """The server reads this client's messages one a second: the second request's reply comes after the request
    gave up, while the third request waits. The third gets its own reply, never the late one."""
    slow = Server(reports=tmp_path, rate=1.0, burst=1.0)
    link = ServerLink(slow.url, {"role": "trainee", "seat": 1, "name": "Li"})
    try:
        first = link.command("cancel X")  # takes the one message the server reads at once
        assert first["type"] == "answer" and "no route is set" in first["message"], first
        link.timeout = 0.3
        late = link.command("route X XI")  # read by the server a second later
        assert late == {"type": "error", "message": "no answer from the classroom server in 0.3 s"}, late
        link.timeout = 5.0
        own = link.request({"type": "watch", "seat": 2})  # its reply comes after the late one ('route X-XI selected')
        assert own["type"] == "error" and "'watch' is the instructor's" in own["message"], own
        after = link.command("cancel X")
        assert after["type"] == "answer" and after["message"] == "route X-XI cancelled", after  # the late one ran
    finally:
        link.close()
        slow.close()


class Listener:
    """A port that accepts each connection and closes it at once, noting when: a server that is down but whose
    port still answers, and counts the dials."""

    def __init__(self, port: int) -> None:
        self.sock = socket.socket()
        self.sock.setsockopt(socket.SOL_SOCKET, socket.SO_REUSEADDR, 1)
        self.sock.bind(("127.0.0.1", port))
        self.sock.listen()
        self.sock.settimeout(0.1)
        self.dials: list[float] = []
        self.open = True
        self.thread = threading.Thread(target=self.serve, daemon=True)
        self.thread.start()

    def serve(self) -> None:
        while self.open:
            try:
                conn, _ = self.sock.accept()
            except TimeoutError:
                continue
            self.dials.append(time.monotonic())
            conn.close()

    def close(self) -> None:
        self.open = False
        self.thread.join(5)
        self.sock.close()


@run
async def test_the_link_dials_again_with_backoff_and_the_console_comes_back(server: Server) -> None:
    app = RemoteConsoleApp(ServerLink(server.url, {"role": "trainee", "seat": 1, "name": "Li"}))
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await until(pilot, lambda: app.remote.live and band(app, "IG") == BAND_COLOUR["free"])
        server.stop()
        listener = Listener(server.port)
        try:
            await pilot.pause(8.5)
        finally:
            listener.close()
        gaps = [b - a for a, b in itertools.pairwise(listener.dials)]
        # websockets' backoff: at once, then within 5 s (at random), then 3.1 s, 5 s, 8.1 s ... later; every second
        # would be 8 dials or more
        assert 2 <= len(listener.dials) <= 4, listener.dials
        assert gaps[-1] >= 3.0, gaps
        assert not app.link.connected and not app.link.ended and LOST in str(app.status_bar.content)
        server.start(server.port)
        await until(pilot, lambda: app.link.connected and band(app, "IG") == BAND_COLOUR["free"], 14)
        assert app.link.generation == 1 and LOST not in str(app.status_bar.content)
        await type_line(pilot, "route X XI")
        assert "✓" in message(app), message(app)


@run
async def test_a_seat_freed_by_the_instructor_ends_the_trainees_link_and_says_why(server: Server) -> None:
    app = RemoteConsoleApp(ServerLink(server.url, {"role": "trainee", "seat": 1, "name": "Li"}))
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await until(pilot, lambda: app.remote.live)
        with ClassroomClient.instructor(server.url, PASSWORD) as teacher:
            assert teacher.request({"type": "free", "seats": [1]})["type"] == "ok"
        await until(pilot, lambda: app.link.ended)
        await pilot.pause(1.5)  # the console dials no more: the seat stays free for another trainee
        assert "the instructor freed seat 1" in message(app) and ENDED in message(app), message(app)
        assert ENDED in str(app.status_bar.content) and band(app, "IG") == BAND_COLOUR["occupied"]
        assert not server.classroom.seat(1).token and not app.link.connected
        await type_line(pilot, "route X XI")
        assert "ended" in message(app) and "nothing was sent" in message(app), message(app)


def wait_for(condition: Callable[[], bool], seconds: float, why: Callable[[], object]) -> None:
    deadline = time.monotonic() + seconds
    while not condition():
        assert time.monotonic() < deadline, why()
        time.sleep(0.1)


def test_the_instructors_link_comes_back_on_its_seat_and_a_refused_hello_ends_it(server: Server) -> None:
    link = ServerLink(server.url, {"role": "instructor", "password": PASSWORD})
    try:
        assert link.watch(2)["type"] == "ok"
        server.stop()
        server.start(server.port)
        wait_for(lambda: link.connected and link.generation == 1, 12, lambda: link.problem)
        link.take()
        wait_for(lambda: (link.take()[0] or {}).get("seat") == 2, 5, link.take)  # seat 2's, watched again
        assert link.command("route X XI")["ok"] and link.seat == 2
        server.stop()
        server.server.instructor_hash = hash_password("another horse")  # restarted with another password
        server.start(server.port)
        wait_for(lambda: link.ended, 12, lambda: (link.connected, link.problem))
        assert "the classroom server refused: wrong instructor password" in link.problem, link.problem
        time.sleep(1.5)
        assert not link.connected and link.generation == 1
        assert server.server.guard._seen["127.0.0.1"].failures == 1  # tried once, not again and again
    finally:
        link.close()


@pytest.mark.parametrize(("argv", "why"), [
    (["--connect", "http://127.0.0.1:1"], "websocket address"),
    (["--connect", "ws://127.0.0.1:1", "--seat", "1"], "cannot reach the classroom server"),
    (["--connect", "ws://127.0.0.1:1", "--seat", "99"], "--seat is 1 to 64"),
    (["--connect", "ws://127.0.0.1:1", "--seat", "1", "--paused"], "--paused is not for --connect"),
    (["--seat", "1"], "--seat goes with --connect"),
])
def test_a_client_that_cannot_start_says_why_in_one_line(argv: list[str], why: str,
                                                         capsys: pytest.CaptureFixture[str]) -> None:
    from liansuo.cli.main import main

    assert main(["tui", *argv]) == 2
    err = capsys.readouterr().err
    assert why in err and err.count("\n") == 1 and "Traceback" not in err, err


def test_a_wrong_password_or_a_taken_seat_ends_the_client_with_status_2(
        server: Server, tmp_path: Any, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    from liansuo.cli.main import main

    wrong = tmp_path / "pw"
    wrong.write_text("wrong horse\n", encoding="utf-8")
    assert main(["tui", "--connect", server.url, "--instructor", "--password-file", str(wrong)]) == 2
    assert "wrong instructor password" in capsys.readouterr().err
    hashed = tmp_path / "hash"
    hashed.write_text(hash_password(PASSWORD) + "\n", encoding="utf-8")
    assert main(["tui", "--connect", server.url, "--instructor", "--password-file", str(hashed)]) == 2
    assert "needs a file with the password itself" in capsys.readouterr().err
    monkeypatch.delenv("LIANSUO_INSTRUCTOR_PASSWORD", raising=False)
    assert main(["tui", "--connect", server.url, "--instructor"]) == 2
    assert "LIANSUO_INSTRUCTOR_PASSWORD" in capsys.readouterr().err
    with ClassroomClient.trainee(server.url, seat=1, name="Li"):
        assert main(["tui", "--connect", server.url, "--seat", "1", "--name", "Qian"]) == 2
        assert "seat 1 is taken" in capsys.readouterr().err


@run
async def test_the_login_screen_lists_the_seats_asks_again_after_a_refusal_then_connects(server: Server) -> None:
    from textual.widgets import Input, Static

    from liansuo.remote.link import Unlinked, lobby
    from liansuo.remote.login import LoginScreen

    with ClassroomClient.trainee(server.url, seat=2, name="Wang"):
        app = RemoteConsoleApp(Unlinked(server.url, lobby(server.url)))
        async with app.run_test(size=SIZE) as pilot:
            await pilot.pause()
            login = app.screen
            assert isinstance(login, LoginScreen)
            assert "1 free · 2 taken" in str(login.query_one("#seats", Static).content)
            assert band(app, "IG") == BAND_COLOUR["occupied"]  # the station drawn dark until logged in
            await pilot.press(*"Li", "tab", "2", "enter")  # name, seat 2: Wang's
            why = login.query_one("#why", Static)
            await until(pilot, lambda: "seat 2 is taken" in str(why.content))
            login.query_one("#seat", Input).value = ""
            await pilot.click("#seat")
            await pilot.press("1", "enter")
            await until(pilot, lambda: app.logged_in and app.remote.live and band(app, "IG") == BAND_COLOUR["free"])
            assert not isinstance(app.screen, LoginScreen) and app.seat == 1
            await type_line(pilot, "route X XI")
            assert "✓" in message(app), message(app)
            assert server.classroom.seat(1).trainee == "Li"


@run
async def test_a_trainee_reads_the_exercise_started_on_the_seat_and_its_score_at_the_end(server: Server) -> None:
    app = RemoteConsoleApp(ServerLink(server.url, {"role": "trainee", "seat": 1, "name": "Li"}))
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        with ClassroomClient.instructor(server.url, PASSWORD) as teacher:
            reply = teacher.request({"type": "exercise", "seats": [1], "name": "jiaopei-cancel-route", "seed": 1})
            assert reply["type"] == "ok", reply
        await until(pilot, lambda: "Cancel a wrong route" in str(app.status_bar.content))
        assert "0/2 goals" in str(app.status_bar.content) and "left" in str(app.status_bar.content)
        assert "dispatcher wants the train on the main track IG" in log(app)  # the briefing, in the event log
        await until(pilot, lambda: isinstance(app.screen, BriefingScreen))  # and in a dialog of its own
        text = str(app.screen.query_one("#briefing", Static).content)
        assert "dispatcher wants the train on the main track IG" in text and "· " in text, text
        await pilot.press("escape")
        await until(pilot, lambda: band(app, "3G") == BAND_COLOUR["locked"])  # the setup's route X-X3
        await type_line(pilot, "cancel X")
        await until(pilot, lambda: band(app, "3G") == BAND_COLOUR["free"])
        await type_line(pilot, "route X XI")
        await until(pilot, lambda: "goals met" in str(app.status_bar.content), 12)
        assert "score" in log(app) and "2/2 goals" in str(app.status_bar.content)
    assert [p.suffix for p in server.classroom.seat(1).desk.reported] == [".json", ".txt", ".html"]


def test_the_dashboard_row_says_how_far_an_exercise_is_and_how_it_ended() -> None:
    from liansuo.remote.dashboard import COLUMNS, seat_row

    base = {"seat": 1, "trainee": "Li", "connected": True, "station": "jiaopei", "t": 75.0, "paused": False,
            "speed": 1.0, "alarms": 0, "refused": 1, "exercise": "jiaopei-cancel-route"}
    going = dict(zip(COLUMNS, seat_row({**base, "score": 40.0, "progress": {
        "goals_met": 1, "goals": 2, "time_left_s": 252.0, "finished": False, "ended": ""}}), strict=True))
    assert going["progress"] == "1/2 goals, 00:04:12.0 left" and going["score"] == "40.0"
    done = dict(zip(COLUMNS, seat_row({**base, "score": 98.0, "progress": {
        "goals_met": 2, "goals": 2, "time_left_s": 200.0, "finished": True, "ended": "goals met"}}), strict=True))
    assert done["progress"] == "2/2 goals, ended: goals met" and "left" not in done["progress"]
    idle = dict(zip(COLUMNS, seat_row({**base, "exercise": None, "progress": None, "score": None}), strict=True))
    assert idle["exercise"] == idle["progress"] == idle["score"] == ""

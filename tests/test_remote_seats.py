"""The instructor's console moving between seats (issue 46): each seat's event log shows that seat's events only,
once; the exercise picker offers the served station's exercises; the instructor's panel starts an exercise through
the server. A real classroom server runs in a thread of the test (test_remote.Server); the consoles are driven with
Textual's Pilot."""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterator
from itertools import pairwise
from pathlib import Path

import pytest
from consoletest import SIZE, message, run
from test_remote import PASSWORD, Server, log, type_line, until
from textual.widgets import Button, Select

from liansuo.classroom.exercise import bundled_exercises, parse_exercise
from liansuo.remote.app import RemoteConsoleApp
from liansuo.remote.dashboard import DashboardScreen, ExercisePicker
from liansuo.remote.link import ServerLink
from liansuo.server.client import ClassroomClient


@pytest.fixture
def server(tmp_path: Path) -> Iterator[Server]:
    s = Server(reports=tmp_path / "reports")
    try:
        yield s
    finally:
        s.close()


def event_lines(app: RemoteConsoleApp) -> list[str]:
    """The log's lines that are the seat's events (those with a time), not the console's own notes."""
    return [line for line in app.log_panel.lines_text if line[:9].strip().replace(".", "").isdigit()]


async def open_seat(pilot: object, app: RemoteConsoleApp, seat: int) -> None:
    """From the diagram or the dashboard: F3, the seat's row, Enter."""
    if not isinstance(app.screen, DashboardScreen):
        await pilot.press("f3")  # type: ignore[attr-defined]
    dash = app.screen
    assert isinstance(dash, DashboardScreen)
    await until(pilot, lambda: len(dash._shown) == 2)
    dash.query_one("DataTable").move_cursor(row=seat - 1)  # type: ignore[attr-defined]
    await pilot.press("enter")  # type: ignore[attr-defined]
    await until(pilot, lambda: not isinstance(app.screen, DashboardScreen) and app.remote.seat == seat
                and app.remote.live)


@run
async def test_each_seats_log_shows_its_own_events_once(server: Server) -> None:
    app = RemoteConsoleApp(ServerLink(server.url, {"role": "instructor", "password": PASSWORD}))
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        dash = app.screen
        assert isinstance(dash, DashboardScreen)
        await until(pilot, lambda: len(dash._shown) == 2)
        await pilot.press("e")  # seat 1 is selected
        assert isinstance(app.screen, ExercisePicker)
        picker = app.screen
        await pilot.press(*["down"] * picker.names.index("jiaopei-cancel-route"), "enter")
        await until(pilot, lambda: server.classroom.seat(1).desk.assessment is not None)
        await open_seat(pilot, app, 1)
        await until(pilot, lambda: "X-X3" in log(app))  # the exercise's setup route, seat 1's
        await open_seat(pilot, app, 2)
        await type_line(pilot, "fault broken-rail IG")
        assert "✓" in message(app), message(app)
        await until(pilot, lambda: "broken" in "\n".join(event_lines(app)))  # seat 2's fault event
        assert "X-X3" not in log(app), log(app)  # seat 1's events are not in seat 2's log
        await open_seat(pilot, app, 1)
        await pilot.pause(1.0)  # snapshots come four times a second
        seat1 = log(app)
        assert "broken" not in seat1, seat1  # seat 2's fault is not in seat 1's log
        twice = [line for line, n in Counter(event_lines(app)).items() if n > 1]
        assert not twice, seat1
        assert "X-X3" in seat1 and seat1.count("lesson   Cancel a wrong route") == 1, seat1  # its own lines, back once
        await open_seat(pilot, app, 2)
        await pilot.pause(1.0)
        seat2 = log(app)
        assert "broken" in seat2 and "X-X3" not in seat2, seat2
        assert not [line for line, n in Counter(event_lines(app)).items() if n > 1], seat2


GAOTIE_EXERCISE = """title: Another station's
station: gaotie
briefing: not for this classroom
goals:
  - description: the route is open
    expect: [route X X3 open]
"""


@run
async def test_the_exercise_picker_offers_the_served_stations_exercises_only(server: Server, tmp_path: Path) -> None:
    own = tmp_path / "exercises"
    own.mkdir()
    (own / "gaotie-elsewhere.yaml").write_text(GAOTIE_EXERCISE, encoding="utf-8")
    (own / "my-cancel.yaml").write_text(Path(parse_exercise("jiaopei-cancel-route").file).read_text("utf-8"),
                                        encoding="utf-8")
    server.classroom.exercise_dirs = (own,)
    app = RemoteConsoleApp(ServerLink(server.url, {"role": "instructor", "password": PASSWORD}))
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        dash = app.screen
        assert isinstance(dash, DashboardScreen)
        await until(pilot, lambda: len(dash._shown) == 2)
        await pilot.press("e")
        picker = app.screen
        assert isinstance(picker, ExercisePicker)
        jiaopei = sorted(p.stem for p in bundled_exercises() if p.stem.startswith("jiaopei-"))
        assert picker.names == sorted([*jiaopei, "my-cancel"]), picker.names  # no gaotie exercise
        await pilot.press("escape")
        assert isinstance(app.screen, DashboardScreen)


@run
async def test_the_instructors_panel_starts_its_exercise_on_the_seat_through_the_server(server: Server) -> None:
    app = RemoteConsoleApp(ServerLink(server.url, {"role": "instructor", "password": PASSWORD}))
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await open_seat(pilot, app, 2)
        await pilot.press("f2")
        await until(pilot, lambda: app.instructor_panel is not None and app.instructor_panel.is_mounted)
        panel = app.instructor_panel
        assert panel is not None
        offered = [p.stem for p in panel.exercises]
        assert offered and all(n.startswith("jiaopei-") for n in offered), offered  # the served station's only
        panel.query_one("#ex-file", Select).value = "jiaopei-cancel-route"
        panel.query_one("#ex-load", Button).press()
        await until(pilot, lambda: isinstance(app.screen, ExercisePicker))
        # the local console's own handler (which loads an exercise into a local simulation) did not run after the
        # remote one: it would have said so on the answer line, over the picker
        assert "own computer" not in message(app), message(app)
        await pilot.press("enter")
        await until(pilot, lambda: server.classroom.seat(2).desk.assessment is not None)
        assert server.classroom.seat(1).desk.assessment is None


@run
async def test_the_local_consoles_panel_offers_its_stations_exercises_only() -> None:
    from liansuo.tui.app import ConsoleApp

    app = ConsoleApp("gaotie", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await app.set_instructor(True)
        assert app.instructor_panel is not None
        offered = [p.stem for p in app.instructor_panel.exercises]
        assert offered and all(n.startswith("gaotie-") for n in offered), offered


def times(app: RemoteConsoleApp) -> list[tuple[float, str]]:
    """The log's lines that carry a time, with it."""
    return [(float(line[:9]), line) for line in app.log_panel.lines_text if line[:9].strip().replace(".", "").isdigit()]


@run
async def test_a_seats_new_simulation_is_marked_where_its_times_go_back(server: Server) -> None:
    app = RemoteConsoleApp(ServerLink(server.url, {"role": "trainee", "seat": 1, "name": "Li"}))
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await until(pilot, lambda: app.remote.live)
        with ClassroomClient.instructor(server.url, PASSWORD) as teacher:
            await until(pilot, lambda: app.remote.t > 1.0)
            assert teacher.request({"type": "exercise", "seats": [1], "name": "jiaopei-cancel-route",
                                    "seed": 1})["type"] == "ok"
            await until(pilot, lambda: "route X-X3 locked" in log(app))  # the setup ran 8 s of the new clock
            await until(pilot, lambda: app.remote.t > 9.0)
            assert teacher.request({"type": "reset", "seats": [1]})["type"] == "ok"
            await until(pilot, lambda: "reset by the instructor" in log(app))
            assert teacher.request({"type": "exercise", "seats": [1], "name": "jiaopei-cancel-route",
                                    "seed": 1})["type"] == "ok"
            await until(pilot, lambda: log(app).count("route X-X3 locked") == 2)
        lines = times(app)
        marks = [line for _, line in lines if "its clock starts again at 0" in line]
        assert len(marks) == 3, log(app)  # the exercise, the reset, the exercise again
        assert "seat 1: exercise 'Cancel a wrong route (取消进路)' started" in marks[0], marks
        for (before, _), (t, line) in pairwise(lines):
            if t < before:  # a time going back is where a new simulation is marked, and only there
                assert "its clock starts again at 0" in line, log(app)

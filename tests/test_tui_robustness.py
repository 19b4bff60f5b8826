"""The console survives any input (issue 17, item 4): each reproducer of the issue, driven as a terminal drives it
(keys and mouse buttons posted to the app, several in one burst where a hasty user makes them), and what the user sees
afterwards: the screen, the alarm panel, the answer line, the exit status and stderr of `liansuo tui`."""

from __future__ import annotations

from collections.abc import Awaitable, Callable
from pathlib import Path
from typing import Any

import pytest
from consoletest import SIZE, message, run
from textual import events
from textual.app import App
from textual.command import CommandPalette
from textual.widgets import Static

from liansuo.cli.main import main
from liansuo.stations.loader import load
from liansuo.stations.schema import Name
from liansuo.stations.station import Station
from liansuo.tui import longrun
from liansuo.tui.app import ConsoleApp
from liansuo.tui.dialogs import ConfirmScreen, HelpScreen, PasswordScreen, QuitScreen
from liansuo.tui.grid import Ref
from liansuo.tui.operate import ConsoleOperator
from liansuo.tui.safeapp import ConsoleScreen


def burst_of_clicks(app: App[Any], x: int, y: int, times: int) -> None:
    """Mouse button down and up ``times`` over, all sent before the app handles the first (as a terminal delivers a
    quick double click); the app makes the clicks itself."""
    for _ in range(times):
        for kind in (events.MouseDown, events.MouseUp):
            app.post_message(kind(None, x, y, 0, 0, 1, False, False, False, screen_x=x, screen_y=y))


def alarm_texts(app: ConsoleApp) -> list[str]:
    return [a.text for a in app.alarm_panel.lines]


# ---- the command palette and quitting --------------------------------------------------------------------------------
@run
async def test_two_clicks_outside_the_command_palette_in_one_burst_close_it_once() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:  # before the fix: ScreenStackError "Can't pop screen" on leaving
        await pilot.press("ctrl+p")
        assert isinstance(app.screen, CommandPalette)
        burst_of_clicks(app, 2, SIZE[1] - 2, 2)
        await pilot.pause()
        assert isinstance(app.screen, ConsoleScreen) and app.is_running
        await pilot.press("question_mark")  # a dialog over the palette is not closed by the palette's late answer
        assert isinstance(app.screen, HelpScreen)
    assert not app.incidents


def burst_of_keys(app: App[Any], *keys: str) -> None:
    """Keys sent before the app handles the first, as a terminal delivers keys typed (or repeated) quickly."""
    for key in keys:
        app.post_message(events.Key(key, "\r" if key == "enter" else key))


@run
async def test_a_dialog_answered_twice_in_one_burst_is_answered_once() -> None:
    app = ConsoleApp("jiaopei", paused=True, instructor_password="pw")
    async with app.run_test(size=SIZE) as pilot:  # before: ScreenStackError, the second Enter closed the main screen
        await pilot.press("f2", "p", "w")
        assert isinstance(app.screen, PasswordScreen)
        burst_of_keys(app, "enter", "enter")
        await pilot.pause()
        assert isinstance(app.screen, ConsoleScreen) and app.is_running and app.instructor
        await pilot.press("question_mark")
        assert isinstance(app.screen, HelpScreen)
    assert not app.incidents


@run
async def test_quitting_always_asks_by_key_by_palette_and_by_command() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("ctrl+q")  # the key
        assert isinstance(app.screen, QuitScreen)
        await pilot.press("n")
        assert app.is_running and "stays open" in message(app)
        await pilot.press("ctrl+p", *"quit")  # the palette's Quit (before the fix it closed the console at once)
        await pilot.pause(0.3)
        await pilot.press("enter")
        await pilot.pause()
        assert isinstance(app.screen, QuitScreen), app.screen
        await pilot.press("escape")
        assert app.is_running
        await pilot.press("colon", *"quit", "enter")  # the command bar
        assert isinstance(app.screen, QuitScreen)
        await pilot.press("ctrl+q")  # asked once, not twice
        assert sum(isinstance(s, QuitScreen) for s in app.screen_stack) == 1
        await pilot.press("y")
        await pilot.pause()
    assert app.return_code == 0 and not app.incidents


@run
async def test_keys_typed_while_the_console_closes_are_let_go() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("ctrl+q")
        burst_of_keys(app, "y", "f2")  # before: MountError, F2 opened the instructor's panel in a closing console
        await pilot.pause()
    assert app.return_code == 0 and not app.incidents


@run
async def test_a_screenshot_due_after_the_console_closed_is_let_go(tmp_path: Path) -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("ctrl+q", "y")
    # the palette's Screenshot fires 0.1 s after it is chosen; quitting at once left it no screen (ScreenStackError)
    assert app.deliver_screenshot(path=str(tmp_path)) is None and list(tmp_path.iterdir()) == []


@run
async def test_shrinking_the_window_through_1x1_with_a_dialog_or_the_palette_open() -> None:
    for opener in ("P", "ctrl+p", "question_mark"):  # a confirmation, the command palette, help
        app = ConsoleApp("jiaopei", paused=True)
        async with app.run_test(size=SIZE) as pilot:  # before: ValueError: range() arg 3 must not be zero
            await pilot.press(opener)
            for size in [(10, 8), (10, 1), (4, 3), (1, 1), (6, 2), SIZE]:
                await pilot.resize_terminal(*size)
            assert not isinstance(app.screen, ConsoleScreen)  # the dialog is still open, and answers
            await pilot.press("escape")
            assert isinstance(app.screen, ConsoleScreen) and app.is_running
        assert not app.incidents, opener


# ---- unexpected errors -----------------------------------------------------------------------------------------------
@run
async def test_an_error_in_a_handler_is_shown_in_the_alarm_panel_and_the_console_carries_on(
        monkeypatch: pytest.MonkeyPatch) -> None:
    real = ConsoleOperator.press
    calls = {"n": 0}

    def press_failing_once(self: ConsoleOperator, ref: Ref) -> Any:
        calls["n"] += 1
        if calls["n"] == 1:
            raise ZeroDivisionError("injected for the test")
        return real(self, ref)

    monkeypatch.setattr(ConsoleOperator, "press", press_failing_once)
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()  # the diagram centres itself after its first refresh
        for ref in (Ref("button", "X", "train"), Ref("button", "X", "train"), Ref("button", "XI", "train")):
            await pilot.click("#diagram", offset=app.diagram.offset_of(ref))
        assert app.is_running
        [alarm] = [a for a in alarm_texts(app) if "console error" in a]
        assert "ZeroDivisionError: injected for the test" in alarm and "ConsoleApp.on_diagram_pressed" in alarm
        assert app.sim.route_state("X-XI") in ("setting", "locked", "open")  # the next clicks still worked
        assert "1 alarm" in str(app.status_bar.content) or "alarms" in str(app.status_bar.content)
        await pilot.press("a")  # acknowledged: it leaves the panel, and stays in the report
        assert not [a for a in alarm_texts(app) if "console error" in a]
    report = app.incidents.report("tui")
    assert "ZeroDivisionError: injected for the test" in report and "Traceback" in report
    assert report.splitlines()[-1].startswith("liansuo tui: the console had 1 internal error and carried on")


def headless(pilot_steps: Callable[[Any], Awaitable[None]] | None = None) -> Callable[..., Any]:
    """``App.run`` in a test: no terminal, and the steps of a user instead of the keyboard."""

    def run_headless(self: App[Any], *args: Any, **kwargs: Any) -> Any:
        return App.run(self, headless=True, size=SIZE, auto_pilot=pilot_steps)

    return run_headless


def test_after_a_crash_liansuo_tui_exits_1_with_the_traceback_on_stderr(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    def crash(self: ConsoleApp) -> None:
        raise RuntimeError("injected crash at start")

    monkeypatch.setattr(ConsoleApp, "started", crash)  # the app's own mount: the console cannot start
    monkeypatch.setattr(ConsoleApp, "run", headless())
    assert main(["tui", "jiaopei", "--paused"]) == 1  # before the fix: 0
    err = capsys.readouterr().err
    assert "RuntimeError: injected crash at start" in err and "Traceback" in err
    assert err.strip().splitlines()[-1].startswith("liansuo tui: the console stopped on an internal error")


def test_liansuo_tui_exits_1_after_a_session_with_an_internal_error_and_0_after_a_clean_one(
        monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    async def steps(pilot: Any) -> None:
        await pilot.press("colon", *"route X XI", "enter", "ctrl+q", "y")

    monkeypatch.setattr(ConsoleApp, "run", headless(steps))
    assert main(["tui", "jiaopei", "--paused"]) == 0
    assert capsys.readouterr().err == ""

    def failing_acknowledge(self: ConsoleApp) -> None:
        raise KeyError("injected")

    monkeypatch.setattr(ConsoleApp, "action_acknowledge", failing_acknowledge)

    async def acknowledging(pilot: Any) -> None:
        await pilot.press("a", "colon", *"route X XI", "enter")
        assert pilot.app.sim.route_state("X-XI") != "released"  # it carried on
        await pilot.press("ctrl+q", "y")

    monkeypatch.setattr(ConsoleApp, "run", headless(acknowledging))
    assert main(["tui", "jiaopei", "--paused"]) == 1
    err = capsys.readouterr().err
    assert "KeyError: 'injected'" in err and "Traceback" in err
    assert err.strip().splitlines()[-1].startswith("liansuo tui: the console had 1 internal error and carried on")


# ---- a long run ------------------------------------------------------------------------------------------------------
@run
async def test_run_1h_advances_in_slices_shows_its_progress_and_esc_stops_it(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(longrun, "RUN_SLICE_S", 0.0)  # one cycle a slice: the test does not depend on the machine
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        t0 = app.sim.t
        await pilot.press("colon", *"run 1h", "enter")  # before: the console froze until it was run
        assert t0 < app.sim.t < t0 + 3600
        assert "run 1h" in str(app.status_bar.content) and "Esc stops it" in message(app)
        await pilot.press(*"route X XI")  # the screen answers while the run goes on
        assert app.command_bar.value == "route X XI" and app.long_run is not None
        await pilot.press("enter")  # one thing at a time: the route waits for the run
        assert "wait: 'run 1h' is running" in message(app) and app.sim.route_state("X-XI") == "released"
        await pilot.press("escape")  # Esc stops it where it is
        assert app.long_run is None and t0 < app.sim.t < t0 + 3600
        assert "'run 1h' stopped at t =" in message(app)
        assert app.send("route X XI").ok


@run
async def test_a_run_finishes_on_the_clock_and_is_recorded_as_cycles_that_replay(tmp_path: Path) -> None:
    from liansuo.simulation.recording.file import load_recording
    from liansuo.simulation.recording.replayer import Replayer

    path = tmp_path / "run.jsonl"
    app = ConsoleApp("jiaopei", paused=True, record=path)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("colon", *"route X XI", "enter")
        t0 = app.sim.t
        await pilot.press("colon", *"run 45s", "enter")
        while app.long_run is not None:  # the clock's ticks, without waiting for them
            app.continue_run()
        assert app.sim.t == pytest.approx(t0 + 45) and message(app) == f"✓ t = {app.sim.t:g} s"
        assert app.sim.aspect("X") == "U"
        assert app.send("run 9999999h").ok is False  # refused by the command language itself, at once
        assert "a run must be from 0 to 3600 s" in message(app)
    assert Replayer(load_recording(path)).verify() == []


# ---- text from files -------------------------------------------------------------------------------------------------
@run
async def test_escape_sequences_and_markup_from_a_file_are_shown_as_written(tmp_path: Path) -> None:
    base = load("jiaopei")
    name = Name(zh="\x1b[2J\x1b]0;pwned\x07教培", en="[bold red]x[/] [/y]")
    station = Station(base.model.model_copy(update={"name": name}))
    from liansuo.simulation.sim import Simulation

    exercise = tmp_path / "markup.yaml"
    exercise.write_text("title: '[/x] a lesson'\nstation: jiaopei\ndescription: '[bold]d'\nsetup: []\n"
                        "goal:\n  description: '[/goal] \\x'\n  expect:\n    - section IG free\n", encoding="utf-8")
    app = ConsoleApp("jiaopei", paused=True, sim=Simulation(station))
    async with app.run_test(size=(160, 44)) as pilot:
        status = str(app.status_bar.content)
        assert "\\x1b[2J\\x1b]0;pwned\\x07教培" in status and "\x1b" not in status
        assert "[bold red]x[/] [/y]" in status  # shown as written, not as markup
        assert "\\x1b[2J" in message(app) and "\x1b" not in message(app)
        app.load_exercise(str(exercise))
        await pilot.pause()
        shown = str(app.screen.query_one("#briefing", Static).content)  # the briefing: markup shown as written
        assert "[/x] a lesson" in shown and "[bold]d" in shown and "[/goal] \\x" in shown, shown
        await pilot.press("escape")
        await pilot.press("f2")  # the instructor's panel shows the goal: '[/goal]' was a MarkupError before
        await pilot.pause()
        assert app.instructor_panel is not None
        assert "[/goal]" in str(app.instructor_panel.ex_goal.content)
        assert any("[/x] a lesson" in line for line in app.log_panel.lines_text)
        await pilot.press("P")
        assert isinstance(app.screen, ConfirmScreen)
        screen_text = app.export_screenshot()
        assert "\x1b]0;pwned" not in screen_text
    assert not app.incidents

"""What a trainee reads and does at the console (issue 46, items 2, 3, 5, 7 and 8): the exercise's briefing in a
dialog of its own, wrapped and reopened with ``e``; the diagram taking the lines it needs and the log the rest; the
footer offering only this operator's keys; the console's actions in the command palette; Tab completing a route from
the interlocking table; the arrows keeping to the track. Driven through Textual's Pilot at the sizes a class uses;
what is asserted is what is on the screen."""

from __future__ import annotations

from pathlib import Path

import pytest
from consoletest import footer, message, run, screen_lines
from textual.command import CommandPalette

from liansuo.classroom.answers import parse_answers
from liansuo.classroom.exercise import bundled_exercises, parse_exercise
from liansuo.tui.app import ConsoleApp
from liansuo.tui.briefing import BriefingScreen, reflow
from liansuo.tui.commands import console_commands
from liansuo.tui.grid import Ref

EXERCISE = "jiaopei-broken-rail-IG"
ANSWERS = Path(__file__).parent / "data" / "exercises" / f"{EXERCISE}.answers"
SIZES = [(120, 40), (160, 48), (200, 60)]


def shown(app: ConsoleApp) -> str:
    """The screen's words in reading order, each line's text joined to the next (a wrapped sentence reads whole)."""
    return " ".join(" ".join(line.replace("│", " ").split()) for line in screen_lines(app))


def every_word_shown(text: str, screen: str) -> list[str]:
    """The words of ``text`` (its paragraphs reflowed) not found on the screen in their order: [] when all are."""
    missing, at = [], 0
    for word in reflow(text).split():
        found = screen.find(word, at)
        if found < 0:
            missing.append(word)
        else:
            at = found + len(word)
    return missing


# ---- item 2: the briefing ------------------------------------------------------------------------------------------
@run
async def test_a_trainee_reads_the_whole_briefing_and_does_a_bundled_exercise_at_120x40() -> None:
    """jiaopei-broken-rail-IG with its model answers, typed into the command bar at their times: the briefing (with
    'receive the next down train on the siding 3G instead') and the goal are on the screen in full, every answer is
    read whole on the answer line, and the briefing reopened with 'e' ticks the goal met."""
    exercise = parse_exercise(Path(__file__).parents[1] / "src" / "liansuo" / "exercises" / f"{EXERCISE}.yaml")
    app = ConsoleApp("jiaopei", paused=True, exercise=EXERCISE)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        assert isinstance(app.screen, BriefingScreen)
        screen = shown(app)
        assert "receive the next down train on the siding 3G instead." in screen, screen
        assert every_word_shown(exercise.briefing, screen) == []
        assert every_word_shown(exercise.goals[0].description, screen) == []
        assert "e briefing" in footer(app)
        await pilot.press("escape")
        assert not isinstance(app.screen, BriefingScreen)
        start = app.sim.t
        for answer in parse_answers(ANSWERS):
            app.advance(max(0, round((start + answer.at - app.sim.t) / app.sim.cycle_s)))
            await pilot.press("colon", *[{" ": "space"}.get(c, c) for c in answer.line], "enter")
            said = message(app)
            assert said and said in " ".join(screen_lines(app)), said  # the answer line read whole, not cut
            assert not any("refused" in line for line in app.log_panel.lines_text), app.log_panel.lines_text
        status = screen_lines(app)[0]
        assert "A broken rail in IG: in progress" in status, status  # before why X waits, which may be cut
        app.advance(40)
        app.check_exercise()
        app.refresh_views()
        await pilot.pause()
        assert app.goal_reached_at is not None and "A broken rail in IG: goal reached" in screen_lines(app)[0]
        await pilot.press("escape", "e")  # from the command bar back to the diagram, then the briefing again
        assert isinstance(app.screen, BriefingScreen)
        screen = shown(app)
        assert every_word_shown(exercise.briefing, screen) == [] and "goal reached" in screen
        assert "✓ IG still shows occupied" in screen, screen
        await pilot.press("e")  # e closes it as well
        assert not isinstance(app.screen, BriefingScreen)
    assert not app.incidents


@pytest.mark.parametrize("path", bundled_exercises(), ids=lambda p: p.stem)
@run
async def test_every_bundled_exercises_briefing_and_goals_fit_a_120x40_window(path: Path) -> None:
    exercise = parse_exercise(path)
    app = ConsoleApp(exercise.station, paused=True, exercise=str(path))
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        assert isinstance(app.screen, BriefingScreen)
        screen = shown(app)
        assert every_word_shown(exercise.title, screen) == []
        assert every_word_shown(exercise.briefing, screen) == []
        for goal in exercise.goals:
            assert every_word_shown(goal.description, screen) == []


@run
async def test_without_an_exercise_there_is_no_briefing_key() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        assert "briefing" not in footer(app) and "? help" in footer(app)
        await pilot.press("e")
        assert not isinstance(app.screen, BriefingScreen)


# ---- item 3: the window's lines shared ------------------------------------------------------------------------------
@pytest.mark.parametrize("size", SIZES, ids=[f"{w}x{h}" for w, h in SIZES])
@run
async def test_the_diagram_takes_the_lines_it_needs_and_the_log_the_rest(size: tuple[int, int]) -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=size) as pilot:
        await pilot.pause()
        lines = screen_lines(app)
        border = next(i for i, line in enumerate(lines) if "报警 Alarms" in line)
        drawn = max(i for i, line in enumerate(lines[:border]) if line.strip() and i > 0)
        assert border - drawn <= 2, (border, drawn)  # no blank band between the drawing and the panels
        d = app.diagram
        assert d.layout_ is not None and d.layout_.height <= d.scrollable_content_region.height  # all of it shown
        column = app.query_one("#left").size.height
        log_lines = app.log_panel.size.height
        assert log_lines >= column // 3 - 1, (log_lines, column)  # the rest is the log's
        if size == (200, 60):
            assert d.layout_.lpr > 6  # the big window's rows spread out: the drawing fills what the log leaves
            assert log_lines >= 20, log_lines


# ---- item 5: each role's keys ---------------------------------------------------------------------------------------
@run
async def test_the_local_consoles_footer_offers_its_own_keys() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.pause()
        keys = footer(app)
        assert "space pause/run" in keys and "F2 instructor" in keys and "? help" in keys, keys
        assert "F3" not in keys  # the seats are a classroom's


# ---- item 7: the command palette ------------------------------------------------------------------------------------
async def palette(pilot: object, app: ConsoleApp, words: str) -> None:
    """ctrl+p, the words typed, the first hit chosen."""
    await pilot.press("ctrl+p", *[{" ": "space"}.get(c, c) for c in words])  # type: ignore[attr-defined]
    await pilot.pause(0.3)  # type: ignore[attr-defined]
    assert isinstance(app.screen, CommandPalette)
    await pilot.press("enter")  # type: ignore[attr-defined]
    await pilot.pause()  # type: ignore[attr-defined]


@run
async def test_the_palette_sets_and_cancels_a_route_zooms_and_shows_help() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=(120, 40)) as pilot:
        titles = [c.title for c in console_commands(app)]
        assert "route X XI" in titles and "shunt D1 D3" in titles and "总取消 cancel" in titles
        assert not any(t.startswith(("repair", "exercise")) for t in titles)  # the instructor's, not here yet
        await palette(pilot, app, "route X XI")
        app.advance(8)
        assert app.sim.route_state("X-XI") == "open"
        assert any(line.split()[1:] == ["trainee>", "route", "X", "XI"] for line in app.log_panel.lines_text)
        await palette(pilot, app, "cancel X")
        app.advance(8)
        assert app.sim.route_state("X-XI") == "released"
        zoom = app.diagram.layout_.zoom if app.diagram.layout_ else None
        await palette(pilot, app, "zoom out")
        assert app.diagram.layout_ is not None and app.diagram.layout_.zoom == (zoom or 0) - 1
        await palette(pilot, app, "总取消")
        assert app.operator.mode is not None and app.operator.mode.name == "cancel"  # armed, as the key c arms it
    assert not app.incidents


@run
async def test_the_instructors_palette_repairs_a_fault_and_loads_an_exercise() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.press("f2")  # no password: the instructor's panel
        assert app.instructor
        app.send("fault broken-rail IG", "instructor")
        assert "repair broken-rail IG" in [c.title for c in console_commands(app)]
        await palette(pilot, app, "repair broken-rail IG")
        assert not app.sim.field.faults
        await palette(pilot, app, f"exercise {EXERCISE}")
        assert app.exercise is not None and app.exercise.name == EXERCISE
        assert isinstance(app.screen, BriefingScreen)
    assert not app.incidents


# ---- item 8: completion from the table, arrows along the track ----------------------------------------------------
@run
async def test_tab_after_a_routes_start_offers_the_ends_the_table_has_from_there() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=(120, 40)) as pilot:
        await pilot.press("colon", *"route", "space", "X", "3", "space", "tab")
        assert app.command_bar.value == "route X3 S "  # X-X3's only train route: to S, not X3 itself or every signal
        app.command_bar.value = ""
        await pilot.press(*"route", "space", "X", "space", "tab")
        assert app.command_bar.value == "route X X" and message(app) == "X3  XI", message(app)  # X's ends


@pytest.mark.parametrize("size", SIZES, ids=[f"{w}x{h}" for w, h in SIZES])
@run
async def test_right_from_x3s_lamp_stays_on_its_track(size: tuple[int, int]) -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=size) as pilot:
        await pilot.pause()
        d = app.diagram
        d.cursor = Ref("signal", "X3")
        await pilot.press("right")
        assert d.cursor == Ref("turnout", "4") and message(app).startswith("道岔 turnout 4"), message(app)
        await pilot.press("right")
        assert d.cursor == Ref("section", "ASG"), d.cursor  # on along 3G's line
        # a route started at X3: only buttons; Right goes to one ahead, never almost straight up (XI's, 7 lines up)
        await pilot.press("escape")
        app.press(Ref("button", "X3", "train"))
        d.cursor = Ref("signal", "X3")
        centres = d.centres()
        await pilot.press("right")
        (x0, y0), (x, y) = centres[Ref("signal", "X3")], centres[d.cursor]
        assert d.cursor.kind == "button" and x - x0 >= 2 * abs(y - y0), (d.cursor, x - x0, y - y0)

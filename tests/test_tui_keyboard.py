"""The console behaves like a CBI display (the "classroom" issue, part A): keys after ':' reach the command bar however
fast they come, menus and questions stand beside their element over a diagram still drawn, the arrows go to the
nearest element and the answer line names it, help has the colour legend, a new alarm rings the bell (which can be
muted), and hints use the station's own ids. Driven through Textual's Pilot; what is asserted is what is on screen."""

from __future__ import annotations

from consoletest import SIZE, message, run, screen_lines
from textual import events
from textual.geometry import Region
from textual.widgets import Static

from liansuo.tui.app import ConsoleApp
from liansuo.tui.diagram import Diagram, nearest
from liansuo.tui.dialogs import ConfirmScreen, HelpScreen, MenuScreen, place
from liansuo.tui.grid import Ref
from liansuo.tui.paint import BAND_COLOUR


def burst_of_keys(app: ConsoleApp, keys: list[str]) -> None:
    """Keys sent before the app handles the first, as a terminal delivers keys typed quickly (Pilot.press waits for
    each key to be handled, so it would not show the race)."""
    for key in keys:
        char = {"colon": ":", "space": " "}.get(key, key)
        app.post_message(events.Key(key, char))


def outside(lines: list[str], area: Region, box: Region) -> list[str]:
    """The text of ``area`` with ``box`` blanked out, line by line."""
    out = []
    for y in range(area.y, area.bottom):
        line = lines[y].ljust(area.right)
        out.append("".join(" " if box.contains(x, y) else line[x] for x in range(area.x, area.right)))
    return out


# ---- 1. keys after ':' ----------------------------------------------------------------------------------------------
@run
async def test_keys_typed_after_colon_in_one_burst_all_reach_the_command_bar() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        burst_of_keys(app, ["colon", *["space" if c == " " else c for c in "route X XI"]])
        await pilot.pause()
        assert app.command_bar.value == "route X XI"  # before: '' and 单解 armed by the 'u'
        assert app.operator.mode is None and app.function_bar.armed is None
        await pilot.press("enter")
        app.advance(8)
        assert app.sim.route_state("X-XI") == "open"
        assert any(line.split()[1:] == ["trainee>", "route", "X", "XI"] for line in app.log_panel.lines_text)


@run
async def test_colon_is_typed_as_itself_in_a_dialogs_input() -> None:
    app = ConsoleApp("jiaopei", paused=True, instructor_password="a:b")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.press("f2", "a", "colon", "b", "enter")
        assert app.instructor


# ---- 2. menus and questions beside the element ---------------------------------------------------------------------
@run
async def test_an_element_menu_stands_beside_it_and_the_rest_of_the_diagram_stays_drawn() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=(80, 24)) as pilot:
        d = app.diagram
        await pilot.pause()  # the diagram centres itself after its first refresh
        at = d.offset_of(Ref("turnout", "5"))
        before = screen_lines(app)
        await pilot.click(Diagram, offset=at)
        await pilot.pause()
        await pilot.pause()
        assert isinstance(app.screen, MenuScreen)
        element = d.cursor_region()
        assert element is not None
        box = app.screen.query_one("Vertical").region
        assert not box.overlaps(element.grow((1, 3, 1, 3)))  # the turnout and the cells around it are not covered
        after = screen_lines(app)
        assert "turnout 5" in "\n".join(after)  # the menu is there
        # every cell of the diagram outside the menu is drawn as before: not blanked, not dimmed away
        assert outside(after, d.region, box) == outside(before, d.region, box)
        assert after[element.y][element.x] == before[element.y][element.x] == "━"  # the turnout's point, on its track


@run
async def test_a_confirmation_stands_beside_its_signal_and_the_diagram_stays_drawn() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=(80, 24)) as pilot:
        d = app.diagram
        await pilot.pause()  # the diagram centres itself after its first refresh
        at = d.offset_of(Ref("button", "X", "train"))
        before = screen_lines(app)
        await pilot.press("r")
        await pilot.click(Diagram, offset=at)
        await pilot.pause()
        await pilot.pause()
        assert isinstance(app.screen, ConfirmScreen)
        element = d.cursor_region()
        assert element is not None
        box = app.screen.query_one("Vertical").region
        assert not box.overlaps(element)
        after = screen_lines(app)
        assert "release X?" in "\n".join(after)
        assert outside(after, d.region, box) == outside(before, d.region, box)


def test_a_dialog_is_placed_below_else_above_the_element_and_inside_the_window() -> None:
    screen = Region(0, 0, 80, 24).size
    box = Region(0, 0, 44, 8).size
    below = place(box, Region(30, 5, 1, 1), screen)
    assert below.y == 5 + 1 + 1 and 0 <= below.x <= 80 - 44  # under the element, a line clear
    above = place(box, Region(30, 20, 1, 1), screen)
    assert above.y + 8 <= 20 - 1  # no room below: above it
    corner = place(box, Region(78, 22, 1, 1), screen)
    assert corner.x + 44 <= 80 and corner.y >= 0 and not Region(*corner, 44, 8).overlaps(Region(78, 22, 1, 1))


# ---- 3. arrows and the name of the element under the cursor --------------------------------------------------------
@run
async def test_each_arrow_goes_to_the_nearest_element_that_way() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE):
        centres = app.diagram.centres()
        x_train, xi_train = Ref("button", "X", "train"), Ref("button", "XI", "train")
        assert nearest(centres, x_train, (1, 0)) == Ref("signal", "X")
        assert nearest(centres, Ref("section", "IG"), (1, 0)) == xi_train
        assert nearest(centres, xi_train, (-1, 0)) == Ref("section", "IG")
        assert nearest(centres, xi_train, (1, 0)) == Ref("button", "XI", "shunt")
        assert nearest(centres, Ref("turnout", "5"), (-1, 0)) == Ref("turnout", "3")
        assert nearest(centres, Ref("turnout", "5"), (1, 0)) == Ref("signal", "S3")
        assert nearest(centres, Ref("turnout", "5"), (0, 1)) == Ref("section", "5DG")
        assert nearest(centres, Ref("section", "IG"), (0, 1)) == Ref("button", "S3", "train")


@run
async def test_route_x_xi_set_by_keys_in_a_handful_of_presses_with_each_element_named() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        keys = ["left"] * 5 + ["enter"] + ["right"] * 4 + ["enter"]  # before: about 35
        await pilot.press(*keys[:5])
        assert app.diagram.cursor == Ref("button", "X", "train")
        assert message(app) == "X 进站信号机 home signal 列车按钮 train button L"
        await pilot.press("enter", "right")
        # with a route started the cursor stops on buttons only
        assert app.diagram.cursor == Ref("button", "D3", "shunt")
        await pilot.press(*keys[7:10])
        assert message(app).startswith("XI 出站信号机 starting signal 列车按钮 train button L")
        await pilot.press("enter")
        assert len(keys) == 11
        app.advance(8)
        assert app.sim.route_state("X-XI") == "open"
        assert any(line.split()[1:] == ["trainee>", "route", "X", "XI"] for line in app.log_panel.lines_text)


@run
async def test_the_answer_line_names_a_turnout_and_a_section_under_the_cursor() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        app.diagram.cursor = Ref("turnout", "3")
        await pilot.press("right")
        assert app.diagram.cursor == Ref("turnout", "5")
        assert message(app) == "道岔 turnout 5 at normal (定位)"
        await pilot.press("down")
        assert message(app) == "区段 section 5DG: free"


# ---- 4. the colour legend -----------------------------------------------------------------------------------------
@run
async def test_help_lists_what_each_colour_means_in_that_colour() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=(100, 50)) as pilot:
        await pilot.press("question_mark")
        assert isinstance(app.screen, HelpScreen)
        shown = app.screen.query_one(Static).content
        text = str(shown)
        for words in ("颜色 Colours", "━━ free", "━━ locked in a route", "━━ occupied (红光带)", "5 normal 定位",
                      "5 reverse 反位", "5 no indication", "■ single lock", "× single block", "● H",
                      "○ commanded, dark", "▬ closed", "▭ open", "▬ bypassed", "new: red, blinking", "acknowledged"):
            assert words in text, words
        start = text.index("━━ occupied")
        assert any(s.start <= start < s.end and str(s.style).endswith(BAND_COLOUR["occupied"])
                   for s in shown.spans)  # type: ignore[union-attr]


# ---- 5. the bell -------------------------------------------------------------------------------------------------
@run
async def test_a_new_alarm_rings_the_bell_once_and_m_mutes_it() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        rung: list[int] = []
        app.bell = lambda: rung.append(1)  # type: ignore[method-assign]
        app.send("fault filament X lamp=H", "instructor")
        app.advance(8)
        for _ in range(5):  # redraws do not ring again
            app.refresh_views()
        assert len(rung) == 1
        await pilot.press("a")  # acknowledged: quiet, and no new ring
        app.refresh_views()
        assert len(rung) == 1
        await pilot.press("m")
        assert "bell muted" in str(app.status_bar.content)
        app.send("fault filament S lamp=H", "instructor")
        app.advance(8)
        app.refresh_views()
        assert len(rung) == 1 and len([a for a in app.alarm_lines() if not a.acknowledged]) == 2
        await pilot.press("colon", *"unmute", "enter")
        assert "bell muted" not in str(app.status_bar.content)
        app.send("fault filament S3 lamp=H", "instructor")
        app.advance(8)
        app.refresh_views()
        assert len(rung) == 2


@run
async def test_the_console_can_start_muted() -> None:
    app = ConsoleApp("jiaopei", paused=True, mute=True)
    async with app.run_test(size=SIZE) as pilot:
        rung: list[int] = []
        app.bell = lambda: rung.append(1)  # type: ignore[method-assign]
        assert "bell muted" in str(app.status_bar.content)
        app.send("fault filament X lamp=H", "instructor")
        app.advance(8)
        app.refresh_views()
        assert rung == [] and app.alarm_lines()
        await pilot.press("m")
        assert "bell muted" not in str(app.status_bar.content)


# ---- 6. hints in the station's own ids --------------------------------------------------------------------------
@run
async def test_hints_and_help_give_an_example_in_the_stations_own_ids() -> None:
    app = ConsoleApp("depot", paused=True)  # no signal X, no train routes
    async with app.run_test(size=(100, 50)) as pilot:
        assert "X" not in app.sim.station.signals
        assert app.command_bar.placeholder.endswith("e.g. shunt D1 D5")
        await pilot.press("question_mark")
        help_text = str(app.screen.query_one(Static).content)
        assert "e.g. shunt D1 D5" in help_text and "route X XI" not in help_text
        await pilot.press("escape", "colon", *"shunt D1 D5", "enter")
        assert any(line.split()[1:] == ["trainee>", "shunt", "D1", "D5"] for line in app.log_panel.lines_text)
        app.advance(8)
        assert app.sim.route_state("D1-D5") == "open"  # the example is a route the station has

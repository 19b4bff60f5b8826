"""The operator console, driven as a user drives it: clicks on the diagram and the function buttons, keys, the
command bar and the instructor's panel (Textual's Pilot). The clock is paused; time moves by single steps."""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

import pytest
from consoletest import SIZE, message, run

from liansuo.tui.app import ConsoleApp
from liansuo.tui.briefing import BriefingScreen
from liansuo.tui.diagram import Diagram
from liansuo.tui.dialogs import ConfirmScreen, MenuScreen, PasswordScreen
from liansuo.tui.grid import Ref
from liansuo.tui.paint import BAND_COLOUR, LAMP_COLOUR, glyph
from liansuo.tui.panels import FunctionBar

EXERCISES = Path(__file__).resolve().parent.parent / "src" / "liansuo" / "exercises"
async def click(pilot: Any, ref: Ref) -> None:
    await pilot.pause()  # the diagram centres itself after its first refresh (when the station is wider than it)
    diagram = pilot.app.diagram
    await pilot.click(Diagram, offset=diagram.offset_of(ref))
    await pilot.pause()


async def function(pilot: Any, mode: str) -> None:
    bar = pilot.app.function_bar
    await pilot.click(FunctionBar, offset=bar.offset_of(mode))
    await pilot.pause()


def cycles(app: ConsoleApp, n: int) -> None:
    app.advance(n)
    app.refresh_views()


def cell(app: ConsoleApp, ref: Ref) -> tuple[str, str]:
    """The character and colour the diagram shows for an element's first cell now."""
    d = app.diagram
    d.update_view()
    assert d.layout_ is not None
    x, y = d.layout_.targets[ref]
    g = d.layout_.at(x, y)
    assert g is not None
    ch, style = glyph(d.frame(), g, app.operator.pressed())
    return ch, str(style.color.name if style.color else "")


def lamp(app: ConsoleApp, signal: str) -> tuple[str, str]:
    """The lamp next to the signal's joint (slot 0)."""
    d = app.diagram
    d.update_view()
    assert d.layout_ is not None
    for x, y in d.layout_.lamp_slots[signal]:
        g = d.layout_.at(x, y)
        if g is not None and g.slot == 0:
            ch, style = glyph(d.frame(), g, set())
            return ch, str(style.color.name if style.color else "")
    raise AssertionError(f"no lamp slot 0 for {signal}")


def turnout_label(app: ConsoleApp, turnout: str, role: str = "tlabel") -> tuple[str, str]:
    d = app.diagram
    d.update_view()
    assert d.layout_ is not None
    for row in d.layout_.grid:
        for g in row:
            if g is not None and g.role == role and g.ref == Ref("turnout", turnout):
                ch, style = glyph(d.frame(), g, set())
                return ch, str(style.color.name if style.color else "")
    raise AssertionError(f"no {role} for turnout {turnout}")


def band_colour(app: ConsoleApp, section: str) -> str:
    d = app.diagram
    d.update_view()
    assert d.layout_ is not None
    x, y = d.layout_.section_cells[section][len(d.layout_.section_cells[section]) // 2]
    g = d.layout_.at(x, y)
    assert g is not None
    _ch, style = glyph(d.frame(), g, set())
    return str(style.color.name if style.color else "")


@run
async def test_a_route_set_by_clicks_opens_and_shows_white_then_cancels_by_function_button() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        await click(pilot, Ref("button", "X", "train"))
        assert app.operator.start == ("X", "train")
        assert "press the end button" in message(app)
        await click(pilot, Ref("button", "XI", "train"))
        cycles(app, 8)
        assert app.sim.route_state("X-XI") == "open"
        assert band_colour(app, "IG") == BAND_COLOUR["locked"]
        assert lamp(app, "X") == ("●", LAMP_COLOUR["yellow"])
        assert any(line.split()[1:] == ["trainee>", "route", "X", "XI"] for line in app.log_panel.lines_text)
        await function(pilot, "cancel")
        assert app.function_bar.armed == "cancel"
        await click(pilot, Ref("button", "X", "train"))
        cycles(app, 2)
        assert app.sim.route_state("X-XI") == "released"
        assert band_colour(app, "IG") == BAND_COLOUR["free"]
        assert "cancelled" in message(app)


@run
async def test_a_refused_route_shows_its_reason_on_the_answer_line() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        app.send("route X XI")
        await click(pilot, Ref("button", "S", "train"))
        await click(pilot, Ref("button", "SI", "train"))
        text = message(app)
        assert text.startswith("✗") and "conflicting route X-XI" in text
        assert any(line.split()[1] == "refused" for line in app.log_panel.lines_text)
        # and from the command bar, with the ':' key
        await pilot.press("colon", *"route S SI", "enter")
        assert "conflicting route X-XI" in message(app)


@run
async def test_manual_release_asks_for_confirmation_and_counts_down_on_the_signal() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        app.send("route X XI")
        cycles(app, 8)
        app.send("occupy IAG", "instructor")  # a train approaching: approach locking
        cycles(app, 2)
        await pilot.press("r")  # the 总人解 key arms the function
        await click(pilot, Ref("signal", "X"))
        assert isinstance(app.screen, ConfirmScreen)
        await pilot.press("y")
        await pilot.pause()
        assert app.sim.route_state("X-XI") == "time_release"
        d = app.diagram
        d.update_view()
        shown = "".join(ch for ch, _ in d.frame().overlay.values())
        assert "180s" in shown
        # section fault release refused on a station track: the reason comes back
        await function(pilot, "fault-release")
        await click(pilot, Ref("section", "IG"))
        await pilot.press("y")
        await pilot.pause()
        assert "station track" in message(app)


@run
async def test_turnout_menu_single_lock_shows_the_red_mark_and_individual_operation_moves_it() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        await click(pilot, Ref("turnout", "5"))
        assert isinstance(app.screen, MenuScreen)
        await pilot.click("#m-lock")
        await pilot.pause()
        assert app.sim.turnout_mark("5") == "locked"
        assert turnout_label(app, "5", "tmark") == ("■", "#ff2020")
        await pilot.press("v")  # 总反位
        await click(pilot, Ref("turnout", "5"))
        assert "single-locked" in message(app)
        await pilot.press("u")  # 单解
        await click(pilot, Ref("turnout", "5"))
        await pilot.press("v")
        await click(pilot, Ref("turnout", "5"))
        cycles(app, 40)
        assert app.sim.turnout_state("5") == ("reverse", False)
        assert turnout_label(app, "5") == ("5", "#ffd700")


@run
async def test_keyboard_only_cursor_enter_and_command_bar_completion() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        d = app.diagram
        await pilot.press("down")  # the cursor appears on an element
        assert d.cursor is not None
        d.cursor = Ref("button", "S", "train")
        await pilot.press("enter")
        d.cursor = Ref("button", "SI", "train")
        await pilot.press("enter")
        cycles(app, 8)
        assert app.sim.route_state("S-SI") == "open"
        await pilot.press("colon", "c", "a", "n", "tab", "S", "tab")
        assert app.query_one("#command").value == "cancel S"  # type: ignore[attr-defined]
        await pilot.press("enter")
        assert app.sim.route_state("S-SI") == "released"
        await pilot.press("up")
        assert app.query_one("#command").value == "cancel S"  # type: ignore[attr-defined]


@run
async def test_instructor_injects_a_broken_rail_from_the_panel_and_the_section_turns_red() -> None:
    app = ConsoleApp("jiaopei", paused=True, instructor_password="pw")
    async with app.run_test(size=(140, 44)) as pilot:
        await pilot.press("f2")
        assert isinstance(app.screen, PasswordScreen)
        await pilot.press("x", "enter")
        await pilot.pause()
        assert not app.instructor and "wrong" in message(app)
        await pilot.press("f2", "p", "w", "enter")
        await pilot.pause()
        assert app.instructor
        await pilot.click("#fault-pick")
        await click(pilot, Ref("section", "IG"))
        assert "IG" in message(app)
        await pilot.click("#fault-inject")
        await pilot.pause()
        cycles(app, 1)
        assert app.sim.section_state("IG") == "occupied"
        assert band_colour(app, "IG") == BAND_COLOUR["occupied"]
        assert any(line.split()[1:] == ["instr.>", "fault", "broken-rail", "IG"] for line in app.log_panel.lines_text)
        await pilot.click("#fault-repair")
        await pilot.pause()
        cycles(app, 1)
        assert app.sim.section_state("IG") == "free"


@run
async def test_every_fault_kind_is_offered_and_injects_from_the_panel() -> None:
    from liansuo.circuits.faults import KINDS
    from liansuo.tui.completion import fault_targets
    from liansuo.tui.instructor import InstructorPanel, fault_line

    app = ConsoleApp("gaotie", paused=True)
    async with app.run_test(size=(140, 44)) as pilot:
        await pilot.press("f2")
        panel = app.query_one(InstructorPanel)
        offered = [v for _, v in panel.query_one("#fault-kind")._options]  # type: ignore[attr-defined]
        assert set(offered) == set(KINDS)
        for kind in KINDS:
            targets = fault_targets(app.sim, kind)
            if kind == "axle-miscount":  # gaotie has track circuits only: no target is offered
                assert targets == []
                continue
            target = targets[0]
            r = app.send(fault_line(app.sim, kind, target), "instructor")
            assert r.ok and (kind, target) in app.sim.field.faults, r.message
            assert app.send(f"repair {kind} {target}", "instructor").ok


@run
async def test_lost_indication_flashes_the_turnout_red_and_guide_asks_for_confirmation() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        app.send("fault no-indication 5", "instructor")
        cycles(app, 1)
        colours = set()
        for _ in range(4):
            cycles(app, 1)
            colours.add(turnout_label(app, "5")[1])
        assert "#ff2020" in colours or "#ffffff" in colours
        await pilot.press("g")
        await click(pilot, Ref("button", "X", "train"))
        assert "引导进路 guide route from X" in message(app)  # no route set: the guide route, by its end button
        await click(pilot, Ref("button", "XI", "train"))
        assert isinstance(app.screen, ConfirmScreen)
        await pilot.press("n")
        await pilot.pause()
        assert "not sent" in message(app)


@run
async def test_a_guide_route_over_a_red_band_is_set_by_its_buttons() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        app.send("occupy IG", "instructor")
        cycles(app, 1)
        await pilot.press("g")
        await click(pilot, Ref("button", "X", "train"))
        await click(pilot, Ref("button", "XI", "train"))
        assert isinstance(app.screen, ConfirmScreen)
        await pilot.press("y")
        await pilot.pause()
        cycles(app, 60)
        assert app.sim.aspect("X") == "HB" and app.sim.sealed_uses().get("guide") == 1


@run
async def test_an_exercise_loads_its_faults_and_notices_the_goal() -> None:
    app = ConsoleApp("jiaopei", paused=True, exercise=EXERCISES / "jiaopei-turnout-5-no-indication.yaml")
    async with app.run_test(size=SIZE) as pilot:
        assert app.exercise is not None and ("no-indication", "5") in app.sim.field.faults
        assert app.goal is not None and not app.goal.reached
        await pilot.pause()
        assert isinstance(app.screen, BriefingScreen)  # the briefing first: the trainee closes it to operate
        await pilot.press("escape")
        await pilot.press("l")
        await click(pilot, Ref("turnout", "5"))
        await click(pilot, Ref("button", "X", "train"))
        await click(pilot, Ref("button", "XI", "train"))
        cycles(app, 8)
        app.check_exercise()
        assert app.goal.reached and app.goal_reached_at is not None
        assert "goal reached" in message(app)


@run
async def test_trains_are_drawn_over_their_sections_when_the_train_commands_exist() -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE):
        r = app.send("train T7 at IAG", "instructor")
        if not r.ok:
            assert message(app).startswith("✗")  # the refusal text is shown
            pytest.skip(f"no trains yet: {r.message}")
        cycles(app, 1)
        d = app.diagram
        d.update_view()
        shown = "".join(ch for ch, _ in d.frame().overlay.values())
        assert "T7" in shown


@run
async def test_no_traceback_on_odd_input() -> None:
    app = ConsoleApp("gaotie", paused=True)
    async with app.run_test(size=(80, 24)) as pilot:
        for line in ["", "route", "route X", "fault", "fault nope IG", "'unclosed", "run -5s", "run 9999999h",
                     "expect", "throw 1 sideways", "guide-lock Q", "doors P3 open", "train", "drive", "seek 5"]:
            app.send(line)
        await pilot.press("colon", *"route X", "tab", "tab", "enter", "escape")
        await pilot.press("left", "right", "up", "down", "enter", "escape", "plus", "minus", "0", "shift+left",
                          "full_stop", "greater_than_sign", "less_than_sign", "a", "c", "c", "space", "space")
        await pilot.press("question_mark")
        await pilot.press("escape")
        await pilot.click(Diagram, offset=(1, 1))
        await pilot.click(Diagram, offset=(40, 10))
        await pilot.pause()
        assert app.is_running


@run
async def test_recording_and_replay_reproduce_the_session(tmp_path: Path) -> None:
    path = tmp_path / "session.jsonl"
    app = ConsoleApp("jiaopei", paused=True, record=path)
    async with app.run_test(size=SIZE) as pilot:
        await click(pilot, Ref("button", "X", "train"))
        await click(pilot, Ref("button", "XI", "train"))
        cycles(app, 20)
        app.send("fault broken-rail IG", "instructor")
        cycles(app, 20)
        app.send("route S SI")
        live = (app.sim.t, app.sim.route_state("X-XI"), app.sim.section_state("IG"), app.sim.aspect("X"))
    records = [json.loads(line) for line in path.read_text().splitlines()]
    assert records[0]["format"] == "liansuo-recording" and records[-1]["k"] == "end"
    assert [(r["line"], r["by"]) for r in records if r["k"] == "cmd"] == [
        ("route X XI", "trainee"), ("fault broken-rail IG", "instructor"), ("route S SI", "trainee")]

    from liansuo.simulation.recording.recorder import load_recording
    from liansuo.tui.replay import ReplayApp

    rec = load_recording(path)
    replay = ReplayApp(rec, paused=True)
    async with replay.run_test(size=SIZE) as pilot:
        await pilot.press("end")
        await pilot.pause()
        sim = replay.sim
        assert (sim.t, sim.route_state("X-XI"), sim.section_state("IG"), sim.aspect("X")) == live
        assert replay.replayer.mismatches == []
        await pilot.press("home")
        await pilot.pause()
        assert replay.sim.t == 0 and replay.sim.route_state("X-XI") == "released"
        await pilot.press("right_square_bracket")
        await pilot.pause()
        assert replay.sim.t == pytest.approx(min(10.0, rec.duration))
        await click(pilot, Ref("button", "S", "train"))
        assert "replay" in message(replay)


def test_variant_buttons_become_the_via_of_the_route() -> None:
    from liansuo.simulation import Simulation
    from liansuo.tui.operate import ConsoleOperator

    sim = Simulation("gaotie")
    op = ConsoleOperator(sim)
    assert op.press(Ref("button", "X", "train")).command == ""
    assert "via BA1" in op.press(Ref("button", "BA1", "variant")).message
    out = op.press(Ref("button", "XI", "train"))
    assert out.command == "route X BA1 XI"
    assert sim.command(out.command).ok
    assert op.press(Ref("button", "XFCK", "exit")).message.startswith("XFCK is an end button")


@run
async def test_after_a_restart_the_sealed_power_up_release_button_asks_counts_and_puts_the_station_in_service(
) -> None:
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        app.send("restart", "instructor")  # the interlocking's restart is the instructor's (the maintainer's)
        cycles(app, 2)
        assert app.sim.section_state("7DG") == "locked" and app.sim.section_state("IG") == "locked"
        await click(pilot, Ref("button", "X", "train"))
        await click(pilot, Ref("button", "XI", "train"))
        assert "上电锁闭" in message(app)  # the route is refused while the station is power-up locked
        app.send("occupy 3G", "instructor")
        await function(pilot, "power-up")  # the sealed button acts on the whole station: it asks at once
        assert isinstance(app.screen, ConfirmScreen) and "used 0 times" in app.screen.question
        await pilot.press("y")
        await pilot.pause()
        assert "3G" in message(app) and app.sim.section_state("7DG") == "locked"  # refused: a section occupied
        app.send("vacate 3G", "instructor")
        cycles(app, 2)
        await pilot.press("P")  # its key, a second press: the refused use was not counted
        assert isinstance(app.screen, ConfirmScreen) and "used 0 times" in app.screen.question
        await pilot.press("y")
        await pilot.pause()
        assert app.sim.section_state("7DG") == "free" and "in service" in message(app)
        assert app.sim.sealed_uses() == {"power-up-release": 1}
        bar = str(app.function_bar.render())
        assert "上电解锁 1" in bar or "上电 1" in bar  # the counter beside the button
        await click(pilot, Ref("button", "X", "train"))
        await click(pilot, Ref("button", "XI", "train"))
        cycles(app, 40)
        assert app.sim.aspect("X") == "U"


@run
async def test_the_trainees_command_bar_refuses_the_instructors_commands_and_hides_their_faults() -> None:
    app = ConsoleApp("jiaopei", paused=True, exercise="jiaopei-broken-rail-IG")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        await pilot.press("escape")  # the briefing
        assert app.sim.section_state("IG") == "occupied"  # the exercise's broken rail is in
        for line in ("faults", "repair broken-rail IG", "fault filament X", "train T1 at IAG", "occupy 3G"):
            await pilot.press("colon", *line, "enter")
            assert "belongs to the instructor" in message(app) and "F2" in message(app), line
        assert app.sim.section_state("IG") == "occupied" and app.sim.section_state("3G") == "free"
        cycles(app, 4)
        log = "\n".join(app.log_panel.lines_text)
        assert "fault injected" not in log and "fault broken-rail" not in log, log  # the set-up lines stay hidden
        await pilot.press("f2")  # no password set: the instructor's panel opens, and their commands go through
        await pilot.press("colon", *"faults", "enter")
        assert "broken-rail" in message(app)


@run
async def test_an_exercise_with_several_goals_keeps_each_goal_once_met_and_shows_its_briefing() -> None:
    """jiaopei-64d-departure: X3 shows green (goal 1), then the train leaves and X3 is red again while the line shows
    departed (goal 2): the console ticks goal 1 for good and reaches the exercise's goal with both."""
    app = ConsoleApp("jiaopei", paused=True, exercise="jiaopei-64d-departure")
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        assert app.exercise is not None and len(app.exercise.goals) == 2
        log = "\n".join(app.log_panel.lines_text)
        assert "The down freight train T2 is ready on the siding 3G" in log and "(seed " in log
        assert app.send("route X3 S").ok and app.send("block-line SL request").ok
        cycles(app, 40)
        app.check_exercise()
        assert app.goal is not None and app.goal.met == [True, False] and app.goal_reached_at is None
        for _ in range(30):
            cycles(app, 8)
            app.check_exercise()
        assert app.sim.aspect("X3") == "H"  # the train has gone: goal 1's green is long over
        assert app.goal.met == [True, True] and app.goal_reached_at is not None
        assert "goal reached" in message(app)


def branch_colours(app: ConsoleApp, track: str) -> set[str]:
    """The colours the diagram draws a track's band and diagonal cells in now (the turnout's leg cell left out)."""
    d = app.diagram
    d.update_view()
    assert d.layout_ is not None
    frame = d.frame()
    out = set()
    for x, y in d.layout_.track_cells[track][2]:
        g = d.layout_.at(x, y)
        if g is not None and g.role in ("band", "diag") and g.track == track and g.leg is None:
            out.add(str(glyph(frame, g, set())[1].color.name))  # type: ignore[union-attr]
    return out


@run
async def test_a_locked_turnout_section_lights_only_the_branch_its_route_runs_over() -> None:
    """Issue 46, item 9: a 6502 panel and a CBI display light a locked turnout section white along the route's
    branch only; the branch the turnout does not lie on stays dark. Occupied, the whole section is red, as its track
    relay shows it."""
    app = ConsoleApp("jiaopei", paused=True)
    async with app.run_test(size=SIZE) as pilot:
        await pilot.pause()
        white, free, red = BAND_COLOUR["locked"], BAND_COLOUR["free"], BAND_COLOUR["occupied"]
        assert app.sim.command("route X XI").ok
        cycles(app, 40)
        assert app.sim.section_state("1DG") == "locked"
        assert branch_colours(app, "t-1a") == branch_colours(app, "t-1b") == {white}
        assert branch_colours(app, "t-1c") == {free}  # 1 lies normal: its reverse branch is not the route's
        assert app.sim.command("cancel X").ok
        cycles(app, 40)
        assert app.sim.command("route X X3").ok
        cycles(app, 80)
        assert app.sim.section_state("1DG") == "locked"
        assert branch_colours(app, "t-1c") == {white} and branch_colours(app, "t-1b") == {free}
        assert app.sim.command("occupy 1DG").ok
        cycles(app, 4)
        assert branch_colours(app, "t-1b") == branch_colours(app, "t-1c") == {red}

"""Console fidelity (the classroom issue, part B): platforms at every size, why a red signal waits, the 64D block
panel, train numbers at the head of the train, the sealed buttons' counters. Driven through the pilot or the public
API, asserting what the operator sees."""

from __future__ import annotations

import asyncio
from typing import Any

import pytest

from liansuo.simulation.sim import Simulation
from liansuo.tui.app import ConsoleApp
from liansuo.tui.diagram import Diagram
from liansuo.tui.dialogs import ConfirmScreen
from liansuo.tui.grid import Layout, Ref
from liansuo.tui.layout import MIN_DOORS
from liansuo.tui.paint import LAMP_COLOUR, glyph, head_cell
from liansuo.tui.panels import FunctionBar

SIZE = (120, 36)


async def click(pilot: Any, ref: Ref) -> None:
    await pilot.pause()  # the diagram centres itself after its first refresh
    await pilot.click(Diagram, offset=pilot.app.diagram.offset_of(ref))
    await pilot.pause()


def cycles(app: ConsoleApp, n: int) -> None:
    app.advance(n)
    app.refresh_views()


def layout(app: ConsoleApp) -> Layout:
    lay = app.diagram.layout_
    assert lay is not None
    return lay


# ---- 1. platforms and screen doors at every size ----------------------------------------------------------------
@pytest.mark.parametrize("size", [(80, 24), (100, 30), (120, 36), (140, 40), (160, 48), (200, 60)])
def test_gaotie_platforms_and_their_doors_are_drawn_at_every_window_size(size: tuple[int, int]) -> None:
    async def body() -> None:
        app = ConsoleApp("gaotie", paused=True)
        async with app.run_test(size=size):
            lay = layout(app)
            for platform in ("P3", "P4"):
                cells = [g for row in lay.grid for g in row if g is not None and g.ref is not None
                         and g.ref.kind == "platform" and g.ref.id == platform]
                assert "".join(g.ch for g in cells if g.role == "plabel") == platform, size
                assert sum(g.role == "door" for g in cells) >= MIN_DOORS, size
                side = "right" if platform == "P3" else "left"
                assert Ref("platform", platform, f"{platform}:{side}") in lay.targets  # clickable

    asyncio.run(body())


# ---- 2. a red signal over a locked route says why ----------------------------------------------------------------
def test_a_departure_onto_a_64d_line_waits_for_the_block_and_the_view_says_so() -> None:
    sim = Simulation("jiaopei")
    assert sim.view.waiting("XI") == ""  # no route: nothing to wait for
    assert sim.command("route XI S")
    sim.run(2)
    assert sim.view.route_state("XI-S") == "locked" and sim.aspect("XI") == "H"
    why = sim.view.waiting("XI")
    assert "block line SL" in why and "64D" in why
    assert sim.command("block-line SL request")
    sim.run(10)  # the virtual neighbour accepts: the signal opens, nothing to wait for
    assert sim.aspect("XI") == "L" and sim.view.waiting("XI") == ""


def test_the_status_and_answer_lines_say_why_the_signal_just_set_stays_red() -> None:
    async def body() -> None:
        app = ConsoleApp("jiaopei", paused=True)
        async with app.run_test(size=SIZE) as pilot:
            await click(pilot, Ref("button", "XI", "train"))
            await click(pilot, Ref("button", "S", "train"))
            cycles(app, 4)
            assert "XI red: block line SL has not been accepted" in str(app.status_bar.content)
            assert "XI red: block line SL" in str(app.message_line.content)
            assert app.sim.command("cancel XI").ok  # not through the console: as a classroom's seat changes
            cycles(app, 4)
            assert "XI red" not in str(app.status_bar.content)
            assert str(app.message_line.content) == ""  # the reason it said is out of date, so it is gone

    asyncio.run(body())


def test_on_gaotie_a_home_signal_says_the_screen_doors_keep_it_red_and_the_cursor_picks_the_signal() -> None:
    async def body() -> None:
        app = ConsoleApp("gaotie", paused=True)
        async with app.run_test(size=(160, 48)) as pilot:
            app.send("fault psd-stuck P3", "instructor")
            app.send("fault psd-stuck P4", "instructor")
            app.send("route X X3")
            app.send("route S S4")
            cycles(app, 60)
            assert app.sim.aspect("X") == "H" and app.sim.aspect("S") == "H"
            status = str(app.status_bar.content)  # the route set last: S's
            assert "S red: screen doors P4:left are not closed and locked" in status
            await click(pilot, Ref("signal", "X"))  # the cursor on X (its menu opens): X's reason
            await pilot.press("escape")
            app.refresh_views()
            assert "X red: screen doors P3:right are not closed and locked" in str(app.status_bar.content)

    asyncio.run(body())


# ---- 3. the 64D block panel ---------------------------------------------------------------------------------------
def lamps(app: ConsoleApp, link: str) -> list[tuple[str, str | None]]:
    """The departure and arrival lamps of a block line as shown: (character, colour)."""
    lay, frame = layout(app), app.diagram.frame()
    cells = sorted((g.slot, g) for row in lay.grid for g in row
                   if g is not None and g.role == "blamp" and g.ref == Ref("line", link))
    out = []
    for _, g in cells:
        ch, style = glyph(frame, g, set())
        out.append((ch, style.color.name if style.color is not None and ch == "●" else None))
    return out


def test_the_64d_block_buttons_send_the_block_commands_and_the_lamps_follow_the_line() -> None:
    async def body() -> None:
        app = ConsoleApp("jiaopei", paused=True)
        async with app.run_test(size=SIZE) as pilot:
            assert lamps(app, "SL") == [("○", None), ("○", None)]
            await click(pilot, Ref("block", "SL", "BSA"))
            assert app.sim.view.block_line("SL") == "requested"
            assert "block line SL: requested" in str(app.message_line.content)  # the command's answer
            assert lamps(app, "SL")[0] == ("●", LAMP_COLOUR["yellow"])  # our departure lamp: asked for
            cycles(app, 40)  # the virtual neighbour accepts
            assert app.sim.view.block_line("SL") == "permitted"
            assert lamps(app, "SL")[0] == ("●", LAMP_COLOUR["green"])
            await click(pilot, Ref("block", "SL", "FUA"))  # restore before a departure: cancel
            assert app.sim.view.block_line("SL") == "idle" and lamps(app, "SL")[0] == ("○", None)
            await click(pilot, Ref("block", "SL", "SGA"))  # the sealed accident button asks first
            assert isinstance(app.screen, ConfirmScreen) and "block-line SL accident" in app.screen.question
            await pilot.press("y")
            await pilot.pause()
            assert app.sim.sealed_uses() == {"block-line accident": 1}

    asyncio.run(body())


# ---- 4. the train number at the head of the train -------------------------------------------------------------
def test_a_moving_train_shows_its_number_at_its_head_with_the_arrow_leading() -> None:
    async def body() -> None:
        app = ConsoleApp("jiaopei", paused=True)
        async with app.run_test(size=SIZE):
            app.send("route X XI")
            app.send("train T1 at IAG", "instructor")
            cycles(app, 20)
            app.send("drive T1 30", "instructor")
            heads = []
            for _ in range(3):
                cycles(app, 40)
                tv = app.sim.train_view("T1")
                head = head_cell(layout(app), tv.head_track, tv.head_m)
                assert head is not None
                label = sorted((xy, ch) for xy, (ch, _) in app.diagram.frame().overlay.items())
                x, y = head
                ax, ay = label[-1][0]
                assert "".join(ch for _, ch in label) == "T1>" and ay == y
                # the arrow on the head's cell, or just ahead where the head's stretch of band is too short for the
                # name behind it (never back over the middle or the rear of the train)
                assert x <= ax <= x + 2
                heads.append(ax)
            assert heads[0] < heads[1] < heads[2]  # it moves with the head
            assert len(app.sim.train_view("T1").sections) > 1  # over several sections, the label at the front

    asyncio.run(body())


# ---- 5. sealed-button counters ----------------------------------------------------------------------------------
def test_each_accepted_use_of_a_sealed_button_is_counted_and_a_refused_one_is_not() -> None:
    sim = Simulation("jiaopei")
    for _ in range(2):
        assert sim.command("route X XI")
        sim.run(6)
        assert sim.command("release X")
    assert not sim.command("release X")  # refused: no route
    assert sim.command("route X XI")
    assert not sim.command("fault-release IG")  # refused on a station track
    assert sim.sealed_uses() == {"release": 2}


def test_the_function_bar_shows_the_counter_beside_a_sealed_button() -> None:
    async def body() -> None:
        app = ConsoleApp("jiaopei", paused=True)
        async with app.run_test(size=SIZE) as pilot:
            bar = app.function_bar
            for _ in range(2):
                app.send("route X XI")
                cycles(app, 24)
                await pilot.click(FunctionBar, offset=bar.offset_of("release"))
                await click(pilot, Ref("signal", "X"))
                assert isinstance(app.screen, ConfirmScreen)
                await pilot.press("y")
                await pilot.pause()
            assert app.sim.sealed_uses() == {"release": 2}
            assert "总人解 2" in str(bar.render())

    asyncio.run(body())

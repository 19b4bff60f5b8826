"""Snapshots of the console (pytest-textual-snapshot): both bundled stations at 80x24 and 160x48, the clock paused so
the picture is the same on every run. After a deliberate change of the drawing, look at the report and refresh
them with ``pytest tests/test_tui_snapshots.py --snapshot-update``."""

from __future__ import annotations

from typing import Any

import pytest

from liansuo.tui.app import ConsoleApp


@pytest.mark.parametrize("size", [(80, 24), (160, 48)], ids=["80x24", "160x48"])
@pytest.mark.parametrize("station", ["jiaopei", "gaotie"])
def test_the_console_at_rest(snap_compare: Any, station: str, size: tuple[int, int]) -> None:
    assert snap_compare(ConsoleApp(station, paused=True), terminal_size=size)


def test_a_route_a_fault_and_an_alarm(snap_compare: Any) -> None:
    """Receiving route X-XI open (white band, yellow lamp), turnout 5 without indication (red), 3G occupied."""

    async def operate(pilot: Any) -> None:
        app = pilot.app
        app.send("route X XI")
        app.send("fault no-indication 5", "instructor")
        app.send("occupy 3G", "instructor")
        app.advance(160)  # 40 s: the squeezed-turnout alarm after 30 s without indication
        app.refresh_views()
        await pilot.pause()

    assert snap_compare(ConsoleApp("jiaopei", paused=True), terminal_size=(80, 24), run_before=operate)

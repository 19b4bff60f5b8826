"""The console in field mode (docs/field-mode.md): the control mode on the status line, QHA's password asked before
the change-over, a lost link in red, and the change-over in the recording."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

pytest.importorskip("pymodbus", reason="the field extra (pymodbus) is not installed")

from consoletest import SIZE, message, run
from fieldsim import STATION, FieldSim

from liansuo.classroom.passwords import hash_password
from liansuo.fieldio import points
from liansuo.fieldio.link import ModbusLink
from liansuo.stations.loader import load
from liansuo.tui.app import ConsoleApp


def _app(port: int, **kwargs: object) -> ConsoleApp:
    station = load(STATION)
    from liansuo.rules import load_rules

    link = ModbusLink("127.0.0.1", port, points.from_station(station, load_rules()))
    return ConsoleApp(STATION, paused=True, field=link, changeover_hash=hash_password("qha-pw"), **kwargs)  # type: ignore[arg-type]


def status(app: ConsoleApp) -> str:
    return app.status_text(0).plain


def test_qha_asks_its_password_and_the_status_line_shows_the_mode(field: FieldSim, tmp_path: Path) -> None:
    record = tmp_path / "session.jsonl"

    @run
    async def drive() -> None:
        app = _app(field.port, record=record)
        async with app.run_test(size=SIZE) as pilot:
            await pilot.pause()
            assert "模拟控制 simulated control" in status(app)
            await pilot.press("colon", *"changeover field", "enter")
            await pilot.pause()
            await pilot.press(*"wrong", "enter")
            await pilot.pause()
            assert "wrong change-over password" in message(app)
            assert "模拟控制" in status(app) and app.sim.sealed_uses() == {}
            await pilot.press("colon", *"changeover field", "enter")
            await pilot.pause()
            await pilot.press(*"qha-pw", "enter")
            await pilot.pause()
            assert "QHJ up" in message(app), message(app)
            assert f"现场控制 field control (modbus 127.0.0.1:{field.port})" in status(app)
            assert app.sim.sealed_uses() == {"changeover": 1}
            await pilot.press("colon", *"route X XI", "enter")
            app.advance(8)
            assert app.sim.aspect("X") == "U"
            field.kill()
            app.advance(1)
            app.refresh_views()
            await pilot.pause()
            assert "LINK LOST" in status(app) and app.sim.aspect("X") == "H"
            assert any("field link lost" in line for line in app.log_panel.lines_text), app.log_panel.lines_text[-12:]

    drive()
    lines = [json.loads(line) for line in record.read_text(encoding="utf-8").splitlines()]
    said = [r for r in lines if "changeover field" in json.dumps(r, ensure_ascii=False)]
    assert said and any("QHJ up" in json.dumps(r, ensure_ascii=False) for r in said), said

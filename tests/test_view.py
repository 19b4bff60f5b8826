"""The query API (simulation/view.py): what front ends and trains read of the interlocking, as typed records."""

from __future__ import annotations

import dataclasses

import pytest

from liansuo.simulation.sim import Simulation
from liansuo.simulation.view import AlarmView, RouteView, SectionView, SignalView, TurnoutView


@pytest.fixture
def sim() -> Simulation:
    s = Simulation("jiaopei")
    assert s.command("route X XI").ok
    s.run(10)
    return s


def test_an_open_route_its_signal_sections_and_turnouts(sim: Simulation) -> None:
    v = sim.view
    route = v.route("X-XI")
    assert isinstance(route, RouteView) and route == v.route_of("X") and route in v.routes()
    assert (route.signal, route.kind, route.state, route.guide) == ("X", "train", "open", False)
    assert "IG" in route.sections and route.release_at is None
    assert v.route("S-SI") is None and v.route_state("S-SI") == "released"
    signal = v.signal("X")
    assert isinstance(signal, SignalView) and signal.aspect == "U" == v.aspect("X")
    assert signal.route == "X-XI" and not signal.alarmed
    section = v.section("IG")
    assert isinstance(section, SectionView) and section.locked and not section.occupied and section.state == "locked"
    locked = [t for t in v.turnouts() if t.locked]
    assert locked and all(isinstance(t, TurnoutView) and t.position and "X-XI" in t.why for t in locked)
    assert [t.id for t in v.turnouts()] == list(sim.station.turnouts)


def test_records_are_frozen(sim: Simulation) -> None:
    with pytest.raises(dataclasses.FrozenInstanceError):
        sim.view.section("IG").locked = False  # type: ignore[misc]


def test_alarms_are_typed_and_mark_their_signal(sim: Simulation) -> None:
    sim.command("fault filament X lamp=U which=both")
    sim.run(1)
    alarms = sim.alarm_views()
    assert alarms and all(isinstance(a, AlarmView) for a in alarms)
    lamp = next(a for a in alarms if a.kind == "lamp")
    assert lamp.element == "X" and "dark" in lamp.text and lamp.t is not None
    assert sim.view.signal("X").lamp_dark and sim.view.signal("X").alarmed
    assert [a.text for a in alarms] == sim.alarm_texts()


def test_a_restarted_interlocking_is_read_afresh(sim: Simulation) -> None:
    assert sim.command("restart").ok
    assert sim.view.routes() == () and sim.view.section("IG").locked

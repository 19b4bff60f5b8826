"""The trains figure of the benchmark: real trains run through the hub on each engine, side by side. Timings are
reported, never asserted."""

from __future__ import annotations

from typing import Any

import pytest

from liansuo.bench.trains import run_trains, train_slots, trains_text
from liansuo.interlocking.table.build import InterlockingTable, build_table
from liansuo.simulation.trains.sumo import sumo_installed
from liansuo.stations.hubgen import generate_hub
from liansuo.stations.loader import load_text
from liansuo.stations.station import Station


@pytest.fixture(scope="module")
def small_hub() -> tuple[Station, InterlockingTable]:
    station = load_text(generate_hub(60, 16), "<hub60>")
    return station, build_table(station)


def test_slots_are_receiving_then_departure_pairs_that_never_conflict(small_hub: tuple[Station,
                                                                                        InterlockingTable]) -> None:
    _, table = small_hub
    slots = train_slots(table, 10)
    assert len(slots) >= 4
    assert {r.direction.value for r, _ in slots} == {"down", "up"}
    ids = [route.id for pair in slots for route in pair]
    for r, d in slots:
        assert r.category == "receiving" and d.category == "departure" and d.start == r.end
        assert not any(other in r.conflicts or other in d.conflicts for other in ids if other not in (r.id, d.id))
    sections = [s for pair in slots for route in pair for s in route.sections]
    assert len(sections) == len(set(sections))


def test_trains_run_through_the_hub_on_both_engines(small_hub: tuple[Station, InterlockingTable]) -> None:
    station, table = small_hub
    report: dict[str, Any] = run_trains(station, table, cycles=1600, sumo_cycles=1600, slots=4)
    kin = report["kinematic"]
    assert report["trains"] == 4 and kin["realtime_factor"] > 0 and report["realtime_factor_trains"] > 0
    assert kin["mean_trains_moving"] > 1 and kin["departures"] >= 1
    assert kin["stalls"] == 0 and kin["alarms"] == 0 and kin["refused_commands"] == 0
    text = "\n".join(trains_text(report))
    assert "kinematic" in text and "sumo" in text
    missing = sumo_installed()
    if missing:
        assert report["sumo"]["status"].startswith("not installed")
        assert report["realtime_factor_trains_sumo"] is None
        return
    sumo = report["sumo"]
    assert sumo["status"] == "ok" and report["realtime_factor_trains_sumo"] > 0
    assert report["ratio_kinematic_to_sumo"] > 0 and "kinematic / sumo" in text
    # the same scenario: the same trains go through and nothing goes wrong on either engine
    assert (sumo["departures"], sumo["stalls"], sumo["alarms"]) == (kin["departures"], 0, 0)

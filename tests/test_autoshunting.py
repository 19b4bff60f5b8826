"""Automatic shunting in the depot (Liu Huawei et al. 2021, Liu Jing et al. 2025: docs/references.md): each driving
condition holds the locomotive braked with its reason; emergency stops by source; manual override; the boundary, blue
signals and the depot limits."""

from __future__ import annotations

import pytest
from conftest import Driver

from liansuo.simulation.sim import Simulation


@pytest.fixture
def depot() -> Driver:
    return Driver(Simulation("depot"))


def loco(d: Driver, name: str = "L1"):  # type: ignore[no-untyped-def]
    return d.sim.fleet.trains[name]


def speed(d: Driver, name: str = "L1") -> float:
    return loco(d, name).speed_kmh


def braked_for(d: Driver, text: str, name: str = "L1") -> None:
    assert speed(d, name) == 0.0
    assert text in loco(d, name).why, loco(d, name).why


def test_full_plan_runs_with_depot_limits_and_one_stop_points(depot: Driver) -> None:
    depot("train L1 at RDG kind=shunter back=20", "auto L1 plan=D1-D5,D13-1KA")
    top, over_sanding = 0.0, 0.0
    for _ in range(int(480 / 0.25)):
        depot.sim.step()
        v = depot.sim.train_views()[0]
        top = max(top, v.speed_kmh)
        if v.head_track == "t-1G" and 451 <= v.head_m <= 475:
            over_sanding = max(over_sanding, v.speed_kmh)
    assert top <= 8.0 + 1e-6  # depot limit
    assert 0 < over_sanding <= 3.0 + 1e-6  # sanding point
    log = "\n".join(depot.sim.event_texts())
    assert "stopped at one-stop point OS1" in log and "stopped at one-stop point OS2" in log
    assert "centre asked for D13-1KA" in log
    braked_for(depot, "buffer B1K")


def test_entry_conditions_refuse_automatic_mode(depot: Driver) -> None:
    depot("train L1 at RDG kind=shunter back=20")
    depot.refused("auto L1 loco=fault", "cannot enter automatic mode: locomotive control or sensor readings")


@pytest.mark.parametrize(("flag", "reason"), [
    ("onboard=off", "automatic-driving switch on the locomotive"),
    ("centre=off", "the control centre has not authorised"),
    ("loco=fault", "locomotive status is not normal"),
    ("perception=fault", "environment perception does not allow movement"),
])
def test_each_driving_condition_holds_the_locomotive_braked(depot: Driver, flag: str, reason: str) -> None:
    depot("train L1 at RDG kind=shunter back=20", "auto L1 plan=D1-D5", "run 20s")
    assert speed(depot) > 0
    depot(f"auto L1 {flag}", "run 15s")
    braked_for(depot, reason)


def test_no_route_ahead_no_open_signal_no_order(depot: Driver) -> None:
    depot("train L1 at RDG kind=shunter back=20", "auto L1", "run 20s")
    braked_for(depot, "no shunting order allows movement")


def test_plan_must_match_the_route_set(depot: Driver) -> None:
    depot("train L1 at RDG kind=shunter back=20", "shunt D1 D7", "run 10s", "auto L1 plan=D1-D5", "run 20s")
    braked_for(depot, "the shunting plan does not match the route and signal")


def test_route_ahead_locked_and_signal_open_are_needed(depot: Driver) -> None:
    depot("train L1 at RDG kind=shunter back=20", "fault no-indication 1", "auto L1 plan=D1-D5", "run 30s")
    braked_for(depot, "the route ahead is not locked")


def test_obstacle_ahead_within_the_safe_distance(depot: Driver) -> None:
    depot("axles wagon t-1G 420 430", "train L1 at RDG kind=shunter back=20", "auto L1 plan=D1-D5", "run 4min")
    assert speed(depot) == 0.0
    v = depot.sim.train_views()[0]
    assert 400.0 <= v.head_m < 420.0  # short of the wagon's first wheelset, by at least the safe distance's worth
    assert "obstacle" in loco(depot).why or "safe distance" in loco(depot).why


def test_emergency_stop_is_released_only_by_its_own_source(depot: Driver) -> None:
    depot("train L1 at RDG kind=shunter back=20", "auto L1 plan=D1-D5", "run 20s", "estop L1 team", "run 10s")
    braked_for(depot, "emergency stop (team)")
    depot("estop L1 cab")
    depot.refused("estop-release L1 team by=cab", "can only be released by the shunting team")
    depot("estop-release L1 team", "run 5s")
    braked_for(depot, "emergency stop (cab)")  # the cab's stop still holds
    depot("estop-release L1 cab", "run 10s")
    assert speed(depot) > 0


def test_manual_driving_overrides_automatic(depot: Driver) -> None:
    depot("train L1 at RDG kind=shunter back=20", "auto L1 plan=D1-D5", "run 20s", "drive L1 5", "run 10s")
    assert loco(depot).mode == "manual" and loco(depot).controller is None
    assert 4.9 < speed(depot) <= 5.0 + 1e-6


def test_stops_before_the_station_boundary_and_a_blue_signal(depot: Driver) -> None:
    depot("train L2 at RDG kind=shunter dir=up back=20", "auto L2", "run 1min")
    assert loco(depot, "L2").speed_kmh == 0.0
    v = next(v for v in depot.sim.train_views() if v.name == "L2")
    assert v.head_m >= 5.0  # a safe distance short of the boundary XB at 0 m
    depot("train L3 at QXG kind=shunter back=40", "auto L3", "run 1min")  # D3 at the neck's end shows blue (A)
    v3 = next(v for v in depot.sim.train_views() if v.name == "L3")
    assert v3.speed_kmh == 0.0

"""Automatic shunting control logic (Liu Huawei et al. 2021, Liu Jing et al. 2025: docs/references.md): conditions,
emergency stops, priorities, depot limits."""

from __future__ import annotations

import pytest

from liansuo.simulation.trains.autoshunt import (
    SAFE_DISTANCE_M,
    EmergencyStops,
    ShuntingInputs,
    StopTarget,
    braking_speed_kmh,
    depot_speed_limit_kmh,
    driving_conditions,
    entry_conditions,
    entry_warnings,
    permitted_speed_kmh,
)
from liansuo.simulation.trains.research.shunting import (
    PRIORITY,
    DepotMarker,
    DrivingMode,
    ModeArbiter,
    OneStopPoints,
    ShuntAction,
    next_stop,
    stop_target,
)
from liansuo.stations.loader import load

CLEAR = ShuntingInputs.all_clear()


# ---- conditions ---------------------------------------------------------------------------------------------------
def test_all_clear_may_enter_and_move() -> None:
    assert entry_conditions(CLEAR) == [] and driving_conditions(CLEAR) == [] and entry_warnings(CLEAR) == []


@pytest.mark.parametrize(("field", "text"), [
    ("authorised_onboard", "switch on the locomotive"),
    ("authorised_centre", "control centre"),
    ("shunting_order", "no shunting order"),
    ("route_ahead_locked", "route ahead is not locked"),
    ("signal_ahead_open", "signal ahead is not open"),
    ("plan_matches_route", "plan does not match"),
    ("position_matches_plan", "locomotive is not where"),
    ("loco_healthy", "locomotive status"),
    ("perception_healthy", "perception"),
    ("system_healthy", "automatic driving system"),
    ("area_ahead_ok", "area ahead"),
])
def test_each_unmet_driving_condition_is_named(field: str, text: str) -> None:
    unmet = driving_conditions(ShuntingInputs.all_clear(**{field: False}))
    assert len(unmet) == 1 and text in unmet[0]


def test_every_unmet_driving_condition_is_listed() -> None:
    nothing = ShuntingInputs(authorised_onboard=False, authorised_centre=False, shunting_order=False,
                             route_ahead_locked=False, signal_ahead_open=False, plan_matches_route=False,
                             loco_healthy=False, perception_healthy=False, obstacle_ahead_m=3.0, speed_kmh=0.0,
                             position_matches_plan=False, system_healthy=False, area_ahead_ok=False)
    assert len(driving_conditions(nothing)) == 12


def test_an_obstacle_within_the_safe_distance_stops_the_movement() -> None:
    assert driving_conditions(ShuntingInputs.all_clear(obstacle_ahead_m=50.0)) == []
    unmet = driving_conditions(ShuntingInputs.all_clear(obstacle_ahead_m=SAFE_DISTANCE_M - 2))
    assert len(unmet) == 1 and "obstacle 8 m ahead" in unmet[0]


@pytest.mark.parametrize(("field", "text"), [
    ("crew_confirmed", "crew has not confirmed"),
    ("positioning_ok", "positioning"),
    ("loco_healthy", "locomotive control"),
    ("ground_signals_ok", "indications"),
    ("plan_received", "no shunting plan"),
    ("comms_ok", "communication"),
    ("external_interfaces_ok", "external interface"),
    ("system_healthy", "self-check"),
])
def test_each_unmet_entry_condition_is_named(field: str, text: str) -> None:
    unmet = entry_conditions(ShuntingInputs.all_clear(**{field: False}))
    assert len(unmet) == 1 and text in unmet[0]


def test_a_non_critical_ground_sensor_allows_entry_with_a_warning() -> None:
    inputs = ShuntingInputs.all_clear(ground_sensors_ok=False)
    assert entry_conditions(inputs) == []
    assert len(entry_warnings(inputs)) == 1 and "gates" in entry_warnings(inputs)[0]
    assert driving_conditions(ShuntingInputs.all_clear(ground_sensors_ok=False, area_ahead_ok=False))


# ---- emergency stops ----------------------------------------------------------------------------------------------
def test_whoever_set_an_emergency_stop_releases_it() -> None:
    stops = EmergencyStops()
    stops.apply("team", "coupling the brake hoses")
    why = stops.release("team", by="cab")
    assert "only be released by the shunting team" in why and "not by the cab button" in why
    assert stops.stopped and stops.active == {"team"}
    assert stops.release("team", by="team") == ""
    assert not stops.stopped


def test_stops_from_several_sources_coexist_and_release_independently() -> None:
    stops = EmergencyStops()
    stops.apply("team")
    stops.apply("remote")
    stops.apply("remote")  # a second press changes nothing
    assert stops.active == {"team", "remote"}
    assert stops.release("remote", by="remote") == ""
    assert stops.active == {"team"} and stops.stopped
    assert "no emergency stop from the cab button" in stops.release("cab", by="cab")
    with pytest.raises(ValueError):
        stops.apply("")


# ---- modes and priorities ------------------------------------------------------------------------------------------
def auto_arbiter(mode: DrivingMode = DrivingMode.auto_shunting) -> ModeArbiter:
    arb = ModeArbiter()
    assert arb.engage(mode, CLEAR) == []
    return arb


def test_entry_is_refused_while_an_entry_condition_is_unmet() -> None:
    arb = ModeArbiter()
    unmet = arb.engage(DrivingMode.auto_shunting, ShuntingInputs.all_clear(comms_ok=False))
    assert unmet and arb.mode is DrivingMode.manual
    assert arb.decide(CLEAR).action is ShuntAction.manual


def test_automatic_moves_only_when_every_condition_holds() -> None:
    arb = auto_arbiter()
    assert arb.decide(CLEAR).action is ShuntAction.move
    d = arb.decide(ShuntingInputs.all_clear(signal_ahead_open=False))
    assert d.action is ShuntAction.brake and d.reasons == ("the signal ahead is not open",)
    assert arb.decide(CLEAR, demand_move=False).action is ShuntAction.brake
    assert arb.mode is DrivingMode.auto_shunting  # a missing condition brakes, it does not leave automatic mode


def test_manual_driving_overrides_automatic_and_latches() -> None:
    arb = auto_arbiter()
    d = arb.decide(CLEAR, manual_input=True)
    assert d.action is ShuntAction.manual and "driver took over" in d.reasons[0]
    assert arb.decide(CLEAR).action is ShuntAction.manual  # stays manual until engaged again
    assert arb.engage(DrivingMode.auto_shunting, CLEAR) == []
    assert arb.decide(CLEAR).action is ShuntAction.move


def test_stopping_outranks_moving_even_manual_moving() -> None:
    arb = auto_arbiter()
    arb.stops.apply("system", "obstacle")
    d = arb.decide(ShuntingInputs.all_clear(speed_kmh=6.0), manual_input=True)
    assert d.action is ShuntAction.emergency_brake and "automatic driving system" in d.reasons[0]
    arb.stops.release("system", by="system")
    assert arb.decide(CLEAR).action is ShuntAction.manual  # the driver's input still latched manual mode


def test_an_emergency_stop_at_a_secured_stand_only_watches_the_speed() -> None:
    arb = auto_arbiter()
    arb.stops.apply("remote")
    assert arb.decide(CLEAR, secured=True).action is ShuntAction.monitor
    assert arb.decide(ShuntingInputs.all_clear(speed_kmh=0.5), secured=True).action is ShuntAction.emergency_brake
    assert arb.decide(CLEAR, secured=False).action is ShuntAction.emergency_brake


def test_remote_driving_waives_route_and_signal_but_is_limited() -> None:
    arb = auto_arbiter(DrivingMode.remote)
    d = arb.decide(ShuntingInputs.all_clear(signal_ahead_open=False, plan_matches_route=False))
    assert d.action is ShuntAction.move and d.speed_limit_kmh == 5.0 and d.distance_limit_m == 200.0
    assert arb.decide(ShuntingInputs.all_clear(loco_healthy=False)).action is ShuntAction.brake


def test_the_priority_table_puts_stopping_first_and_automatic_moving_last() -> None:
    actions = [a for _, a in PRIORITY]
    assert actions[0] is ShuntAction.emergency_brake and actions[-1] is ShuntAction.move
    assert actions.index(ShuntAction.manual) < actions.index(ShuntAction.brake)


# ---- depot limits ---------------------------------------------------------------------------------------------------
MARKERS = [
    DepotMarker("SA", "sanding", "t-1", 100.0, length_m=20.0, speed_kmh=3.0),
    DepotMarker("WA", "washing", "t-1", 200.0, length_m=40.0),  # no speed given: the 3 km/h service limit
    DepotMarker("SB", "sanding", "t-2", 150.0, length_m=20.0, speed_kmh=3.0),
    DepotMarker("OS1", "one-stop", "t-1", 300.0),
    DepotMarker("OS0", "one-stop", "t-1", 50.0),
    DepotMarker("R1", "rfid", "t-1", 120.0),
]


@pytest.mark.parametrize(("front", "rear", "limit"), [
    (60.0, None, 8.0),  # plain depot track
    (105.0, None, 3.0),  # over the sanding stretch 100-120
    (130.0, 110.0, 3.0),  # the front has left it, the rear not yet
    (150.0, 130.0, 8.0),
    (220.0, 200.0, 3.0),  # washing, default 3 km/h
    (160.0, None, 8.0),  # SB is on another track
])
def test_depot_speed_limits(front: float, rear: float | None, limit: float) -> None:
    assert depot_speed_limit_kmh(front, MARKERS, rear_m=rear, tracks={"t-1"}) == limit


def test_without_a_track_filter_every_marker_counts() -> None:
    assert depot_speed_limit_kmh(160.0, MARKERS) == 3.0


def test_permitted_speed_brakes_towards_a_stretch_and_a_stop() -> None:
    far = permitted_speed_kmh(20.0, "down", MARKERS, tracks={"t-1"})
    near = permitted_speed_kmh(99.0, "down", MARKERS, tracks={"t-1"})
    assert far == 8.0 and 3.0 < near < 8.0
    stop = StopTarget(300.0, "one-stop point OS1", "OS1")
    assert permitted_speed_kmh(300.0, "down", MARKERS, tracks={"t-1"}, stop=stop) == 0.0
    assert permitted_speed_kmh(299.0, "down", MARKERS, tracks={"t-1"}, stop=stop) == pytest.approx(
        braking_speed_kmh(1.0))


def test_next_one_stop_point_in_either_direction() -> None:
    assert next_stop(60.0, "down", MARKERS) == StopTarget(300.0, "one-stop point OS1", "OS1")
    assert next_stop(60.0, "up", MARKERS) == StopTarget(50.0, "one-stop point OS0", "OS0")
    assert next_stop(60.0, "down", MARKERS, served={"OS1"}) is None
    with pytest.raises(ValueError):
        next_stop(60.0, "sideways", MARKERS)


def test_a_one_stop_point_is_passed_only_after_a_stop_and_the_drivers_confirmation() -> None:
    points = OneStopPoints(MARKERS, tracks={"t-1"})
    target = points.next_stop(250.0, "down")
    assert target is not None and target.marker == "OS1"
    assert points.confirm("OS1").startswith("the movement has not stopped")
    assert points.observe(297.0, "down", speed_kmh=1.0) is None  # rolling past is no stop
    assert points.observe(290.0, "down", speed_kmh=0.0) is None  # too far before it
    assert points.observe(297.0, "down", speed_kmh=0.0) == "OS1"
    assert points.next_stop(297.0, "down") == target  # still the stopping point until confirmed
    assert points.confirm("OS1") == ""
    assert points.next_stop(297.0, "down") is None


def test_stop_targets_keep_the_safe_distance() -> None:
    assert stop_target(400.0, "down", signal_at_m=500.0, signal_aspect="A") == StopTarget(
        490.0, "signal ahead shows A")
    assert stop_target(400.0, "down", signal_at_m=500.0, signal_aspect="B") is None
    boundary = stop_target(100.0, "up", boundary_at_m=0.0)
    assert boundary is not None and boundary.at_m == 10.0 and boundary.reason == "station boundary"
    nearest = stop_target(400.0, "down", signal_at_m=500.0, obstacle_ahead_m=30.0, buffer_at_m=700.0,
                          one_stop=StopTarget(450.0, "one-stop point X", "X"))
    assert nearest == StopTarget(420.0, "obstacle ahead")
    dark = stop_target(400.0, "down", signal_at_m=500.0, signal_aspect="", safe_distance_m=20.0)
    assert dark is not None and dark.at_m == 480.0


def test_the_depot_station_markers_drive_the_limits() -> None:
    markers = load("depot").model.markers
    assert depot_speed_limit_kmh(455.0, markers, tracks={"t-1G"}) == 3.0  # sanding SA1 on servicing track 1
    assert depot_speed_limit_kmh(455.0, markers, tracks={"t-3G"}) == 8.0  # stabling track 3 at the same position
    assert depot_speed_limit_kmh(610.0, markers, tracks={"t-1KG"}) == 3.0  # washing WA1 in the shed
    target = next_stop(400.0, "down", markers, tracks={"t-1G", "t-1KG"})
    assert target is not None and target.marker == "OS1" and target.at_m < 560.0  # before the shed signal D13

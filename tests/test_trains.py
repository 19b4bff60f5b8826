"""Trains in the yard: they occupy track circuits through their wheelsets, obey (or pass) signals, and exercise
every release path of the interlocking."""

from __future__ import annotations

import pytest
from conftest import Driver

from liansuo.simulation.sim import Simulation
from liansuo.stations.library import bundled
from liansuo.stations.loader import load_text


def view(d: Driver, name: str):  # type: ignore[no-untyped-def]
    return next(v for v in d.sim.train_views() if v.name == name)


def max_speed_past(d: Driver, name: str, x: float, seconds: float, until_x: float = 1e9) -> float:
    """The highest speed of the train while its front is between position ``x`` (a signal it has just passed)
    and ``until_x`` (the next signal)."""
    top = 0.0
    for _ in range(int(seconds / 0.25)):
        d.sim.step()
        v = next((v for v in d.sim.train_views() if v.name == name), None)
        if v is not None and x < v.head_m < until_x:
            top = max(top, v.speed_kmh)
    return top


def test_train_is_seen_through_its_wheelsets_and_stops_at_the_closed_starting_signal(jiaopei: Driver) -> None:
    jiaopei("train T1 at IAG mode=signal length=200", "expect section IAG occupied", "route X XI", "run 2min")
    v = view(jiaopei, "T1")
    assert v.sections == ("IG",) and v.speed_kmh == 0.0
    assert 1000.0 < v.head_m < 1020.0  # short of starting signal XI at 1020 m
    # released section by section behind the train (three-point check), never all at once
    log = jiaopei.sim.event_texts()
    order = [line.split("section ")[1].split(" ")[0] for line in log if "released (X-XI)" in line]
    assert order == ["7DG", "1DG", "IG"]
    jiaopei("expect route X XI released", "expect signal X H")


def test_departure_over_64d_the_train_leaves_and_the_neighbour_restores(jiaopei: Driver) -> None:
    jiaopei("train T1 at IG mode=signal length=200", "route XI S", "run 5s", "expect signal XI H",
            "block-line SL request", "run 5s", "expect signal XI L", "run 1min", "expect block-line SL departed",
            "run 2min", "expect block-line SL idle")
    assert jiaopei.sim.train_views() == []
    assert any("has left the station" in e for e in jiaopei.sim.event_texts())


def test_manual_driver_passes_a_red_signal_and_the_interlocking_notices(jiaopei: Driver) -> None:
    jiaopei("train T1 at IAG length=100 back=60", "drive T1 20", "run 30s", "expect alarm passed at danger")


def test_signal_obeying_driver_waits_at_red_and_goes_when_it_clears(jiaopei: Driver) -> None:
    jiaopei("train T1 at IAG mode=signal length=100 back=100", "run 1min", "expect section 7DG free")
    assert view(jiaopei, "T1").speed_kmh == 0.0
    jiaopei("route X XI", "run 10s")
    assert view(jiaopei, "T1").speed_kmh > 0.0


def test_trailing_through_a_turnout_the_wrong_way_squeezes_it(jiaopei: Driver) -> None:
    jiaopei("throw 1/3 reverse", "run 5s", "train T1 at IG dir=up length=100", "drive T1 15", "run 40s",
            "expect alarm squeezed", "expect turnout 1 none")


def test_facing_move_onto_a_moving_turnout_derails(jiaopei: Driver) -> None:
    jiaopei("fault high-resistance 1", "throw 1 reverse", "train T1 at 7DG length=40 back=10", "drive T1 20",
            "run 20s", "expect alarm derailed at turnout 1")
    assert view(jiaopei, "T1").speed_kmh == 0.0


def test_manual_time_release_with_a_train_approaching_that_stops(jiaopei: Driver) -> None:
    jiaopei("train T1 at IAG mode=signal length=150 back=250", "route X XI", "run 2s", "release X",
            "expect accepted releases in 180 s", "run 170s", "expect route X XI time_release", "run 15s",
            "expect route X XI released", "expect section 7DG free")


def test_guide_aspect_train_passes_at_most_20_kmh(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "fault broken-rail 1DG", "run 1s", "expect signal X H", "guide X", "run 1s",
            "expect signal X HB", "train T1 at IAG mode=signal length=120 back=150")
    assert 0 < max_speed_past(jiaopei, "T1", 300.0, 120) <= 20.01  # past home signal X
    jiaopei("expect signal X H")


def test_section_fault_release_after_a_poor_shunt_hid_the_train(jiaopei: Driver) -> None:
    # a contact film of 30 ohm per wheelset: even all the train's wheelsets in parallel no longer drop the relay
    jiaopei("fault poor-shunt 1DG ohm=30", "route X XI", "train T1 at IAG mode=signal length=100 back=20",
            "run 2min", "expect section 1DG locked", "expect route X XI in_use", "repair poor-shunt 1DG",
            "fault-release 1DG", "expect section 1DG free")


def test_shunting_partial_release_when_the_shunter_draws_back(jiaopei: Driver) -> None:
    jiaopei("train L1 at QXG kind=shunter mode=signal back=30", "shunt D1 SI", "run 5s", "expect signal D1 B",
            "drive L1 10", "run 25s", "stop L1", "run 10s", "expect section 7DG occupied", "expect signal D1 A",
            "reverse L1", "drive L1 10", "run 30s", "stop L1", "run 5s", "expect section 7DG free",
            "expect route D1 SI released")


def test_overlap_released_180s_after_the_train_stands_on_the_receiving_track() -> None:
    text = bundled()["jiaopei"].read_text(encoding="utf-8") + (
        "overlaps:\n  - {end_signal: XI, sections: [2DG], turnouts: [{turnout: \"2\", position: normal}]}\n")
    d = Driver(Simulation(load_text(text, "jiaopei-overlap.yaml")))
    d("train T1 at IAG mode=signal length=150 back=50", "route X XI", "run 90s", "expect route X XI released",
      "expect section 2DG locked", "run 180s", "expect section 2DG free")


@pytest.fixture
def gaotie() -> Driver:
    return Driver(Simulation("gaotie"))


def test_platform_stop_in_the_window_doors_linked_and_departure_only_with_doors_locked(gaotie: Driver) -> None:
    gaotie("train G2 at IAG kind=emu mode=signal back=900 stop=P3", "route X X3", "run 150s")
    g = gaotie.sim.fleet.trains["G2"]
    assert g.platform_stop is not None and g.platform_stop.state == "doors_open"
    assert g.train_doors_open and gaotie.sim.field.doors["P3:right"].is_open
    gaotie("route X3 XFCK", "run 2s", "expect signal X3 H")  # the screen doors are open
    gaotie("run 60s")
    assert not g.train_doors_open
    events = gaotie.sim.event_texts()
    assert any("from the mark (window ±0.5 m)" in e for e in events)
    closing = next(float(e.split()[0]) for e in events if "doors closing at P3" in e)
    opened = next(float(e.split()[0]) for e in events if "signal X3 opened" in e)
    assert opened >= closing + 3.9  # X3 cleared only once the screen doors were proven closed and locked (~4 s)
    assert any("signal X3 closed: train entered" in e for e in events)  # and the train left


def test_usu_through_the_no18_turnout(gaotie: Driver) -> None:
    gaotie("train G1 at IAG kind=emu mode=signal back=900", "route X X3", "route X3 XFCK", "run 15s",
           "expect signal X USU")
    x_home, x_start = gaotie.sim.station.node_at("J-X"), gaotie.sim.station.node_at("J-3G2")
    top = max_speed_past(gaotie, "G1", x_home, 150, until_x=x_start)
    assert 70 < top <= 80.01  # USU: 80 km/h over the No. 18 turnouts, up to the starting signal


def test_train_command_refusals(jiaopei: Driver) -> None:
    jiaopei.refused("train T1 at NOPE", "no section 'NOPE'")
    jiaopei.refused("train T1 at IAG mode=fast", "mode must be one of")
    jiaopei.refused("train T1 at IAG length=abc", "length must be a number")
    jiaopei.refused("train T1 at IAG wheels=4", "unknown train parameter")
    jiaopei("train T1 at IAG")
    jiaopei.refused("train T1 at IG", "already on the track")
    jiaopei.refused("drive T9 10", "no train 'T9'")
    jiaopei.refused("drive T1 500", "at most")
    jiaopei("drive T1 10", "run 5s")
    jiaopei.refused("reverse T1", "is moving")
    jiaopei("train T1 remove")

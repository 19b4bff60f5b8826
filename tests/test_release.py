"""Every kind of release: sequential (three-point check), shunting partial release, cancel, manual time release,
section fault release, overlap timer, and signal-passed-at-danger detection."""

from __future__ import annotations

from conftest import Driver

from liansuo.simulation.sim import Simulation
from liansuo.stations.library import bundled
from liansuo.stations.loader import load_text


def test_sequential_release_follows_the_train_section_by_section(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy IAG", "occupy 7DG", "run 1s", "expect signal X H",
            "expect section 7DG occupied", "vacate IAG", "occupy 1DG", "run 1s", "expect section 7DG occupied")
    jiaopei("vacate 7DG", "run 1s", "expect section 7DG free", "expect section 1DG occupied")
    jiaopei("occupy IG", "vacate 1DG", "run 1s", "expect section 1DG free", "expect route X XI released",
            "expect turnout 1 normal")
    _, locked = jiaopei.sim.turnout_state("1")
    assert not locked


def test_three_point_check_holds_a_section_cleared_before_the_next_is_occupied(jiaopei: Driver) -> None:
    # 7DG drops and picks up again without 1DG ever being occupied: not a train passing, no release
    jiaopei("route X XI", "run 1s", "occupy IAG", "occupy 7DG", "run 1s", "vacate 7DG", "run 1s",
            "expect section 7DG locked", "expect route X XI locked")


def test_shunting_route_partial_release_when_the_movement_draws_back(jiaopei: Driver) -> None:
    jiaopei("shunt D1 SI", "run 5s", "expect signal D1 B", "occupy QXG", "occupy 7DG", "run 1s",
            "expect signal D1 B")  # stays open until the whole consist is past the signal
    jiaopei("vacate QXG", "run 1s", "expect signal D1 A")
    jiaopei("occupy QXG", "vacate 7DG", "run 1s", "expect section 7DG free", "expect section 1DG free",
            "expect route D1 SI released")


def test_cancel_releases_at_once_while_the_approach_is_clear(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "cancel X", "expect signal X H", "expect route X XI released",
            "expect section 7DG free", "throw 1 reverse")


def test_cancel_refused_when_approach_locked(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy IAG", "run 1s")
    jiaopei.refused("cancel X", "approach section IAG is occupied")


def test_manual_time_release_train_route_180s_with_checks_during_delay(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy IAG", "run 1s", "release X", "run 1s", "expect signal X H",
            "expect route X XI time_release", "run 177s", "expect route X XI time_release", "run 2s",
            "expect route X XI released")


def test_manual_time_release_shunting_route_30s(jiaopei: Driver) -> None:
    jiaopei("shunt D1 SI", "run 5s", "occupy QXG", "run 1s", "release D1", "run 29s",
            "expect route D1 SI time_release", "run 1.5s", "expect route D1 SI released")


def test_manual_release_delay_configurable_per_signal() -> None:
    text = bundled()["jiaopei"].read_text(encoding="utf-8").replace(
        "{id: X, kind: home, at: J-X, direction: down,", "{id: X, kind: home, at: J-X, direction: down, release_s: 60,")
    d = Driver(Simulation(load_text(text, "jiaopei-60.yaml")))
    d("route X XI", "run 1s", "occupy IAG", "run 1s", "release X", "run 59.5s", "expect route X XI time_release",
      "run 1s", "expect route X XI released")


def test_train_entering_during_time_release_is_signal_passed_at_danger(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy IAG", "run 1s", "release X", "run 10s", "occupy 7DG", "run 1s",
            "expect alarm passed at danger", "expect route X XI in_use")


def test_signal_passed_at_danger_without_route(jiaopei: Driver) -> None:
    jiaopei("occupy IAG", "run 1s", "occupy 7DG", "run 1s", "expect alarm signal X passed at danger")


def test_no_spad_for_a_train_passing_an_open_signal(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy IAG", "occupy 7DG", "run 1s", "expect no-alarm passed at danger")


def test_section_fault_release_of_a_stuck_section(jiaopei: Driver) -> None:
    # the train passes but 1DG never shows it (a dead zone / poor shunt): 1DG stays locked
    jiaopei("route X XI", "run 1s", "occupy IAG", "occupy 7DG", "run 1s", "vacate IAG", "occupy IG", "vacate 7DG",
            "run 1s", "expect section 1DG locked")
    jiaopei("fault-release 1DG", "run 1s", "expect section 1DG free")


def test_section_fault_release_refused_on_station_track_and_on_free_or_occupied_sections(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s")
    jiaopei.refused("fault-release IG", "station track")
    jiaopei.refused("fault-release 6DG", "not locked")
    jiaopei.refused("fault-release 7DG", "signal X is open")
    jiaopei("cancel X", "route X XI", "run 1s", "occupy 1DG", "run 1s")
    jiaopei.refused("fault-release 1DG", "occupied")


def test_section_fault_release_is_delayed_with_a_train_approaching(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy IAG", "occupy IG", "run 1s", "vacate IG", "run 1s")  # closed abnormally
    jiaopei("fault-release 1DG", "run 100s", "expect section 1DG locked", "run 81s", "expect section 1DG free")


OVERLAP = """
overlaps:
  - {end_signal: XI, sections: [2DG], turnouts: [{turnout: "2", position: normal}], release_s: 180}
"""


def test_overlap_locked_with_route_and_released_180s_after_train_on_the_receiving_track() -> None:
    text = bundled()["jiaopei"].read_text(encoding="utf-8") + OVERLAP
    d = Driver(Simulation(load_text(text, "jiaopei-overlap.yaml")))
    d("route X XI", "run 1s", "expect section 2DG locked", "expect turnout 2 normal locked")
    d.refused("shunt D2 XI", "conflicting route X-XI is locked (section 2DG)")
    d("occupy IAG", "occupy 7DG", "run 1s", "vacate IAG", "occupy 1DG", "run 1s", "vacate 7DG", "occupy IG",
      "run 1s", "vacate 1DG", "run 1s", "expect route X XI released", "expect section 2DG locked")
    d.refused("shunt D2 XI", "section 2DG is locked in route X-XI")
    d("run 177s",
      "expect section 2DG locked", "run 2s", "expect section 2DG free")


def test_overlap_is_part_of_the_table_and_conflicts_only_with_movements_that_do_not_continue_it() -> None:
    from liansuo.interlocking.table.build import build_table

    text = bundled()["jiaopei"].read_text(encoding="utf-8") + OVERLAP
    table = build_table(load_text(text, "jiaopei-overlap.yaml"))
    r = table.routes["X-XI"]
    assert r.overlap_sections == ("2DG",)
    # the departure from XI continues the receiving route over its overlap: a through movement, not an enemy
    assert "XI-S" not in r.conflicts and "X-XI" not in table.routes["XI-S"].conflicts
    # a movement the other way over the overlap is
    assert r.conflicts["S-SI"].startswith("section") and r.conflicts["D2-D4"] == "section 2DG"


def test_a_route_partly_released_by_section_fault_release_never_opens(jiaopei: Driver) -> None:
    # found by the safety properties: the signal opened over a turnout whose section had been fault-released
    jiaopei("block-line XL request", "run 1s", "route SI X", "fault-release 1DG", "run 5s", "expect signal SI H",
            "expect turnout 1 normal", "expect section 1DG free", "run 30s", "expect signal SI H")
    jiaopei.refused("reopen SI", "has been released")


def test_a_shunting_signal_held_for_its_passing_consist_still_sees_an_occupancy_further_on(jiaopei: Driver) -> None:
    jiaopei("shunt D1 S3", "run 12s", "expect signal D1 B", "occupy QXG", "occupy 7DG", "occupy 1DG", "run 1s",
            "expect signal D1 B")  # the consist entering: approach and the first sections, contiguous
    jiaopei("occupy 5DG", "run 1s", "expect signal D1 A", "expect alarm section 5DG is occupied")


def test_an_overlap_without_release_s_releases_after_the_rule_sets_overlap_release_s() -> None:
    from liansuo.interlocking.table.build import build_table
    from liansuo.rules import load_rules

    text = bundled()["jiaopei"].read_text(encoding="utf-8") + OVERLAP.replace(", release_s: 180", "")
    station = load_text(text, "jiaopei-overlap.yaml")
    assert build_table(station).routes["X-XI"].overlap_release_s == load_rules().overlap_release_s == 180.0
    rules = load_rules().model_copy(update={"overlap_release_s": 90.0})
    assert build_table(station, rules).routes["X-XI"].overlap_release_s == 90.0

"""Route selection, turnout operation, locking and signal clearing on jiaopei."""

from __future__ import annotations

from conftest import Driver

from liansuo.rules import load_rules
from liansuo.simulation.sim import Simulation


def test_receiving_route_opens_with_yellow_when_starting_signal_closed(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "expect signal X U", "expect route X XI open",
            "expect turnout 7 normal locked", "expect turnout 1 normal locked", "expect turnout 3 normal locked",
            "expect section 7DG locked", "expect section IG locked")


def test_home_aspect_follows_onward_starting_signal(jiaopei: Driver) -> None:
    jiaopei("route X XI", "route XI S", "block-line SL request", "run 6s", "expect signal XI L", "expect signal X L")


def test_diverging_route_moves_crossover_pair_after_throw_time_and_shows_two_yellows(jiaopei: Driver) -> None:
    jiaopei("route X X3", "run 2s", "expect signal X H", "expect turnout 1 none")
    jiaopei("run 3s", "expect turnout 1 reverse locked", "expect turnout 3 reverse locked", "expect signal X UU")


def test_conflicting_route_is_refused_with_its_name(jiaopei: Driver) -> None:
    jiaopei("route X XI")
    jiaopei.refused("route S SI", "conflicting route X-XI is locked")
    jiaopei.refused("route X X3", "signal X already has route X-XI")


def test_occupied_section_refuses_the_route(jiaopei: Driver) -> None:
    jiaopei("occupy 1DG")
    jiaopei.refused("route X XI", "section 1DG is occupied")


def test_unknown_and_wrong_buttons_are_explained(jiaopei: Driver) -> None:
    jiaopei.refused("route X Q9", "no signal or button 'Q9'")
    jiaopei.refused("route D1 SI", "signal D1 has no train button")
    jiaopei.refused("route X S", "no train route from X to S; routes from X: X-X3, X-XI")


def test_single_locked_turnout_in_the_wrong_position_refuses_the_route(jiaopei: Driver) -> None:
    jiaopei("throw 1 reverse", "run 5s", "lock 1")
    jiaopei.refused("route X XI", "turnout 1 is single-locked")
    jiaopei.refused("throw 1 normal", "single-locked")
    jiaopei("unlock 1", "route X XI", "run 5s", "expect signal X U")


def test_single_blocked_turnout_forbids_routes_but_allows_individual_operation(jiaopei: Driver) -> None:
    jiaopei("block 7")
    jiaopei.refused("route X XI", "turnout 7 is single-blocked")
    jiaopei("throw 7 reverse", "run 5s", "expect turnout 7 reverse", "unblock 7", "throw 7 normal", "run 5s",
            "route X XI", "run 1s", "expect signal X U")


def test_individual_operation_refused_when_locked_or_occupied(jiaopei: Driver) -> None:
    jiaopei("route X XI")
    jiaopei.refused("throw 1 reverse", "turnout 1 is locked in route X-XI")
    jiaopei("occupy 5DG")
    jiaopei.refused("throw 5 reverse", "section 5DG is occupied")


def test_crossover_pair_moves_together_by_one_command(jiaopei: Driver) -> None:
    jiaopei("throw 1/3 reverse", "run 5s", "expect turnout 1 reverse", "expect turnout 3 reverse")


def test_turnout_moves_are_queued_with_limited_concurrency() -> None:
    rules = load_rules().model_copy(update={"turnout_concurrency": 1})
    d = Driver(Simulation("jiaopei", rules=rules))
    d("shunt D1 D5", "run 4.5s")  # 7, 1/3 and 5 must all move, one machine at a time
    moved = [t for t in ("7", "1", "3", "5") if d.sim.turnout_state(t)[0] == "reverse"]
    assert len(moved) == 1
    d("run 15s", "expect signal D1 B")


def test_lost_condition_closes_signal_and_it_never_reopens_by_itself(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy IG", "run 1s", "expect signal X H", "expect alarm signal X closed")
    jiaopei("vacate IG", "run 30s", "expect signal X H", "expect route X XI locked")
    jiaopei("reopen X", "run 1s", "expect signal X U")


def test_reopen_refused_while_the_condition_is_still_lost(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy 1DG", "run 1s")
    jiaopei.refused("reopen X", "section 1DG is occupied")


def test_turnout_losing_indication_closes_signal(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "expect signal X U")
    jiaopei("fault no-indication 1", "run 1s", "expect signal X H", "expect alarm turnout 1 has no indication")


def test_squeezed_turnout_alarm_after_thirty_seconds_without_indication(jiaopei: Driver) -> None:
    jiaopei("fault squeezed 5", "run 29s", "expect no-alarm squeezed", "run 2s", "expect alarm turnout 5 squeezed",
            "repair squeezed 5", "run 1s", "expect no-alarm squeezed")


def test_move_timeout(jiaopei: Driver) -> None:
    jiaopei("fault high-resistance 5", "throw 5 reverse", "run 20s", "expect alarm turnout 5 did not reach reverse",
            "expect turnout 5 none")


def test_a_departure_onto_a_line_with_no_block_described_checks_the_line_sections() -> None:
    from liansuo.stations.library import bundled
    from liansuo.stations.loader import load_text

    text = bundled()["jiaopei"].read_text(encoding="utf-8")
    start = text.index("links:")
    end = text.find("\n\n", start)
    end = len(text) if end < 0 else end  # the links block runs to the next blank line, or to the end
    d = Driver(Simulation(load_text(text[:start] + text[end:], "jiaopei-no-block.yaml")))
    assert d.sim.table.routes["S3-X"].line_sections == ("IAG",)
    # a train on the line, and nothing (no 64D, no automatic block) to say so but the track circuit
    d("occupy IAG", "route S3 X", "run 20s", "expect signal S3 H", "expect route S3 X locked")
    d("vacate IAG", "run 1s", "expect signal S3 L")
    d("occupy IAG", "run 1s", "expect signal S3 H")  # and a train running in closes it again


def test_expect_route_names_the_stages_a_route_can_be_in() -> None:
    sim = Simulation("jiaopei")
    sim.command("route X XI")
    sim.run(10)
    assert sim.command("expect route X XI open").ok and sim.command("expect route X XI locked").ok
    wrong = sim.command("expect route X XI lockd")
    assert not wrong.ok and "not 'lockd'" in wrong.message and "closed" in wrong.message and "released" in wrong.message

"""Guide routes and guide total lock, 64D semi-automatic block, platform screen doors, automatic block signals."""

from __future__ import annotations

import pytest
from conftest import Driver

from simulation.sim import Simulation


@pytest.fixture
def gaotie() -> Driver:
    return Driver(Simulation("gaotie"))


# ---- guide --------------------------------------------------------------------------------------------------
def test_guide_route_over_a_faulty_section_shows_red_and_moon_white(jiaopei: Driver) -> None:
    jiaopei("occupy 1DG")  # red band on 1DG: the route cannot be set normally
    jiaopei.refused("route X XI", "section 1DG is occupied")
    jiaopei("vacate 1DG", "route X XI", "run 1s", "occupy 1DG", "run 1s", "expect signal X H")
    jiaopei("guide X", "run 1s", "expect signal X HB", "expect turnout 1 normal locked")
    jiaopei("occupy IAG", "run 5s", "expect signal X HB", "occupy 7DG", "vacate IAG", "run 1s", "expect signal X H")


def test_guide_refused_without_route_or_with_turnout_out_of_position(jiaopei: Driver) -> None:
    jiaopei.refused("guide X", "no route is set from X")
    jiaopei.refused("guide XI", "no guide aspect")
    jiaopei.sim.field.set_indication_lost("7", True)
    jiaopei("route X XI", "run 1s")
    jiaopei.refused("guide X", "turnout 7 has no indication")


def test_guide_needs_the_red_lamp_lit(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy 1DG", "run 1s")
    jiaopei.sim.field.set_lamp_dark("X", "H", True)
    jiaopei("run 1s")
    jiaopei.refused("guide X", "red lamp of X is dark")


def test_guide_total_lock_locks_every_turnout_of_the_throat_and_allows_guide_without_route(jiaopei: Driver) -> None:
    jiaopei("guide-lock X", "expect turnout 1 normal locked", "expect turnout 7 normal locked",
            "expect turnout 5 normal locked")
    jiaopei.refused("throw 1 reverse", "guide total lock")
    jiaopei.refused("route X X3", "guide total lock")
    jiaopei("guide X", "run 1s", "expect signal X HB", "occupy IAG", "run 2s", "vacate IAG", "run 1s",
            "expect signal X H", "guide-unlock X", "throw 1 reverse")
    jiaopei.refused("guide-lock Q", "throats are named by their home signal: S, X")


# ---- 64D semi-automatic block ----------------------------------------------------------------------------------
def test_64d_departure_needs_acceptance_and_blocks_the_line_until_restored(jiaopei: Driver) -> None:
    jiaopei("route XI S", "run 1s", "expect signal XI H", "expect block-line SL idle")
    jiaopei("block-line SL request", "run 1s", "expect block-line SL requested", "run 3s",
            "expect block-line SL permitted", "run 1s", "expect signal XI L")
    jiaopei("occupy IG", "occupy 2DG", "run 1s", "expect signal XI H", "vacate IG", "occupy 6DG", "run 1s",
            "vacate 2DG", "occupy IIAG", "run 1s", "vacate 6DG", "run 1s", "expect block-line SL departed")
    jiaopei("route XI S", "run 1s", "expect signal XI H")  # the line is blocked behind the train
    jiaopei("vacate IIAG", "run 5s", "expect block-line SL idle")  # the virtual neighbour restores after arrival
    jiaopei.refused("block-line SL restore", "only after the train has arrived")


def test_64d_receiving_accept_arrive_restore(jiaopei: Driver) -> None:
    jiaopei.refused("block-line XL accept", "has not asked")
    jiaopei("neighbour XL request", "run 1s", "expect block-line XL asked", "block-line XL accept",
            "expect block-line XL accepted", "neighbour XL depart", "run 1s", "expect block-line XL arriving")
    jiaopei("route X XI", "run 1s", "occupy IAG", "run 1s", "occupy 7DG", "vacate IAG", "run 1s",
            "expect block-line XL arrived", "block-line XL restore", "expect block-line XL idle")


def test_64d_accident_button_forces_the_line_back_and_is_counted(jiaopei: Driver) -> None:
    jiaopei("block-line SL request", "run 4s", "block-line SL accident", "expect block-line SL idle")
    assert jiaopei.sim.interlocking.links["SL"].accidents == 1


# ---- platform screen doors (gaotie: P3 on 3G, P4 on 4G) -------------------------------------------------------
def test_signal_onto_platform_track_needs_doors_closed_and_locked_or_bypassed(gaotie: Driver) -> None:
    gaotie.sim.field.set_doors("P3:left", open_=True)
    gaotie.sim.field.doors_stuck.add("P3:left")
    gaotie("route X X3", "run 10s", "expect signal X H", "expect route X X3 locked")
    gaotie.sim.field.set_doors("P3:left", bypass=True)
    gaotie("run 1s", "expect signal X UU")


def test_losing_door_proof_closes_the_departure_signal(gaotie: Driver) -> None:
    gaotie("route X3 XFCK", "run 10s", "expect signal X3 L")
    gaotie.sim.field.set_doors("P3:left", open_=True)  # doors spring open (stuck)
    gaotie.sim.field.doors_stuck.add("P3:left")
    gaotie("run 1s", "expect signal X3 H", "expect alarm screen doors P3:left")


def test_doors_open_only_with_a_train_at_the_platform(gaotie: Driver) -> None:
    gaotie.refused("doors P3 open", "no train at platform P3")
    gaotie("occupy 3G", "doors P3 open", "run 1s")
    assert gaotie.sim.field.doors_open["P3:left"]
    gaotie("doors P3 close", "run 1s")
    assert not gaotie.sim.field.doors_open["P3:left"]


# ---- USU, automatic block, cab codes on gaotie --------------------------------------------------------------
def test_usu_over_no18_turnout_with_onward_route_open(gaotie: Driver) -> None:
    gaotie("route X X3", "run 10s", "expect signal X UU", "route X3 XFCK", "run 10s", "expect signal X3 L",
           "run 1s", "expect signal X USU")


def test_flasher_failure_degrades_usu_to_uu(gaotie: Driver) -> None:
    gaotie("route X X3", "route X3 XFCK", "run 12s", "expect signal X USU")
    gaotie.sim.field.set_flasher_failed("X", True)
    gaotie("run 1s", "expect signal X UU", "expect alarm flasher")


def test_departure_aspect_counts_clear_block_sections(gaotie: Driver) -> None:
    gaotie("route XI XFCK", "run 10s", "expect signal XI L", "occupy X3LQG", "run 1s", "expect signal XI LU",
           "occupy X2LQG", "run 1s", "expect signal XI U", "occupy X1LQG", "run 1s", "expect signal XI H")


def test_cab_codes_follow_the_signal_ahead_on_coded_sections(gaotie: Driver) -> None:
    gaotie("route X XI", "run 10s", "expect code IG HU", "route XI XFCK", "run 10s", "expect code IG L")

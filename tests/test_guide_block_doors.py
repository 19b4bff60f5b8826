"""Guide routes and guide total lock, 64D semi-automatic block, platform screen doors, automatic block signals."""

from __future__ import annotations

import pytest
from conftest import Driver

from liansuo.proving.oracle import Watch
from liansuo.simulation.sim import Simulation


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
    jiaopei("fault no-indication 7", "route X XI", "run 1s")
    jiaopei.refused("guide X", "turnout 7 has no indication")


def test_guide_needs_the_red_lamp_lit(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy 1DG", "run 1s")
    jiaopei("fault filament X lamp=H which=both", "run 1s")
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
    assert jiaopei.sim.interlocking.core.links["SL"].accidents == 1


# ---- platform screen doors (gaotie: P3 on 3G, P4 on 4G) -------------------------------------------------------
def test_signal_onto_platform_track_needs_doors_closed_and_locked_or_bypassed(gaotie: Driver) -> None:
    gaotie("fault psd-stuck P3", "route X X3", "run 10s", "expect signal X H", "expect route X X3 locked",
           "fault psd-bypass P3", "run 1s", "expect signal X UU")


def test_losing_door_proof_closes_the_departure_signal(gaotie: Driver) -> None:
    gaotie("route X3 XFCK", "run 10s", "expect signal X3 L", "fault psd-stuck P3", "run 1s", "expect signal X3 H",
           "expect alarm screen doors P3:right")


def test_doors_open_only_with_a_train_at_the_platform(gaotie: Driver) -> None:
    gaotie.refused("doors P3 open", "no train at platform P3")
    gaotie("occupy 3G", "doors P3 open", "run 4s")
    assert gaotie.sim.field.doors["P3:right"].is_open
    gaotie("doors P3 close", "run 5s")
    assert not gaotie.sim.field.doors["P3:right"].is_open


def test_doors_do_not_open_when_platform_occupancy_is_disturbed_or_close_when_gmj_failed(gaotie: Driver) -> None:
    gaotie("fault psd-no-open P3", "occupy 3G", "doors P3 open", "run 4s")
    assert not gaotie.sim.field.doors["P3:right"].is_open
    gaotie("repair psd-no-open P3", "fault psd-no-close P3", "doors P3 open", "run 4s", "doors P3 close", "run 5s")
    assert gaotie.sim.field.doors["P3:right"].is_open
    gaotie("route X3 XFCK", "run 10s", "expect signal X3 H")


# ---- USU, automatic block, cab codes on gaotie --------------------------------------------------------------
def test_usu_over_no18_turnout_with_onward_route_open(gaotie: Driver) -> None:
    gaotie("route X X3", "run 10s", "expect signal X UU", "route X3 XFCK", "run 10s", "expect signal X3 L",
           "run 1s", "expect signal X USU")


def test_flasher_failure_degrades_usu_to_uu(gaotie: Driver) -> None:
    gaotie("route X X3", "route X3 XFCK", "run 12s", "expect signal X USU")
    gaotie("fault flasher X", "run 3s", "expect signal X UU", "expect alarm flasher")


def test_classic_relay_flasher_bad_contact_is_silent(gaotie: Driver) -> None:
    """Chen Xinmei 2023 (docs/references.md): with the classic RC flasher a bad SNJ contact leaves the flashing lamp
    dark while SNJ keeps working, so the interlocking still commands USU and the signal silently shows a single
    yellow."""
    gaotie("route S S4", "route S4 SFCK", "run 15s", "expect signal S USU", "fault flasher S", "run 5s",
           "expect signal S USU", "expect no-alarm flasher")
    assert gaotie.sim.field.lit_lamps("S") == {"U2"}


def test_departure_aspect_counts_clear_block_sections(gaotie: Driver) -> None:
    gaotie("route XI XFCK", "run 10s", "expect signal XI L", "occupy X3LQG", "run 1s", "expect signal XI LU",
           "occupy X2LQG", "run 1s", "expect signal XI U", "occupy X1LQG", "run 1s", "expect signal XI H")


def test_cab_codes_follow_the_signal_ahead_on_coded_sections(gaotie: Driver) -> None:
    gaotie("route X XI", "run 10s", "expect code IG HU", "route XI XFCK", "run 10s", "expect code IG L")


def test_a_neighbour_that_accepted_our_train_cannot_ask_to_send_one() -> None:
    """Found by the suite's random runs on a fresh clone: the instructor's 'neighbour LINK request' was sent while the
    neighbour had accepted our train, so the neighbour's side showed the line no longer accepted while our starting
    signal stayed at L. A 64D machine asks to send a train only from its normal state."""
    sim = Simulation("jiaopei")
    watch = Watch(sim)
    watch.attach()
    assert sim.command("route XI S").ok and sim.command("block-line SL request").ok
    sim.run(6)
    assert sim.view.block_line("SL") == "permitted" and sim.aspect("XI") == "L"
    refused = sim.command("neighbour SL request")
    assert not refused.ok and "has accepted our train" in refused.message
    sim.run(2)
    assert sim.aspect("XI") == "L" and not watch.violations

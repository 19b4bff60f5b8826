"""Every fault kind at relay level (what the equipment does) and at interlocking level (what the CBI and the
operator see). Faults are injected through the command language, as an instructor does."""

from __future__ import annotations

from itertools import pairwise

import pytest
from conftest import Driver

from liansuo.simulation.sim import Simulation


@pytest.fixture
def gaotie() -> Driver:
    return Driver(Simulation("gaotie"))


# ---- track circuits ---------------------------------------------------------------------------------------------
def test_broken_rail_drops_the_track_relay_and_closes_a_signal_over_it(jiaopei: Driver) -> None:
    assert jiaopei.sim.field.track_up("IG")
    jiaopei("route X XI", "run 1s", "expect signal X U", "fault broken-rail IG at=200", "run 1s")
    assert not jiaopei.sim.field.track_up("IG") and jiaopei.sim.field.circuits["IG"].voltage < 1.0
    jiaopei("expect section IG occupied", "expect signal X H", "expect alarm signal X closed: section IG",
            "repair broken-rail IG", "run 1s", "expect section IG locked", "expect signal X H")


def test_poor_shunt_hides_a_standing_vehicle(jiaopei: Driver) -> None:
    jiaopei("axles car t-IG 600 602.5", "expect section IG occupied", "axles car clear",
            "fault poor-shunt IG ohm=1", "axles car t-IG 600 602.5", "expect section IG free")
    jiaopei.refused("fault poor-shunt IG", "already active")
    jiaopei("repair poor-shunt IG", "expect section IG occupied")


def test_low_ballast_gives_a_red_band(jiaopei: Driver) -> None:
    jiaopei("fault low-ballast IG ohm_km=0.05", "expect section IG occupied")
    jiaopei.refused("route X XI", "section IG is occupied")
    jiaopei("repair low-ballast IG", "expect section IG free", "route X XI")


def test_failed_insulation_at_a_switch_machine_is_a_red_band_on_its_section(jiaopei: Driver) -> None:
    jiaopei("fault insulation 5", "expect section 5DG occupied", "expect section 3DG free")
    jiaopei.refused("throw 5 reverse", "section 5DG is occupied")


def test_failed_insulated_joint_drops_both_neighbouring_relays(jiaopei: Driver) -> None:
    jiaopei("fault insulation J-71", "expect section 7DG occupied", "expect section 1DG occupied",
            "repair insulation J-71", "expect section 7DG free", "expect section 1DG free")


# ---- switch machines --------------------------------------------------------------------------------------------
def test_obstruction_leaves_the_turnout_without_indication_and_the_route_cannot_open(jiaopei: Driver) -> None:
    jiaopei("fault obstruction 1 mm=4", "route X X3", "run 10s", "expect turnout 1 none", "expect signal X H",
            "expect route X X3 setting")
    machine = jiaopei.sim.field.machines["1"]
    assert machine.rails == "reverse" and not machine.locked  # the rails moved but could not lock
    jiaopei("run 10s", "expect alarm turnout 1 did not reach reverse")


def test_obstruction_below_4mm_still_locks(jiaopei: Driver) -> None:
    jiaopei("fault obstruction 1 mm=2", "route X X3", "run 10s", "expect signal X UU")


def test_high_resistance_clutch_slips_and_turnout_never_arrives(jiaopei: Driver) -> None:
    jiaopei("fault high-resistance 5 N=4000", "throw 5 reverse", "run 5s")
    m = jiaopei.sim.field.machines["5"]
    assert m.running and m.clutch_slips and m.rails is None
    jiaopei("run 15s", "expect alarm turnout 5 did not reach reverse", "expect turnout 5 none")


def test_indication_lost_closes_the_signal_and_squeezed_turnout_alarm_after_30s(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "fault no-indication 7", "run 1s", "expect signal X H",
            "expect alarm turnout 7 has no indication", "run 31s", "expect alarm turnout 7 squeezed")


def test_squeezed_turnout_loses_its_lock(jiaopei: Driver) -> None:
    jiaopei("fault squeezed 5", "expect turnout 5 none")
    assert jiaopei.sim.field.machines["5"].rails == "reverse"


# ---- lamps and the flasher ---------------------------------------------------------------------------------------
def test_main_filament_broken_burns_on_backup_with_an_alarm_and_aspect_kept(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "fault filament X lamp=U which=main", "run 1s", "expect signal X U",
            "expect alarm main filament broken")
    assert "U" in jiaopei.sim.field.lit_lamps("X")


def test_both_filaments_broken_is_a_dark_lamp_and_the_signal_closes(jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "fault filament X lamp=U which=both", "run 1s", "expect signal X H",
            "expect alarm lamp(s) U dark")
    assert jiaopei.sim.field.lit_lamps("X") == {"H"}


def test_flasher_fault_makes_a_usu_route_show_uu(gaotie: Driver) -> None:
    gaotie("route X X3", "route X3 XFCK", "run 12s", "expect signal X USU", "fault flasher X", "run 3s",
           "expect signal X UU", "expect alarm flasher")


def test_usu_flashes_at_the_modelled_rate(gaotie: Driver) -> None:
    gaotie("route X X3", "route X3 XFCK", "run 12s", "expect signal X USU")
    phases = []
    for _ in range(80):  # 20 s sampled every 250 ms
        gaotie("run 250ms")
        phases.append("U" in gaotie.sim.field.lit_lamps("X"))
    flashes = sum(1 for a, b in pairwise(phases) if b and not a)
    assert 10 <= flashes <= 14  # 30-40 per minute -> 10-13 in 20 s


# ---- screen doors ------------------------------------------------------------------------------------------------
def test_psd_faults_at_relay_level(gaotie: Driver) -> None:
    doors = gaotie.sim.field.doors["P3:right"]
    gaotie("fault psd-stuck P3")
    assert not doors.pdkj
    gaotie("repair psd-stuck P3", "fault psd-bypass P3")
    assert doors.pdkj and doors.pdqcj


# ---- fault commands ------------------------------------------------------------------------------------------------
def test_fault_commands_refuse_with_reasons(jiaopei: Driver) -> None:
    jiaopei.refused("fault nonsense IG", "unknown fault kind")
    jiaopei.refused("fault broken-rail NOPE", "no section 'NOPE'")
    jiaopei.refused("fault capacitor IG", "not a ZPW-2000A section")
    jiaopei.refused("fault filament X lamp=Q", "one of U, L, H, U2, B")
    jiaopei.refused("fault obstruction 1 mm=abc", "must be a number")
    jiaopei.refused("fault obstruction 1 depth=3", "unknown parameter")
    jiaopei.refused("fault flasher X", "no USU flasher")
    jiaopei.refused("repair broken-rail IG", "no broken-rail fault on IG")
    jiaopei.refused("fault psd-stuck P1", "no platform")


def test_faults_lists_active_faults(jiaopei: Driver) -> None:
    jiaopei("fault broken-rail IG", "fault no-indication 3", "faults", "expect accepted no-indication 3")


def test_dead_capacitor_on_a_long_zpw_section_lowers_the_receive_voltage(gaotie: Driver) -> None:
    circuit = gaotie.sim.field.circuits["X2JG"]  # 1400 m, 14 capacitors
    healthy = circuit.voltage
    gaotie("fault capacitor X2JG n=7 mode=open", "run 1s")
    assert circuit.voltage < 0.95 * healthy  # the adjustment voltage falls
    gaotie("expect section X2JG free")  # still above the drop level: no red band
    gaotie("repair capacitor X2JG", "fault capacitor X2JG n=7 mode=short", "run 1s", "expect section X2JG occupied",
           "expect signal 1217 H")  # the block signal in rear of it closes
    gaotie.refused("fault capacitor IG n=99", "n must be a whole number from 1 to 7")


def test_route_over_sections_released_behind_a_train_can_be_set_before_the_train_route_ends(
        jiaopei: Driver) -> None:
    jiaopei("route X XI", "run 1s", "occupy IAG", "occupy 7DG", "run 1s", "vacate IAG", "occupy 1DG", "run 1s",
            "vacate 7DG", "run 1s", "expect section 7DG free", "expect route X XI locked")
    jiaopei("shunt D3 D1", "run 5s", "expect signal D3 B")  # 7DG only (and on into the neck): released behind the train
    jiaopei.refused("shunt D1 D3", "conflicting route")  # the shunting route now holds 7DG
    # a shunting movement from D1 to D3 would run on past D3 into 1DG, where the train still is
    jiaopei("release D3", "run 31s")  # the train in 1DG approach-locks D3: manual time release, 30 s for shunting
    jiaopei.refused("shunt D1 D3", "section 1DG")

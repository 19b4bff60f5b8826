"""Signal lamps with DJ proving, and the USU flasher (Chen Xinmei 2023, docs/references.md; 技规)."""

from __future__ import annotations

import math

import pytest

from liansuo.circuits.flasher import ElectronicFlasher, RelayFlasher
from liansuo.circuits.lamps import LampRelay, SignalLamp, SignalLamps

NOMINAL_RATE = 35.0


# --- lamps ---------------------------------------------------------------------------------------------------------
def test_lit_lamp_current_picks_dj_and_dark_lamp_drops_it() -> None:
    lamp = SignalLamp("U")
    assert 170.0 <= lamp.current_mA(True) <= 200.0
    assert lamp.current_mA(False) == 0.0
    assert lamp.apply(True)
    assert not lamp.apply(False)


def test_main_filament_break_switches_to_backup_and_alarms() -> None:
    lamp = SignalLamp("U")
    lamp.apply(True)
    lamp.break_filament("main")
    assert lamp.lit(True)
    assert 170.0 <= lamp.current_mA(True) <= 200.0
    assert lamp.apply(True)  # DJ still proves the lamp
    assert lamp.alarm and lamp.on_backup


def test_both_filaments_broken_lamp_dark_and_dj_down() -> None:
    lamp = SignalLamp("L")
    lamp.apply(True)
    lamp.break_filament("both")
    assert not lamp.lit(True)
    assert lamp.current_mA(True) == 0.0
    assert not lamp.apply(True)
    lamp.repair()
    assert lamp.apply(True) and not lamp.alarm


def test_dj_hysteresis_140_pick_40_release() -> None:
    dj = LampRelay()
    assert not dj.update(100.0)  # below pick-up from down
    assert dj.update(140.0)
    assert dj.update(100.0)  # held between release and pick-up
    assert dj.update(40.0)
    assert not dj.update(39.0)
    assert dj.dj_up(150.0, previous_up=False) and not dj.dj_up(30.0, previous_up=True)


def test_signal_lamps_prove_exactly_the_commanded_lamps() -> None:
    lamps = SignalLamps(["L", "U", "H", "2U", "B"])
    assert lamps.apply({"U", "2U"}) == {"L": False, "U": True, "H": False, "2U": True, "B": False}
    assert lamps.lit() == {"U", "2U"}
    assert lamps.apply({"H"}) == {"L": False, "U": False, "H": True, "2U": False, "B": False}


def test_signal_lamps_filament_faults_and_repair() -> None:
    lamps = SignalLamps(["U", "2U"])
    lamps.apply({"U", "2U"})
    lamps.break_filament("2U", "main")
    assert lamps.proving()["2U"] and lamps.alarms() == ["2U: main filament broken, lit on backup filament"]
    lamps.break_filament("2U", "backup")
    assert not lamps.proving()["2U"]  # the second yellow is dark: the interlocking sees it at once
    assert lamps.lit() == {"U"}
    lamps.repair("2U")
    assert lamps.proving()["2U"] and lamps.alarms() == []


def test_broken_backup_alone_is_latent() -> None:
    lamps = SignalLamps(["H"])
    lamps.break_filament("H", "backup")
    assert lamps.apply({"H"}) == {"H": True}
    assert lamps.alarms() == []


def test_signal_lamps_refuse_unknown_names() -> None:
    lamps = SignalLamps(["U"])
    with pytest.raises(KeyError, match="no lamp"):
        lamps.apply({"G"})
    with pytest.raises(ValueError):
        lamps["U"].break_filament("left")  # type: ignore[arg-type]
    with pytest.raises(ValueError, match="twice"):
        SignalLamps(["U", "U"])


# --- classic relay flasher: rate from the components -------------------------------------------------------------
def test_default_rate_35_per_minute_50_percent_duty() -> None:
    f = RelayFlasher()
    assert 30.0 <= f.rate_per_min() <= 40.0
    assert f.rate_per_min() == pytest.approx(NOMINAL_RATE, abs=0.3)
    assert f.duty() == pytest.approx(0.5, abs=0.01)
    assert f.period_s() == pytest.approx(60.0 / 35.0, rel=0.01)  # 1.714 s


def test_relay_thresholds_are_the_jwxc_1700_figures() -> None:
    f = RelayFlasher()
    assert (f.pickup_V, f.drop_V, f.coil_ohm, f.supply_V) == (16.8, 3.4, 850.0, 24.0)
    assert f.pick_coil_V == pytest.approx(21.47, abs=0.01)  # 24 V x 850 / (100 + 850)


@pytest.mark.parametrize("tolerance", [0.9, 1.1])
def test_ten_percent_capacitor_tolerance_stays_in_the_30_40_band(tolerance: float) -> None:
    assert 30.0 <= RelayFlasher(capacitance_F=680e-6 * tolerance).rate_per_min() <= 40.0


@pytest.mark.parametrize("tolerance", [0.75, 1.25])
def test_out_of_tolerance_capacitor_leaves_the_band_until_trimmed(tolerance: float) -> None:
    f = RelayFlasher(capacitance_F=680e-6 * tolerance)
    assert not 30.0 <= f.rate_per_min() <= 40.0
    assert f.trim()
    assert f.rate_per_min() == pytest.approx(NOMINAL_RATE, rel=1e-3)
    assert f.duty() == pytest.approx(0.5, abs=1e-3)


def test_trim_cannot_save_a_far_too_large_capacitor() -> None:
    f = RelayFlasher(capacitance_F=1000e-6)  # the dark phase stays above 0.857 s even with R3 = 0
    assert not f.trim()
    assert f.rate_per_min() < NOMINAL_RATE


def test_rate_follows_the_components_in_the_right_direction() -> None:
    base = RelayFlasher()
    assert RelayFlasher(capacitance_F=1000e-6).rate_per_min() < base.rate_per_min()
    longer_lit = RelayFlasher(r1_ohm=1600.0)
    assert longer_lit.lit_time_s() > base.lit_time_s() and longer_lit.dark_time_s() == pytest.approx(
        base.dark_time_s())
    longer_dark = RelayFlasher(r3_ohm=200.0)
    assert longer_dark.dark_time_s() > base.dark_time_s()
    assert longer_lit.rate_per_min() < base.rate_per_min() and longer_dark.rate_per_min() < base.rate_per_min()


def test_pick_coil_too_weak_never_flashes_and_snjj_drops() -> None:
    f = RelayFlasher(r3_ohm=400.0)  # 24 V x 850 / 1250 = 16.3 V < 16.8 V pick-up
    assert f.rate_per_min() == 0.0
    f.energise(True)
    f.step(3.0)
    assert not f.snj_up and not f.healthy


# --- classic relay flasher: running ------------------------------------------------------------------------------
def run(f: RelayFlasher | ElectronicFlasher, seconds: float, dt: float) -> tuple[list[float], float]:
    """Rising edges of phase_on and the fraction of samples lit."""
    edges: list[float] = []
    was_on = f.phase_on
    lit = 0
    steps = round(seconds / dt)
    for _ in range(steps):
        f.step(dt)
        if f.phase_on and not was_on:
            edges.append(f.time_s)
        was_on = f.phase_on
        lit += f.phase_on
    return edges, lit / steps


@pytest.mark.parametrize("flasher", [RelayFlasher, ElectronicFlasher])
def test_phase_on_toggles_at_the_modelled_rate(flasher: type[RelayFlasher] | type[ElectronicFlasher]) -> None:
    f = flasher()
    f.energise(True)
    edges, lit_fraction = run(f, 60.0, 0.005)
    assert abs(len(edges) - f.rate_per_min()) <= 1.0
    period = (edges[-1] - edges[1]) / (len(edges) - 2)
    assert period == pytest.approx(60.0 / f.rate_per_min(), rel=0.01)
    assert lit_fraction == pytest.approx(0.5, abs=0.02)
    assert f.healthy


def test_relay_flasher_counts_the_same_at_the_interlocking_cycle() -> None:
    fine, coarse = RelayFlasher(), RelayFlasher()
    fine.energise(True)
    coarse.energise(True)
    run(fine, 60.0, 0.001)
    run(coarse, 60.0, 0.25)  # SNJ switches at its exact threshold crossings inside a long step
    assert coarse.transitions == fine.transitions
    assert coarse.capacitor_V == pytest.approx(fine.capacitor_V, rel=1e-6)


def test_first_pick_up_is_slower_than_steady_flashing() -> None:
    f = RelayFlasher()
    f.energise(True)
    edges, _ = run(f, 5.0, 0.001)
    assert edges[0] > f.dark_time_s()  # the capacitor starts empty (Chen Xinmei: first pick-up is the longer one)


def test_bad_contact_classic_flasher_stays_healthy_with_the_lamp_dark() -> None:
    f = RelayFlasher(bad_contact=True)
    dj = LampRelay(up=True)  # the lamp was lit steadily (U) before the signal changed to USU
    f.energise(True)
    moves_before = f.transitions
    phases_on = 0
    for _ in range(round(10.0 / 0.01)):
        f.step(0.01)
        assert f.healthy  # SNJJ stays up: the interlocking keeps USU
        assert not f.lamp_lit  # the flashing lamp shows nothing: the driver sees a single yellow
        phases_on += f.phase_on
        dj.update(f.lamp_current_mA)
        assert dj.up  # the dim current keeps DJ up: no lamp failure seen either
    assert f.transitions - moves_before >= 10  # SNJ still flashing
    assert phases_on > 0


def test_healthy_classic_flasher_lamp_current_keeps_dj_up_through_the_dark_phase() -> None:
    f = RelayFlasher()
    dj = LampRelay()
    f.energise(True)
    seen_dim = False
    for _ in range(1000):
        f.step(0.01)
        dj.update(f.lamp_current_mA)
        seen_dim |= f.lamp_current_mA < 140.0 and f.time_s > 1.0
        if f.time_s > 1.0:
            assert dj.up
        assert f.lamp_lit == f.phase_on
    assert seen_dim


def test_stuck_snj_is_noticed_by_snjj() -> None:
    f = RelayFlasher()
    f.energise(True)
    f.step(3.0)
    assert f.healthy
    f.snj_stuck = True
    f.step(f.snjj_hold_s + 0.1)
    assert not f.healthy
    f.repair()
    f.energise(False)
    f.energise(True)
    f.step(5.0)
    assert f.healthy


def test_de_energised_flasher_is_dark_and_not_proving() -> None:
    for f in (RelayFlasher(), ElectronicFlasher()):
        f.energise(True)
        f.step(2.0)
        f.energise(False)
        f.step(1.0)
        assert not f.healthy and not f.lamp_lit and f.lamp_current_mA == 0.0


# --- electronic flasher ----------------------------------------------------------------------------------------------
def test_electronic_flasher_fixed_35_per_minute() -> None:
    f = ElectronicFlasher()
    assert f.rate_per_min() == NOMINAL_RATE and f.duty() == 0.5


def test_electronic_flasher_healthy_while_pulsing() -> None:
    f = ElectronicFlasher()
    f.energise(True)
    for _ in range(round(120.0 / 0.25)):
        f.step(0.25)
        assert f.healthy


@pytest.mark.parametrize("inject_at", [0.0, 5.0, 5.5, 6.2])
def test_electronic_flasher_drops_snjj_within_two_periods_of_a_bad_contact(inject_at: float) -> None:
    f = ElectronicFlasher()
    f.energise(True)
    f.step(inject_at)
    assert f.healthy
    f.bad_contact = True
    dt = 0.05
    while f.healthy:
        f.step(dt)
        assert not f.lamp_lit
        assert f.time_s - inject_at <= 2.0 * f.period + dt, "no detection within two periods"
    assert not f.snj_up and not f.snjj_up
    next_pulse_due = math.ceil(inject_at / f.period) * f.period
    assert f.time_s >= next_pulse_due  # it waits for a pulse that does not come: no hair trigger


def test_electronic_flasher_recovers_after_repair_and_re_energising() -> None:
    f = ElectronicFlasher(bad_contact=True)
    f.energise(True)
    f.step(5.0)
    assert not f.healthy
    f.repair()
    f.energise(False)
    f.energise(True)
    f.step(10.0)
    assert f.healthy


def test_same_fault_two_verdicts() -> None:
    classic, electronic = RelayFlasher(bad_contact=True), ElectronicFlasher(bad_contact=True)
    for f in (classic, electronic):
        f.energise(True)
        f.step(5.0)
        assert not f.lamp_lit
    assert classic.healthy  # silent USU -> UU degradation in the field
    assert not electronic.healthy  # the interlocking is told and shows UU itself

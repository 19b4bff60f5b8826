"""97-type 25 Hz phase-sensitive track circuit: the figures a maintainer checks (维规, docs/references.md).

Adjustment >= 18 V on the track coil (typical 15-26 V), residual <= 7.4 V with the 0.06 ohm standard shunt anywhere
in the section, lengths up to 1500 m, phase selectivity, and the red band for broken rail / failed insulation.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import replace

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from liansuo.circuits.phase25.model import (
    Phase25HzCircuit,
    Phase25HzFaults,
    Phase25HzParams,
    adjusted_params,
)

LENGTHS = [50, 100, 150, 200, 300, 400, 500, 600, 700, 800, 900, 1000, 1100, 1200, 1300, 1400, 1500]
STANDARD_SHUNT = 0.06
ADJUSTMENT_MIN = 18.0
RESIDUAL_MAX = 7.4


def positions(length: float, n: int = 41) -> list[float]:
    return [length * i / (n - 1) for i in range(n)]


@pytest.mark.parametrize("length", LENGTHS)
def test_adjustment_voltage_in_the_typical_band_and_relay_up(length: float) -> None:
    circuit = Phase25HzCircuit(length)
    state = circuit.adjustment()
    assert circuit.params.ballast_ohm_km == 0.6  # checked at the design-minimum ballast
    assert ADJUSTMENT_MIN <= state.voltage_V <= 26.0
    assert state.relay_up
    assert abs(state.phase_error_deg) <= 20.0  # well inside the +-30 degree window at every length


@pytest.mark.parametrize("length", LENGTHS)
def test_adjustment_still_18V_with_the_supply_10_percent_low(length: float) -> None:
    params = replace(adjusted_params(length), supply_V=198.0)
    state = Phase25HzCircuit(length, params).adjustment()
    assert state.voltage_V >= ADJUSTMENT_MIN - 1e-6
    assert state.relay_up


@pytest.mark.parametrize("length", LENGTHS)
def test_standard_shunt_residual_at_start_end_and_between(length: float) -> None:
    circuit = Phase25HzCircuit(length)
    for x in positions(length):
        state = circuit.evaluate([(x, STANDARD_SHUNT)])
        assert state.voltage_V <= RESIDUAL_MAX, f"{length} m, shunt at {x:.0f} m: {state.voltage_V:.2f} V"
        assert not state.relay_up_after(True), f"{length} m, shunt at {x:.0f} m: relay held up"


@settings(max_examples=300, deadline=None)
@given(length=st.floats(50.0, 1500.0), where=st.floats(0.0, 1.0), ballast=st.sampled_from([0.6, 1.0, 3.0, math.inf]))
def test_standard_shunt_anywhere_drops_the_relay_at_any_ballast(length: float, where: float, ballast: float) -> None:
    # the tap is set at the design-minimum ballast; dry ballast raises both adjustment and residual
    params = replace(adjusted_params(length), ballast_ohm_km=ballast)
    state = Phase25HzCircuit(length, params).evaluate([(where * length, STANDARD_SHUNT)])
    assert state.voltage_V <= RESIDUAL_MAX
    assert not state.relay_up_after(True)


def test_residual_worst_case_figure_is_well_below_the_limit() -> None:
    worst = max(Phase25HzCircuit(length).max_residual_V() for length in LENGTHS)
    assert 3.0 < worst < 5.0  # about 4.4 V against the 7.4 V limit: the standard shunt margin


def test_short_section_matches_the_plain_voltage_divider() -> None:
    # 1 m, no leakage: feed EMF through Rx onto the relay load, stepped up 45 times
    p = replace(Phase25HzParams(feed_tap_V=3.0), ballast_ohm_km=math.inf)
    circuit = Phase25HzCircuit(0.001, p)
    e_rail = 3.0 / 3.0
    zs = 4.4 / 9.0
    zl = cmath.rect(800.0, math.radians(25.0)) / 45.0**2
    expected = abs(e_rail * zl / (zs + zl)) * 45.0
    assert circuit.adjustment().voltage_V == pytest.approx(expected, rel=1e-4)


def test_longer_sections_need_a_higher_feed_tap() -> None:
    taps = [adjusted_params(length).feed_tap_V for length in LENGTHS]
    assert taps == sorted(taps)
    assert taps[-1] > 2 * taps[0]


@pytest.mark.parametrize("length", [50, 400, 1000, 1500])
@pytest.mark.parametrize("shift", [180.0, 90.0, -90.0, 60.0, -60.0])
def test_wrong_phase_never_picks_up(length: float, shift: float) -> None:
    params = replace(adjusted_params(length), feed_phase_deg=shift)
    state = Phase25HzCircuit(length, params).adjustment()
    assert state.voltage_V >= ADJUSTMENT_MIN  # plenty of voltage, wrong phase
    assert not state.relay_up
    if abs(shift) >= 90.0:
        assert not state.relay_up_after(True)  # no torque (90) or reverse torque (180): an up relay drops too
    if shift == 180.0:
        assert state.effective_V < 0.0


def test_local_supply_lost_relay_cannot_pick_up() -> None:
    circuit = Phase25HzCircuit(800, replace(adjusted_params(800), local_V=0.0))
    assert not circuit.adjustment().relay_up_after(True)


@pytest.mark.parametrize("length", [50, 700, 1500])
def test_broken_rail_anywhere_drops_the_relay(length: float) -> None:
    circuit = Phase25HzCircuit(length)
    for x in positions(length, 11):
        state = circuit.evaluate([], Phase25HzFaults(broken_rail_at_m=x))
        assert state.voltage_V == 0.0
        assert not state.relay_up_after(True)
    outside = circuit.evaluate([], Phase25HzFaults(broken_rail_at_m=length + 10.0))
    assert outside.relay_up  # a break in the next section is not ours


@pytest.mark.parametrize("length", [50, 700, 1500])
@pytest.mark.parametrize("at", [None, 0.0])
def test_failed_insulation_gives_a_red_band(length: float, at: float | None) -> None:
    state = Phase25HzCircuit(length).evaluate([], Phase25HzFaults(insulation_short=True, insulation_short_at_m=at))
    assert state.voltage_V < RESIDUAL_MAX
    assert not state.relay_up_after(True)


def test_feed_lost_drops_the_relay() -> None:
    assert not Phase25HzCircuit(600).evaluate([], Phase25HzFaults(feed_lost=True)).relay_up_after(True)


def test_low_ballast_holds_then_red_band() -> None:
    circuit = Phase25HzCircuit(1500)
    wet = circuit.evaluate([], Phase25HzFaults(ballast_ohm_km=0.3))
    assert circuit.params.drop_V <= wet.effective_V < circuit.params.pickup_V
    assert wet.relay_up_after(True)  # an up relay holds (hysteresis) ...
    assert not wet.relay_up_after(False)  # ... but a dropped one does not pick up again
    flooded = circuit.evaluate([], Phase25HzFaults(ballast_ohm_km=0.2))
    assert not flooded.relay_up_after(True)  # red band


@pytest.mark.parametrize("length", [50, 300, 800, 1500])
def test_failed_joint_with_alternating_polarity_is_safe(length: float) -> None:
    circuit = Phase25HzCircuit(length)
    leak = Phase25HzFaults(joint_failure=True, neighbour_phase_deg=180.0)
    assert not circuit.evaluate([], leak).relay_up_after(True)  # the failed joint shows as a red band
    for x in positions(length, 21):
        occupied = circuit.evaluate([(x, STANDARD_SHUNT)], leak)
        assert not occupied.relay_up, f"neighbour's supply picked the relay with a train at {x:.0f} m"


def test_failed_joint_without_polarity_alternation_can_show_clear_under_a_train() -> None:
    circuit = Phase25HzCircuit(1500)
    same_phase = Phase25HzFaults(joint_failure=True, neighbour_phase_deg=0.0)
    assert any(circuit.evaluate([(x, STANDARD_SHUNT)], same_phase).relay_up for x in positions(1500, 21))


@pytest.mark.parametrize("length", [50, 400, 800, 1500])
def test_poor_shunt_limit(length: float) -> None:
    circuit = Phase25HzCircuit(length)
    limit = circuit.poor_shunt_limit_ohm()
    assert 0.1 < limit < 0.3
    worst_hold = max(circuit.evaluate([(x, 1.0)]).effective_V for x in positions(length))
    assert worst_hold >= circuit.params.drop_V  # a 1 ohm poor shunt leaves the relay up somewhere
    for x in positions(length):
        assert not circuit.evaluate([(x, limit * 0.95)]).relay_up_after(True)


def test_more_axles_shunt_harder() -> None:
    circuit = Phase25HzCircuit(1000)
    one = circuit.evaluate([(500.0, 0.15)]).voltage_V
    train = circuit.evaluate([(500.0 + 2.5 * i, 0.15) for i in range(8)]).voltage_V
    assert train < one
    assert not circuit.evaluate([(500.0 + 2.5 * i, 0.15) for i in range(8)]).relay_up_after(True)


def test_the_relay_follows_a_train_through_the_section() -> None:
    """The relay starts down (fail-safe) and each evaluation decides from the previous state (the hysteresis)."""
    circuit = Phase25HzCircuit(600)
    up = circuit.evaluate([]).relay_up_after(False)
    assert up
    for x in (0.0, 150.0, 300.0, 599.0):
        up = circuit.evaluate([(x, STANDARD_SHUNT)]).relay_up_after(up)
        assert not up
    state = circuit.evaluate([])
    assert state.relay_up_after(up) and state.voltage_V >= ADJUSTMENT_MIN


def test_shunts_outside_the_section_are_ignored() -> None:
    circuit = Phase25HzCircuit(400)
    clear = circuit.adjustment().voltage_V
    assert circuit.evaluate([(-5.0, 0.06), (420.0, 0.06)]).voltage_V == pytest.approx(clear)


def test_invalid_length_is_refused() -> None:
    with pytest.raises(ValueError, match="length"):
        Phase25HzCircuit(0.0)


def test_phase_window_blocks_pick_up_even_with_enough_quadrature_voltage() -> None:
    base = adjusted_params(300)
    params = replace(base, feed_tap_V=base.feed_tap_V * 2.0, feed_phase_deg=45.0)
    state = Phase25HzCircuit(300, params).adjustment()
    assert abs(state.phase_error_deg) > params.phase_window_deg
    assert state.effective_V >= params.pickup_V  # torque would be enough ...
    assert not state.relay_up  # ... but the phase is outside the +-30 degree window

"""The ZPW-2000A system model's ends (circuits/zpw/ends.py): tuning units designed by their two resonances, the tuning
area and the small track (小轨道) with its check, the cable; and the whole section against an independent solver (a
nodal analysis of a lumped ladder, which shares no code with the chain products it checks)."""

from __future__ import annotations

import cmath
import math

import numpy as np
import pytest

from liansuo.circuits.zpw.ends import PARTNER, section_ends, unit
from liansuo.circuits.zpw.model import ZpwCircuit, ZpwFaults, standard_positions
from liansuo.circuits.zpw.params import DEFAULT_PARAMS, ZpwParams, carrier_frequency_Hz

P = DEFAULT_PARAMS
BASES = ("1700", "2000", "2300", "2600")


@pytest.mark.parametrize("base", BASES)
def test_tuning_units_zero_at_the_neighbour_and_pole_with_the_tuning_area(base: str) -> None:
    """Each unit is a near-short at the neighbour's carrier; at its own carrier it is capacitive and cancels the
    reactance of the rest of the tuning area (half the rail, the 33.5 uH air-core coil, half the rail, the
    neighbour's unit), computed here from the rail constants alone."""
    u = unit(P, base)
    assert abs(u.impedance(float(PARTNER[base]))) < 0.06  # ohm: the zero
    fo = float(base)
    w = 2 * math.pi * fo
    i = BASES.index(base)
    x_half = w * P.rail_inductance_mH_km[i] * 1e-3 * P.tuning_area_m / 2000.0
    x_coil = w * P.air_core_uH * 1e-6
    x_rest = x_half + x_coil * x_half / (x_coil + x_half)  # the neighbour's unit an ideal short
    assert u.impedance(fo).imag == pytest.approx(-x_rest, rel=0.01)
    if fo < float(PARTNER[base]):  # F1: a series L-C resonating at the partner carrier
        assert 1 / (2 * math.pi * math.sqrt(u.l_H * u.c_F)) == pytest.approx(float(PARTNER[base]))


@pytest.mark.parametrize("carrier", ["1700-1", "2000-2", "2300-1", "2600-2"])
def test_the_tuning_area_is_a_few_ohm_at_its_own_carrier(carrier: str) -> None:
    """The pole: the transmitter's own carrier sees a few ohm across the rails in the tuning area, so the signal goes
    into the main track; with insulated joints there is no tuning area."""
    ends = section_ends(P, carrier)
    assert 1.5 < abs(1 / ends.tx_end_S) < 6.0
    assert ends.small_track != 0
    insulated = section_ends(ZpwParams(tuning_units=False), carrier)
    assert insulated.tx_end_S == 0 and insulated.small_track == 0


def test_small_track_falls_on_a_broken_rail_or_a_train_in_the_tuning_area() -> None:
    circuit = ZpwCircuit(1400.0, "2600-1", standard_positions(1400.0))
    healthy = circuit.small_track_mV()
    assert healthy == pytest.approx(P.adjust_mV)  # adjusted like the main track
    for at in (3.0, 10.0, 20.0, 27.0):
        assert circuit.small_track_mV(tuning_break_m=at) < 0.05 * healthy  # the broken rail is detected
    # a standard shunt in the half of the tuning area on the section's side drops the small track under 153 mV;
    # in the far half, next to the neighbour's unit (a near-short at this carrier already), it moves it little
    for at in (0.0, 5.0, 10.0, 14.5):
        assert circuit.small_track_mV(tuning_shunt_m=at) < P.drop_mV
    assert circuit.small_track_mV(tuning_shunt_m=27.0) > 0.8 * healthy
    assert circuit.small_track_mV([(1390.0, 0.15)]) < 0.3 * healthy  # a train at the transmitter end
    assert circuit.small_track_mV([(100.0, 0.15)]) == pytest.approx(healthy, rel=0.05)  # far from it: little change


def test_an_open_capacitor_moves_the_small_track_both_ways_through_the_cable() -> None:
    """Luo Ying 2023's small-track rows: an open capacitor raises the small track for some capacitors and lowers it
    for others, by tens of percent; the cable's own impedance makes that, without it the change is a few percent."""
    caps = standard_positions(1400.0)
    for params, low, high in ((P, 15.0, 80.0), (P.__class__(cable_km=0.0), 0.0, 8.0)):
        changes = []
        for base in BASES:
            circuit = ZpwCircuit(1400.0, base, caps, params)
            healthy = circuit.small_track_mV()
            changes += [circuit.small_track_mV(faults=ZpwFaults(capacitors={k: "open"})) / healthy * 100 - 100
                        for k in range(1, 15)]
        assert low <= max(changes) <= high and low <= -min(changes) <= high


# ---- an independent solver: nodal analysis of a lumped ladder -------------------------------------------------------
def _cable_equivalent(f: float, termination: complex | None, cells: int = 400) -> tuple[complex, complex]:
    """Lumped pi-ladder of the cable, equipment at the near end: (Thevenin EMF per volt of source, impedance) at the
    track end for a source of ``P.source_ohm`` (termination None), or (0, input impedance) for a load."""
    w = 2 * math.pi * f
    d = P.cable_km / cells
    z = complex(P.cable_ohm_km, w * P.cable_mH_km * 1e-3) * d
    y = complex(0.0, w * P.cable_nF_km * 1e-9) * d
    zt = P.source_ohm if termination is None else termination
    zin = zt
    for _ in range(cells):
        zin = 1 / (1 / zin + y / 2)
        zin = 1 / (1 / (zin + z) + y / 2)
    if termination is not None:
        return 0j, zin
    v, i = 1 + 0j, 0j  # open track end: walk back to the equipment
    for _ in range(cells):
        i = i + v * y / 2
        v = v + i * z
        i = i + v * y / 2
    return 1 / (v + P.source_ohm * i), zin


def _nodal(length: float, carrier: str, caps: list[float], faults: dict[int, str], shunt: tuple[float, float] | None,
           tuning_break: float | None) -> dict[str, complex]:
    f = carrier_frequency_Hz(carrier)
    w = 2 * math.pi * f
    base = carrier.partition("-")[0]
    i = BASES.index(base)
    z_km = complex(P.rail_resistance_ohm_km[i], w * P.rail_inductance_mH_km[i] * 1e-3)
    y_km = 1.0 / P.ballast_ohm_km
    ta = P.tuning_area_m
    xs = sorted({*np.arange(-ta, 0.0, 0.5), *np.arange(0.0, length, 1.0), *np.arange(length, length + ta + 1e-9, 0.5),
                 length, *caps, *([shunt[0]] if shunt else [])})
    xs = [float(x) for x in xs]
    n = len(xs)
    index = {round(x, 6): k for k, x in enumerate(xs)}
    y = np.zeros((n, n), dtype=complex)
    inject = np.zeros(n, dtype=complex)

    def node(x: float) -> int:
        return index[round(x, 6)]

    def admit(a: int, b: int | None, value: complex) -> None:
        y[a, a] += value
        if b is not None:
            y[b, b] += value
            y[a, b] -= value
            y[b, a] -= value

    brk = None if tuning_break is None else length + tuning_break
    for k in range(n - 1):
        d_km = (xs[k + 1] - xs[k]) / 1000.0
        series = z_km * d_km
        if brk is not None and xs[k] <= brk < xs[k + 1]:
            series += P.broken_rail_ohm
        admit(k, k + 1, 1 / series)
        admit(k, None, y_km * d_km / 2)
        admit(k + 1, None, y_km * d_km / 2)
    c = (P.capacitance_uF[i]) * 1e-6
    for number, x in enumerate(caps, start=1):
        factor = {"ok": 1.0, "half": 0.5, "open": 0.0}[faults.get(number, "ok")]
        admit(node(x), None, complex(0.0, w * c * factor))
    coil = complex(w * P.air_core_uH * 1e-6 / P.tuning_q, w * P.air_core_uH * 1e-6)
    n2 = P.matching_ratio**2
    emf, z_source = _cable_equivalent(f, None)
    _, z_receiver = _cable_equivalent(f, P.receiver_ohm)
    z0 = cmath.sqrt(z_km / y_km)
    own, other = unit(P, base).impedance(f), unit(P, PARTNER[base]).impedance(f)
    for p_end, q_end, mid, far_equipment in ((0.0, -ta, -ta / 2, z_source), (length, length + ta, length + ta / 2,
                                                                               z_receiver)):
        admit(node(p_end), None, 1 / own)
        admit(node(mid), None, 1 / coil)
        admit(node(q_end), None, 1 / other + 1 / z0 + n2 / far_equipment)
    admit(node(0.0), None, n2 / z_receiver)  # the receiver
    admit(node(length), None, n2 / z_source)  # the transmitter: Norton
    inject[node(length)] = P.transmitter_V * emf / P.matching_ratio / (z_source / n2)
    if shunt:
        admit(node(shunt[0]), None, 1 / shunt[1])
    v = np.linalg.solve(y, inject)
    out = {"rx": v[node(0.0)], "small": v[node(length + ta)]}
    if shunt:
        k = node(shunt[0])
        d_km = (xs[k + 1] - xs[k]) / 1000.0
        out["cab"] = (v[k + 1] - v[k]) / (z_km * d_km) - v[k] * y_km * d_km / 2
    return out


@pytest.mark.parametrize(("carrier", "faults", "shunt", "tuning_break"), [
    ("1700-1", {}, None, None), ("2600-2", {2: "open"}, None, None), ("2300-1", {}, (120.0, 0.15), None),
    ("2000-1", {3: "half"}, (333.0, 0.15), None), ("2600-1", {}, None, 10.0),
])
def test_whole_section_against_an_independent_nodal_solver(carrier: str, faults: dict[int, str],
                                                           shunt: tuple[float, float] | None,
                                                           tuning_break: float | None) -> None:
    """Receiver rail voltage, cab current and small track of a 400 m section: the chain products with exact line
    two-ports against nodal analysis of pi-cells of 1 m (0.5 m in the tuning areas, 25 m of cable), to 2e-5."""
    caps = standard_positions(400.0)
    circuit = ZpwCircuit(400.0, carrier, caps)
    f = ZpwFaults(capacitors=faults)
    nodal = _nodal(400.0, carrier, caps, faults, shunt, tuning_break)
    shunts = [shunt] if shunt else []
    state = circuit.evaluate(shunts, f)
    if tuning_break is None:  # the main track's figures take no fault in the tuning area
        assert state.voltage_mV / circuit.gain_mV_per_V == pytest.approx(abs(nodal["rx"]), rel=2e-5)
    if shunt:
        assert state.cab_current_mA == pytest.approx(abs(nodal["cab"]) * 1000.0, rel=2e-5)
    small = circuit.small_track_mV(shunts, f, tuning_break_m=tuning_break) / circuit.small_track_gain_mV_per_V
    assert small == pytest.approx(abs(nodal["small"]), rel=2e-5, abs=1e-9)

"""The ends of a ZPW-2000A section: tuning areas (调谐区), cable (电缆) and matching transformers (匹配变压器).

Each end of a section is an electrical insulation joint, a tuning area of ``tuning_area_m`` (29 m) of rail: at the
section's side the tuning unit of its own carrier (调谐单元 BA), in the middle the air-core coil (空芯线圈 SVA), at the
far side the tuning unit of the neighbour's carrier. The carriers alternate along a line (TB/T 3206: 1700 / 2300 Hz on
one line, 2000 / 2600 Hz on the other), so the neighbour's carrier is the partner of the own one (:data:`PARTNER`).

The tuning units are designed by two resonances (TB/T 3206 and the ZPW-2000A system description, docs/zpw2000a.md):

* **zero** (零阻抗): the unit is series-resonant at the neighbour's carrier, a near-short that keeps the neighbour's
  signal out of the section;
* **pole** (极阻抗): at its own carrier the unit is capacitive and, in parallel with the rest of the tuning area (half
  the rail, the air-core coil, the other half and the neighbour's unit, a near-short at this carrier), parallel-
  resonant: a few ohm across the rails, so the section's own signal goes into its main track.

A unit for a low carrier (1700, 2000 Hz; type F1) is a series L1-C1; both conditions fix L1 and C1. A unit for a high
carrier (2300, 2600 Hz; type F2) is a series L2-C2 (the zero) with C3 across it (the pole): the two conditions fix
C2 and C3 for a chosen L2 (``f2_inductance_uH``). Losses: the inductors have the quality factor ``tuning_q``.

The transmitter (EMF ``transmitter_V`` behind ``source_ohm``) and the receiver (input ``receiver_ohm``) sit in the
equipment room, ``cable_km`` of cable away (an exact uniform-line two-port with the cable's primary constants), behind
a matching transformer of ``matching_ratio`` : 1 at the track. The small track (小轨道) of a section is the tuning area
at its transmitter end: the neighbour's receiver reads the section's carrier across the rails at the far side of it.

Only the standard library: the parameters are a :class:`.params.ZpwParams`.
"""

from __future__ import annotations

import cmath
import math
from dataclasses import dataclass
from functools import lru_cache

from liansuo.circuits.zpw.params import ZpwParams, carrier_frequency_Hz

PARTNER = {"1700": "2300", "2300": "1700", "2000": "2600", "2600": "2000"}  # TB/T 3206 frequency plan
Chain = tuple[complex, complex, complex, complex]  # (A, B, C, D): [V, I] near = [[A, B], [C, D]] [V, I] far
IDENTITY: Chain = (1 + 0j, 0j, 0j, 1 + 0j)
DRY_S_KM = 1e-12  # leakage of dry (infinite) ballast


def chain(a: Chain, b: Chain) -> Chain:
    """The two-port ``a`` followed by ``b`` (matrix product)."""
    return (a[0] * b[0] + a[1] * b[2], a[0] * b[1] + a[1] * b[3], a[2] * b[0] + a[3] * b[2], a[2] * b[1] + a[3] * b[3])


def line(z_km: complex, y_km: complex, length_km: float) -> Chain:
    """Exact uniform-line two-port of ``length_km`` with series ``z_km`` and shunt ``y_km`` per km."""
    if length_km <= 0.0:
        return IDENTITY
    gamma, zc = cmath.sqrt(z_km * y_km), cmath.sqrt(z_km / y_km)
    ch, sh = cmath.cosh(gamma * length_km), cmath.sinh(gamma * length_km)
    return (ch, zc * sh, sh / zc, ch)


def shunt(y: complex) -> Chain:
    return (1 + 0j, 0j, y, 1 + 0j)


def series(z: complex) -> Chain:
    return (1 + 0j, z, 0j, 1 + 0j)


def input_impedance(c: Chain, z_load: complex) -> complex:
    """Impedance at the near port with ``z_load`` across the far one."""
    return (c[0] * z_load + c[1]) / (c[2] * z_load + c[3])


@dataclass(frozen=True)
class TuningUnit:
    """A tuning unit: ``kind`` F1 (series L-C) or F2 (series L-C with ``c3_F`` across it); inductor quality ``q``."""

    base: str  # its own carrier
    kind: str
    l_H: float
    c_F: float
    c3_F: float | None
    q: float

    def impedance(self, f_Hz: float) -> complex:
        w = 2 * math.pi * f_Hz
        z = complex(w * self.l_H / self.q, w * self.l_H) + 1 / complex(0.0, w * self.c_F)
        return z if self.c3_F is None else 1 / (1 / z + complex(0.0, w * self.c3_F))


@dataclass(frozen=True)
class Ends:
    """Both ends of a section at its carrier, referred to the rails (ohm, siemens, volt)."""

    emf_V: float  # Thevenin EMF of the transmitter, cable and matching transformer at the rails
    source_rail_ohm: complex  # and its impedance
    tx_end_S: complex  # the tuning area across the rails at the transmitter end
    rx_end_S: complex  # the tuning area and the receiver (through cable and transformer) at the receiver end
    small_track: complex  # rail voltage at the far side of the transmitter-end tuning area per volt at the section


def _rail_z(params: ZpwParams, base: str, f_Hz: float) -> complex:
    """Rail impedance per km of the carrier ``base``'s line constants at ``f_Hz``."""
    i = ("1700", "2000", "2300", "2600").index(base)
    return complex(params.rail_resistance_ohm_km[i], 2 * math.pi * f_Hz * params.rail_inductance_mH_km[i] * 1e-3)


def _leak(ballast: float) -> complex:
    return complex(DRY_S_KM if math.isinf(ballast) else 1.0 / ballast)


def _air_core(params: ZpwParams, f_Hz: float) -> complex:
    x = 2 * math.pi * f_Hz * params.air_core_uH * 1e-6
    return complex(x / params.tuning_q, x)


def _beyond(params: ZpwParams, f_Hz: float, rail_z: complex, ballast: float, equipment: complex) -> complex:
    """What the far side of a tuning area has across the rails at ``f_Hz`` besides the neighbour's unit: the
    neighbour's main track (a long line: its characteristic impedance) and the neighbour's equipment."""
    z0 = cmath.sqrt(rail_z / _leak(ballast))
    return 1 / (1 / z0 + 1 / equipment)


def _half(params: ZpwParams, rail_z: complex, ballast: float) -> Chain:
    return line(rail_z, _leak(ballast), params.tuning_area_m / 2000.0)


def tuning_area(params: ZpwParams, carrier: str, f_Hz: float, ballast: float, equipment: complex, *,
                break_at_m: float | None = None, shunt_at_m: float | None = None,
                shunt_ohm: float | None = None) -> tuple[Chain, complex]:
    """The tuning area past the own unit, from the section's side (metres from it) to the far side, and what the far
    side has across it (the neighbour's unit in parallel with its track and equipment): (two-port, load)."""
    base = carrier.partition("-")[0]
    rail_z = _rail_z(params, base, f_Hz)
    leak = _leak(ballast)
    length = params.tuning_area_m
    mid = length / 2.0
    nodes: list[tuple[float, int, complex]] = [(mid, 0, 1 / _air_core(params, f_Hz))]
    if break_at_m is not None:
        nodes.append((min(max(break_at_m, 0.0), length), 1, complex(params.broken_rail_ohm)))
    if shunt_at_m is not None:
        r = params.standard_shunt_ohm if shunt_ohm is None else shunt_ohm
        nodes.append((min(max(shunt_at_m, 0.0), length), 0, complex(1.0 / max(r, 1e-9))))
    c, pos = IDENTITY, 0.0
    for s, kind, value in sorted(nodes, key=lambda n: (n[0], n[1])):
        c = chain(c, line(rail_z, leak, (s - pos) / 1000.0))
        c, pos = chain(c, series(value) if kind == 1 else shunt(value)), s
    c = chain(c, line(rail_z, leak, (length - pos) / 1000.0))
    neighbour = unit(params, PARTNER[base]).impedance(f_Hz)
    load = 1 / (1 / neighbour + 1 / _beyond(params, f_Hz, rail_z, ballast, equipment))
    return c, load


@lru_cache(maxsize=64)
def unit(params: ZpwParams, base: str) -> TuningUnit:
    """The tuning unit of carrier ``base``, designed for the zero at the partner carrier and the pole at its own, at
    the nominal carriers and the design ballast, with the tuning area's rail and air-core coil."""
    fo, fn = float(base), float(PARTNER[base])
    wo, wn = 2 * math.pi * fo, 2 * math.pi * fn
    # the rest of the tuning area at the own carrier, lossless, the neighbour's unit an ideal zero
    rail_z = complex(0.0, _rail_z(params, base, fo).imag)
    half = line(rail_z, _leak(params.ballast_ohm_km), params.tuning_area_m / 2000.0)
    rest = chain(chain(half, shunt(1 / complex(0.0, wo * params.air_core_uH * 1e-6))), half)
    x_rest = input_impedance(rest, 0j).imag
    if fo < fn:  # F1: series L1-C1, X(fo) = -x_rest, zero at fn
        c1 = (1.0 - wo**2 / wn**2) / (wo * x_rest)
        return TuningUnit(base, "F1", 1.0 / (wn**2 * c1), c1, None, params.tuning_q)
    l2 = params.f2_inductance_uH * 1e-6  # F2: series L2-C2 zero at fn, C3 across it for the pole at fo
    c2 = 1.0 / (wn**2 * l2)
    x_series = wo * l2 - 1.0 / (wo * c2)
    c3 = (1.0 / x_rest + 1.0 / x_series) / wo
    return TuningUnit(base, "F2", l2, c2, c3, params.tuning_q)


def cable(params: ZpwParams, f_Hz: float) -> Chain:
    """The cable between the equipment room and the matching transformer: equipment side near, track side far."""
    w = 2 * math.pi * f_Hz
    z = complex(params.cable_ohm_km, w * params.cable_mH_km * 1e-3)
    y = complex(0.0, w * params.cable_nF_km * 1e-9)
    return line(z, y, params.cable_km)


def equipment(params: ZpwParams, f_Hz: float) -> tuple[complex, complex, complex]:
    """(transmitter Thevenin EMF per volt of level, its impedance, the receiver's impedance), at the rails."""
    a, b, c, d = cable(params, f_Hz)
    n2 = params.matching_ratio**2
    zs = params.source_ohm
    emf = 1 / (a + zs * c) / params.matching_ratio  # open-circuit voltage at the track side of the cable, referred
    z_source = (b + zs * d) / (a + zs * c) / n2
    zr = params.receiver_ohm  # the receiver seen through the cable from the track side
    z_receiver = (d * zr + b) / (c * zr + a) / n2
    return emf, z_source, z_receiver


@lru_cache(maxsize=1024)
def section_ends(params: ZpwParams, carrier: str, ballast: float | None = None) -> Ends:
    """Both ends of a section at its carrier, referred to the rails, at ``ballast`` (the design ballast if None)."""
    return ends(params, carrier, carrier_frequency_Hz(carrier), params.ballast_ohm_km if ballast is None else ballast)


def ends(params: ZpwParams, carrier: str, f_Hz: float, ballast: float) -> Ends:
    """The section's two ends at its carrier ``f_Hz`` and ``ballast`` (ohm*km; inf: dry)."""
    emf, z_source, z_receiver = equipment(params, f_Hz)
    if not params.tuning_units:  # insulated joints, no tuning area across the rails
        return Ends(params.transmitter_V * abs(emf), z_source, 0j, 1 / z_receiver, 0j)
    own = unit(params, carrier.partition("-")[0]).impedance(f_Hz)
    # the neighbour's equipment at the far side: its receiver beyond the transmitter end, its transmitter (a
    # passive source impedance at this carrier) beyond the receiver end
    tx_area, tx_load = tuning_area(params, carrier, f_Hz, ballast, z_receiver)
    rx_area, rx_load = tuning_area(params, carrier, f_Hz, ballast, z_source)
    y_tx = 1 / own + 1 / input_impedance(tx_area, tx_load)
    y_rx = 1 / own + 1 / input_impedance(rx_area, rx_load) + 1 / z_receiver
    a, b, _, _ = tx_area
    small = tx_load / (a * tx_load + b)  # V far / V near with the load across the far side
    return Ends(params.transmitter_V * abs(emf), z_source, y_tx, y_rx, small)


def small_track_transfer(params: ZpwParams, carrier: str, f_Hz: float, ballast: float, *,
                         break_at_m: float | None = None, shunt_at_m: float | None = None,
                         shunt_ohm: float | None = None) -> tuple[complex, complex]:
    """(admittance of the transmitter-end tuning area past the own unit, far-side voltage per volt at the section)
    with a broken rail or a shunt in the tuning area (metres from the section's side)."""
    _, _, z_receiver = equipment(params, f_Hz)
    area, load = tuning_area(params, carrier, f_Hz, ballast, z_receiver, break_at_m=break_at_m,
                             shunt_at_m=shunt_at_m, shunt_ohm=shunt_ohm)
    own = unit(params, carrier.partition("-")[0]).impedance(f_Hz)
    a, b, _, _ = area
    return 1 / own + 1 / input_impedance(area, load), load / (a * load + b)


__all__ = ["PARTNER", "Ends", "TuningUnit", "cable", "ends", "equipment", "small_track_transfer", "tuning_area",
           "unit"]

"""ZPW-2000A jointless audio-frequency track circuit (ZPW-2000A 无绝缘移频轨道电路) as a transmission line.

One section of ``length_m`` is a uniform two-rail line (series rail impedance, shunt ballast conductance) between a
transmitter end (发送端) and a receiver end (接收端), solved exactly with chain (ABCD) matrices:

    transmitter: the transmitter (EMF ``transmitter_V`` behind ``source_ohm``) through ``cable_km`` of cable and
                 the matching transformer, referred to the rails, in parallel with the tuning area (:mod:`.ends`)
    line:        exact uniform-line two-ports (cosh / sinh of gamma*l) between the compensation capacitors
                 (补偿电容, shunt admittances across the rails) and wheelset shunts (shunt conductances)
    receiver:    the tuning area in parallel with the receiver seen through its cable and matching transformer,
                 rail voltage times the receiver gain = main-track output voltage (主轨出) in mV
    small track: the tuning area at the transmitter end; its far side's rail voltage times its own gain is what
                 the neighbour's receiver checks (小轨道, ``ZpwCircuit.small_track_mV``)

The transmitter is at the section's upper end and the receiver at its lower end (``transmitter_end="upper"``), as
for a down train: in ZPW-2000A the signal runs against the traffic, from the end the train leaves towards, so a
train's leading wheelset reads the rail current coming from the transmitter. ``transmitter_end="lower"`` mirrors it.
Capacitors are numbered 1..N from the section's lower end; positions are metres from the lower end.

The receiver gain is set per section as a maintainer sets the attenuator (衰耗器): the no-train main-track output at
the design ballast with no fault is ``adjust_mV``. Figures and their sources: docs/zpw2000a.md.

Ballast resistances <= 0 or NaN and positions that are not finite numbers raise ``ValueError`` (:mod:`.physical`);
infinite ballast is dry ballast, with no leakage.
"""

from __future__ import annotations

import cmath
import dataclasses
import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING, Any, Literal

import numpy as np
import numpy.typing as npt

from liansuo.circuits.physical import check_ballast, check_position, check_shunts
from liansuo.circuits.zpw import ends as zpwends
from liansuo.circuits.zpw.ends import Ends
from liansuo.circuits.zpw.params import (
    DEFAULT_PARAMS,
    ZpwParams,
    base_index,
    carrier_frequency_Hz,
)

if TYPE_CHECKING:
    from liansuo.stations.station import Station

CArray = npt.NDArray[Any]  # complex128
FArray = npt.NDArray[Any]  # float64
FAULT_MODES = ("open", "half", "short")
End = Literal["upper", "lower"]


# ---- line classes --------------------------------------------------------------------------------------------------
# The ZPW-2000A of a passenger-dedicated line (客专, communication-coded) differs from the conventional one (普速,
# relay-coded, ZpwParams' figures) in its design minimum ballast and its standard capacitors (docs/zpw2000a.md):
PASSENGER_BALLAST_OHM_KM = 2.0  # design minimum: ballastless track stays above it (about 3 ohm*km measured)
PASSENGER_CAPACITANCE_UF = 25.0  # every carrier
PASSENGER_SPACING_M = (60.0, 60.0, 80.0, 80.0)  # on the line (区间), per carrier 1700, 2000, 2300, 2600 Hz
PASSENGER_STATION_SPACING_M = 100.0  # in the station (站内)
LAYOUTS = ("conventional", "passenger-line", "passenger-station")  # what a section's standard figures follow


def layout_params(layout: str, carrier: str, params: ZpwParams = DEFAULT_PARAMS) -> ZpwParams:
    """``params`` with the design minimum ballast, capacitance and capacitor spacing of a layout (:data:`LAYOUTS`):
    ``conventional`` keeps them; ``passenger-line`` and ``passenger-station`` are the passenger-dedicated line's,
    on the line and in the station."""
    if layout == "conventional":
        return params
    if layout not in LAYOUTS:
        raise ValueError(f"unknown ZPW-2000A layout '{layout}': use {', '.join(LAYOUTS)}")
    spacing = PASSENGER_SPACING_M[base_index(carrier)] if layout == "passenger-line" else PASSENGER_STATION_SPACING_M
    return dataclasses.replace(params, ballast_ohm_km=PASSENGER_BALLAST_OHM_KM,
                               capacitance_uF=(PASSENGER_CAPACITANCE_UF,) * 4, capacitor_spacing_m=spacing)


def section_layout(station: Station, section_id: str) -> str:
    """The layout of a station's ZPW-2000A section: its line class, and for a passenger-dedicated line whether it is
    on the line (an approach, departure or block section) or in the station."""
    section = station.sections[section_id]
    if section.line_class is None or section.line_class.value == "conventional":
        return "conventional"
    on_line = section.role.value in ("approach", "departure", "block")
    return "passenger-line" if on_line else "passenger-station"


# ---- capacitor layout ----------------------------------------------------------------------------------------------
def standard_positions(length_m: float, count: int | None = None, params: ZpwParams = DEFAULT_PARAMS) -> list[float]:
    """Evenly spaced with half a spacing at the ends: ``count`` of them, or by the rule (about every
    ``capacitor_spacing_m``, none at or under ``capacitor_min_section_m``)."""
    if count is None:
        if length_m <= params.capacitor_min_section_m:
            return []
        count = math.ceil(length_m / params.capacitor_spacing_m - 1e-9)
    step = length_m / count if count else 0.0
    return [round((i + 0.5) * step, 6) for i in range(count)]


def capacitor_positions(station: Station, section_id: str, params: ZpwParams = DEFAULT_PARAMS,
                        length_m: float | None = None) -> list[float]:
    """The capacitors of a section as the station file describes them (``positions``, ``count`` or ``rule``), those
    by count or rule placed over ``length_m``, the length of the circuit they go into (by default the section's
    span): placed on one length and solved on another, a track's own ``length`` would put them off the line."""
    section = station.sections[section_id]
    caps = section.capacitors
    if caps is None:
        return []
    if caps.positions is not None:
        return sorted(caps.positions)
    params = layout_params(section_layout(station, section_id), section.carrier or "1700-1", params)
    length = station.section_span(section_id) if length_m is None else length_m
    if caps.count is not None:
        return standard_positions(length, caps.count, params)
    return standard_positions(length, None, params) if caps.rule == "standard" else []


# ---- the vectorised solver -----------------------------------------------------------------------------------------
def solve(length_m: float, capacitors_s: Sequence[float], ycap: CArray, shunts_s: Sequence[float] | FArray,
          z_km: CArray, ballasts: Sequence[float], params: ZpwParams = DEFAULT_PARAMS, *,
          ends: Sequence[Sequence[Ends]], shunt_ohm: float | None = None, breaks_s: Sequence[float] = (),
          rx_extra_S: complex = 0j) -> tuple[CArray, CArray, CArray, CArray]:
    """Receiver rail voltage (V) and cab current (A) of many configurations at once (batched ABCD products).

    Coordinates ``s`` are metres from the receiver end. ``ycap`` (C, F, N): admittance of each of the N capacitors
    per carrier C and fault case F; ``z_km`` (C,): rail impedance per km; ``ballasts`` (B,) in ohm*km; ``ends``
    (C, B): the section's ends per carrier and ballast (``ZpwParams.ends``). Returns ``v0`` (C, B, F) with no train,
    ``v``, ``i_cab`` (C, B, F, P) with one shunt at each of ``shunts_s`` and ``vtx0`` (C, B, F), the rail voltage at
    the transmitter end with no train; ``i_cab`` is the rail current on the transmitter side of the shunt.
    ``breaks_s``: broken rails (series ``broken_rail_ohm``); ``rx_extra_S``: extra admittance at the receiver end (a
    failed insulation). The loops run over the nodes of the line (capacitors, shunt points), never over
    configurations.
    """
    r_sh = params.standard_shunt_ohm if shunt_ohm is None else shunt_ohm
    nodes = sorted([(s, 0, n) for n, s in enumerate(capacitors_s)] + [(s, 1, p) for p, s in enumerate(shunts_s)]
                   + [(s, 2, 0) for s in breaks_s])
    s_nodes = np.array([0.0] + [n[0] for n in nodes] + [length_m])
    gaps_km = np.diff(s_nodes) / 1000.0  # (K + 1,)
    g = np.array([1e-12 if math.isinf(b) else 1.0 / b for b in ballasts])[None, :]  # S/km
    gamma, zc = np.sqrt(z_km[:, None] * g), np.sqrt(z_km[:, None] / g)  # (C, B)
    arg = gaps_km[:, None, None] * gamma[None]
    ch = np.cosh(arg)[..., None]  # (K + 1, C, B, 1), broadcast over the fault cases
    sh = np.sinh(arg)[..., None]
    zsh, shz = zc[..., None] * sh, sh / zc[..., None]
    shape = (ycap.shape[0], len(ballasts), ycap.shape[1])

    def per_end(field: str) -> CArray:
        return np.array([[complex(getattr(e, field)) for e in row] for row in ends])[..., None]  # (C, B, 1)

    zs, ytx, emf = per_end("source_rail_ohm"), per_end("tx_end_S"), per_end("emf_V")
    yrx, zb = per_end("rx_end_S") + rx_extra_S, params.broken_rail_ohm
    n_p = len(shunts_s)
    vs, is_, r0s, r1s = (np.empty((n_p, *shape), dtype=complex) for _ in range(4))
    # receiver -> transmitter: state [V, I] for 1 V at the receiver, I flowing towards the receiver
    v = np.ones(shape, dtype=complex)
    i = np.broadcast_to(yrx, shape).astype(complex)
    for k, (_, kind, idx) in enumerate(nodes):
        v, i = ch[k] * v + zsh[k] * i, shz[k] * v + ch[k] * i
        if kind == 0:
            i = i + ycap[:, None, :, idx] * v
        elif kind == 1:
            vs[idx], is_[idx] = v, i
        else:
            v = v + zb * i
    v, i = ch[-1] * v + zsh[-1] * i, shz[-1] * v + ch[-1] * i
    v0 = emf / ((1 + zs * ytx) * v + zs * i)
    vtx0 = v0 * v
    # transmitter -> receiver: row vector r with EMF = r . [V, I] (for 1 V at the receiver)
    r0 = np.broadcast_to(1 + zs * ytx, shape).astype(complex)
    r1 = np.broadcast_to(zs, shape).astype(complex)
    r0, r1 = r0 * ch[-1] + r1 * shz[-1], r0 * zsh[-1] + r1 * ch[-1]
    for k in range(len(nodes) - 1, -1, -1):
        _, kind, idx = nodes[k]
        if kind == 0:
            r0 = r0 + r1 * ycap[:, None, :, idx]
        elif kind == 1:
            r0s[idx], r1s[idx] = r0, r1
        else:
            r1 = r1 + r0 * zb
        r0, r1 = r0 * ch[k] + r1 * shz[k], r0 * zsh[k] + r1 * ch[k]
    i_tx_side = is_ + vs / r_sh
    vrx = emf / (r0s * vs + r1s * i_tx_side)
    return v0, np.moveaxis(vrx, 0, -1), np.moveaxis(vrx * i_tx_side, 0, -1), vtx0


def profile_points(length_m: float, step_m: float) -> FArray:
    """Shunt positions every ``step_m`` (at most), both ends included."""
    return np.linspace(0.0, length_m, max(2, math.ceil(length_m / step_m - 1e-9) + 1))


# ---- one section in the live simulation ----------------------------------------------------------------------------
@dataclass(frozen=True)
class ZpwFaults:
    """Trackside faults of one section. A poor shunt is not a fault here: pass a high shunt resistance."""

    capacitors: dict[int, str] = field(default_factory=dict)  # capacitor number (1 = lowest) -> open|half|short
    broken_rail_at_m: float | None = None  # metres from the section's lower end
    ballast_ohm_km: float | None = None  # wet / dirty ballast overriding the design value
    insulation_short: bool = False  # failed insulation across the rails at the receiver end (red band)

    def __post_init__(self) -> None:
        if self.ballast_ohm_km is not None:
            check_ballast("ballast_ohm_km", self.ballast_ohm_km)
        if self.broken_rail_at_m is not None:
            check_position("broken_rail_at_m", self.broken_rail_at_m)

    def key(self) -> tuple[object, ...]:
        return (tuple(sorted(self.capacitors.items())), self.broken_rail_at_m, self.ballast_ohm_km,
                self.insulation_short)

    def __hash__(self) -> int:
        return hash(self.key())


NO_FAULTS = ZpwFaults()


@dataclass(frozen=True)
class ZpwState:
    """What the receiver sees: the main-track output voltage (主轨出) and the relay rule (pick-up / drop)."""

    voltage_mV: float
    cab_current_mA: float | None  # rail current at the shunt nearest the transmitter; None with no train
    pickup_mV: float
    drop_mV: float

    @property
    def relay_up(self) -> bool:
        """Pick-up rule from the released state."""
        return self.voltage_mV >= self.pickup_mV

    def relay_up_after(self, previous_up: bool) -> bool:
        """Relay state given the previous one: an up relay (GJ) holds until the voltage falls under ``drop_mV``."""
        return self.voltage_mV >= self.drop_mV if previous_up else self.relay_up


_Base = tuple[complex, complex, list[tuple[float, int, complex]], complex, Ends]


class ZpwCircuit:
    """One ZPW-2000A section: ``evaluate(shunts, faults)`` with shunts ``(metres from the lower end, ohm)``.

    The receiver gain is set at construction (design ballast, no fault, no train -> ``params.adjust_mV``). The
    no-train result is cached per fault set; one evaluation with a train costs tens of microseconds.
    """

    def __init__(self, length_m: float, carrier: str, capacitor_positions_m: Sequence[float] = (),
                 params: ZpwParams = DEFAULT_PARAMS, *, capacitance_uF: float | None = None,
                 transmitter_end: End = "upper") -> None:
        if not (math.isfinite(length_m) and length_m > 0.0):
            raise ValueError(f"length_m must be a positive number of metres, got {length_m!r}")
        if transmitter_end not in ("upper", "lower"):
            raise ValueError("transmitter_end is 'upper' or 'lower'")
        self.length_m = float(length_m)
        self.carrier = carrier
        self.frequency_Hz = carrier_frequency_Hz(carrier)
        self.params = params
        self.capacitance_uF = capacitance_uF
        self.transmitter_end = transmitter_end
        self.capacitors_m = tuple(sorted(float(x) for x in capacitor_positions_m))
        if any(not 0.0 <= x <= self.length_m for x in self.capacitors_m):
            raise ValueError(f"capacitor positions must lie within the section (0..{self.length_m:g} m)")
        self._z = params.rail_impedance(carrier)
        self._caps_s = sorted((self._s(x), n) for n, x in enumerate(self.capacitors_m, start=1))
        self._lines: dict[float, tuple[complex, complex]] = {}
        self._bases: dict[tuple[object, ...], _Base] = {}
        self._adjustments: dict[tuple[object, ...], ZpwState] = {}
        self.gain_mV_per_V = 1.0
        self.small_track_gain_mV_per_V = 1.0
        vrx, _, vtx = self._rail((), NO_FAULTS)
        self.gain_mV_per_V = params.adjust_mV / abs(vrx)
        reach = abs(vtx * self._base(NO_FAULTS)[4].small_track)  # 0 with insulated joints: no small track
        self.small_track_gain_mV_per_V = params.adjust_mV / reach if reach > 0 else 0.0

    def _s(self, x_m: float) -> float:
        """Position from the lower end -> distance from the receiver end."""
        x = min(max(x_m, 0.0), self.length_m)
        return x if self.transmitter_end == "upper" else self.length_m - x

    def _line(self, ballast: float) -> tuple[complex, complex]:
        line = self._lines.get(ballast)
        if line is None:
            g = 1e-12 if math.isinf(ballast) else 1.0 / ballast
            line = self._lines[ballast] = (cmath.sqrt(self._z * g), cmath.sqrt(self._z / g))
        return line

    def _ballast(self, f: ZpwFaults) -> float:
        return self.params.ballast_ohm_km if f.ballast_ohm_km is None else f.ballast_ohm_km

    def _base(self, f: ZpwFaults) -> _Base:
        """(gamma, zc, capacitor and break elements, receiver-end admittance, ends) for a fault set, cached."""
        key = f.key()
        base = self._bases.get(key)
        if base is None:
            p = self.params
            n = len(self._caps_s)
            bad = [k for k in f.capacitors if not 1 <= k <= n]
            if bad:
                raise ValueError(f"capacitor {bad[0]} does not exist: the section has {n}")
            elements = [(s, 0, p.capacitor_admittance(self.carrier, f.capacitors.get(k, "ok"), self.capacitance_uF))
                        for s, k in self._caps_s]
            if f.broken_rail_at_m is not None and 0.0 <= f.broken_rail_at_m <= self.length_m:
                elements.append((self._s(f.broken_rail_at_m), 2, complex(p.broken_rail_ohm)))
            elements.sort(key=lambda e: (e[0], e[1]))
            ends = zpwends.section_ends(p, self.carrier, self._ballast(f))
            yrx = ends.rx_end_S + (1.0 / p.insulation_short_ohm if f.insulation_short else 0.0)
            gamma, zc = self._line(self._ballast(f))
            base = self._bases[key] = (gamma, zc, elements, yrx, ends)
            if len(self._bases) > 256:
                self._bases.pop(next(iter(self._bases)))
        return base

    def _rail(self, shunts: Sequence[tuple[float, float]], f: ZpwFaults, tx_end_S: complex | None = None,
              ) -> tuple[complex, complex | None, complex]:
        """Receiver rail voltage (V), the rail current at the leading shunt (A) and the rail voltage at the
        transmitter end (V), scalar chain; ``tx_end_S`` replaces the transmitter end's tuning area."""
        gamma, zc, elements, yrx, ends = self._base(f)
        if shunts:
            elements = sorted(elements + [(self._s(x), 1, complex(1.0 / max(r, 1e-9))) for x, r in shunts],
                              key=lambda e: (e[0], e[1]))
        last_shunt = max((k for k, e in enumerate(elements) if e[1] == 1), default=-1)
        v, i = 1 + 0j, complex(yrx)
        lead: complex | None = None
        pos = 0.0
        for k, (s, kind, value) in enumerate([*elements, (self.length_m, 3, 0j)]):  # 3: the transmitter end
            if s > pos:
                ch, sh = cmath.cosh(gamma * (s - pos) / 1000.0), cmath.sinh(gamma * (s - pos) / 1000.0)
                v, i, pos = ch * v + zc * sh * i, sh / zc * v + ch * i, s
            if kind == 2:
                v += value * i
            else:
                i += value * v
            if k == last_shunt:
                lead = i
        zs = ends.source_rail_ohm
        vrx = ends.emf_V / ((1 + zs * (ends.tx_end_S if tx_end_S is None else tx_end_S)) * v + zs * i)
        return vrx, (None if lead is None else vrx * lead), vrx * v

    def evaluate(self, shunts: Sequence[tuple[float, float]] = (), faults: ZpwFaults | None = None) -> ZpwState:
        """Receiver state for wheelset shunts ``(metres from the section's lower end, ohm)``; outside ones ignored, a
        position that is not a finite number raises ``ValueError`` (such a wheelset lies nowhere)."""
        f = faults or NO_FAULTS
        check_shunts(shunts)
        inside = [(x, r) for x, r in shunts if -1e-9 <= x <= self.length_m + 1e-9]
        if not inside:
            return self.adjustment(f)
        vrx, cab, _ = self._rail(inside, f)
        return ZpwState(abs(vrx) * self.gain_mV_per_V, None if cab is None else abs(cab) * 1000.0,
                        self.params.pickup_mV, self.params.drop_mV)

    def adjustment(self, faults: ZpwFaults | None = None) -> ZpwState:
        """No-train state (调整状态), cached per fault set."""
        f = faults or NO_FAULTS
        key = f.key()
        state = self._adjustments.get(key)
        if state is None:
            vrx, _, _ = self._rail((), f)
            state = ZpwState(abs(vrx) * self.gain_mV_per_V, None, self.params.pickup_mV, self.params.drop_mV)
            self._adjustments[key] = state
            if len(self._adjustments) > 256:
                self._adjustments.pop(next(iter(self._adjustments)))
        return state

    def profile(self, faults: ZpwFaults | None = None, positions_m: Sequence[float] | None = None,
                shunt_ohm: float | None = None) -> tuple[FArray, FArray, FArray]:
        """(positions from the lower end, residual mV, cab current mA) with one shunt (default the 0.15 ohm
        standard shunt) at each position (default every ``profile_step_m``), all at once."""
        p = self.params
        f = faults or NO_FAULTS
        elements = self._base(f)[2]  # validates the fault set
        pos = profile_points(self.length_m, p.profile_step_m) if positions_m is None else np.asarray(positions_m, float)
        ycap = np.array([e[2] for e in elements if e[1] == 0], dtype=complex).reshape(1, 1, -1)
        ballast = self._ballast(f)
        _, v, i, _ = solve(self.length_m, [s for s, _ in self._caps_s], ycap, [self._s(float(x)) for x in pos],
                           np.array([self._z]), (ballast,), p, ends=[[zpwends.section_ends(p, self.carrier, ballast)]],
                           shunt_ohm=shunt_ohm, breaks_s=[e[0] for e in elements if e[1] == 2],
                           rx_extra_S=1.0 / p.insulation_short_ohm if f.insulation_short else 0.0)
        return pos, np.abs(v[0, 0, 0]) * self.gain_mV_per_V, np.abs(i[0, 0, 0]) * 1000.0

    def small_track_mV(self, shunts: Sequence[tuple[float, float]] = (), faults: ZpwFaults | None = None, *,
                       tuning_break_m: float | None = None, tuning_shunt_m: float | None = None,
                       tuning_shunt_ohm: float | None = None) -> float:
        """The small track (小轨道): the section's carrier across the rails at the far side of its transmitter-end
        tuning area, as the neighbour's receiver reads it, in mV (adjusted like the main track: ``adjust_mV`` at the
        design ballast with no train and no fault). ``shunts`` and ``faults`` are the main track's; a broken rail
        (``tuning_break_m``) or a wheelset (``tuning_shunt_m``, ``tuning_shunt_ohm``) in the tuning area are given in
        metres from the section's end. It falls with a train in the tuning area or near the transmitter and with a
        broken rail in the tuning area: the small track's check."""
        f = faults or NO_FAULTS
        check_shunts(shunts)
        ends = self._base(f)[4]
        y_tx, small = ends.tx_end_S, ends.small_track
        if tuning_break_m is not None or tuning_shunt_m is not None:
            y_tx, small = zpwends.small_track_transfer(
                self.params, self.carrier, self.frequency_Hz, self._ballast(f), break_at_m=tuning_break_m,
                shunt_at_m=tuning_shunt_m, shunt_ohm=tuning_shunt_ohm)
        inside = [(x, r) for x, r in shunts if -1e-9 <= x <= self.length_m + 1e-9]
        _, _, vtx = self._rail(inside, f, y_tx)
        return abs(vtx * small) * self.small_track_gain_mV_per_V

    def max_shunt_residual_mV(self, faults: ZpwFaults | None = None) -> float:
        return float(self.profile(faults)[1].max())

    def min_cab_current_mA(self, faults: ZpwFaults | None = None) -> float:
        return float(self.profile(faults)[2].min())

    @property
    def cab_min_mA(self) -> float:
        """The documented minimum cab (entry) current for this carrier."""
        return self.params.cab_min(self.carrier)


def section_circuit(station: Station, section_id: str, params: ZpwParams = DEFAULT_PARAMS,
                    transmitter_end: End = "upper") -> ZpwCircuit:
    """The ZpwCircuit of a ZPW-2000A section of a station (length, carrier, capacitors from the file, the figures
    of its layout)."""
    section = station.sections[section_id]
    if section.type.value != "zpw2000a" or section.carrier is None:
        raise ValueError(f"section {section_id} is not a ZPW-2000A section with a carrier")
    params = layout_params(section_layout(station, section_id), section.carrier, params)
    caps = section.capacitors
    length = station.section_run(section_id)  # the main run: a turnout section's branches lie beside it
    return ZpwCircuit(length, section.carrier, capacitor_positions(station, section_id, params, length), params,
                      capacitance_uF=caps.capacitance_uF if caps else None, transmitter_end=transmitter_end)

"""One live track circuit per section: the physical model of its type behind one small interface.

``SectionCircuit.update(shunts)`` re-evaluates the model when the wheelsets on the section or its faults change and
returns the track relay (GJ) state with the model's hysteresis. The shunts are a list, or the field's live view of
the section (:mod:`.shunts`), listed only when the model must be solved. The teaching base's switch K (``occupy``)
forces the relay down. Faults a section can carry: broken rail, poor shunt (wheelsets shunt through a higher
resistance), low ballast, failed insulation (at an insulated joint or a switch machine), and on ZPW-2000A
compensation capacitors. A section of ``type: axle_counter`` has an axle counter (:mod:`.axlecounter`) instead: it
counts wheelsets, so those faults do not touch it; its own fault is a miscount, and its count is reset by the
operator (计轴复零).

Fail-safe where the model cannot answer: a wheelset at an unknown place (a position that was not a finite number,
:mod:`.railgeometry`) drops the relay, and a 25 Hz section longer than the model's range (``max_25hz_m``, at most
:data:`~liansuo.circuits.phase25.model.MAX_LENGTH_M`) is held down for good with the reason in ``held_down``: in dry
ballast a standard shunt would not drop its relay, so the model could not show a train there. """

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field

from liansuo.circuits.axlecounter import AxleCounter
from liansuo.circuits.phase25.model import MAX_LENGTH_M, Phase25HzCircuit, Phase25HzFaults, adjusted_params
from liansuo.circuits.shunts import Listed, Shunt, Shunts
from liansuo.stations.schema import CircuitType
from liansuo.stations.station import Station


@dataclass
class SectionFaults:
    broken_rail_at_m: float | None = None
    poor_shunt_ohm: float | None = None
    ballast_ohm_km: float | None = None
    insulation_short: bool = False
    joint_failure: bool = False
    capacitors: dict[int, str] = field(default_factory=dict)

    def any(self) -> bool:
        return bool(self.broken_rail_at_m is not None or self.poor_shunt_ohm is not None
                    or self.ballast_ohm_km is not None or self.insulation_short or self.joint_failure
                    or self.capacitors)


class SectionCircuit:
    """The track circuit of one section, with its relay state and last evaluation."""

    def __init__(self, section: str, kind: CircuitType, length_m: float, model: object) -> None:
        self.section = section
        self.kind = kind
        self.length_m = length_m
        self.model = model
        self.faults = SectionFaults()
        self.k_switch = False  # the teaching panel's switch K shorting the track
        self.leak_drop = False  # traction leakage through a long dead zone holds the relay down now (:mod:`.leakage`)
        self.held_down = ""  # why the relay is held down for good (a section past its model's range), or ''
        self.up = False  # fail-safe until first evaluated
        self._voltage = 0.0  # V for 25 Hz, mV for ZPW-2000A
        self._cab_current_mA: float | None = None
        self._shunted: Shunts | None = None  # while down by a standard shunt: the shunts, solved only if asked
        self._inside = 0  # wheelsets on the section at the last update (what an axle counter counts)
        # every model is adjusted so that one standard shunt anywhere drops its relay (25 Hz: residual <= 7.4 V
        # with 0.06 ohm, below the relay's drop level; ZPW-2000A: < 153 mV with 0.15 ohm), as their tests assert
        self.standard_shunt_ohm = 0.06 if kind is CircuitType.phase25hz else 0.15

    @classmethod
    def settled(cls, spec: CircuitSpec) -> SectionCircuit:
        """A live circuit of its own, as ``build_circuit`` and a first ``update([])`` leave it: with nothing on the
        track and no fault. Only its model is ``spec``'s (see :class:`CircuitSpec`); its faults, switch K, leakage
        and axle count are its own."""
        c = cls(spec.section, spec.kind, spec.length_m, AxleCounter() if spec.model is None else spec.model)
        c.held_down = spec.held_down
        c.up, c._voltage, c._cab_current_mA = spec.up, spec.voltage, spec.cab_current_mA
        return c

    @property
    def voltage(self) -> float:
        """Relay-end voltage: V for 25 Hz, mV for ZPW-2000A."""
        self._solve_shunted()
        return self._voltage

    @property
    def cab_current_mA(self) -> float | None:
        self._solve_shunted()
        return self._cab_current_mA

    @property
    def shunted_down(self) -> bool:
        """Down by design: a healthy track circuit with a standard shunt on it. It stays down while the shunts
        only move, and needs to be updated again only when it may lose its last standard shunt or gets a fault."""
        return self._shunted is not None and not self.faults.any()

    def _solve_shunted(self) -> None:
        if self._shunted is not None:
            up = self.up
            self._evaluate(self._shunted.listed())
            self.up = up

    @property
    def axle_count(self) -> int | None:
        """An axle counter's count (None for a track circuit)."""
        return self.model.count(self._inside) if isinstance(self.model, AxleCounter) else None

    @property
    def counter(self) -> AxleCounter | None:
        """The axle counter of an axle-counter section (None on a track circuit); re-evaluate after changing it."""
        return self.model if isinstance(self.model, AxleCounter) else None

    @property
    def inside(self) -> int:
        """Wheelsets on the section at the last update."""
        return self._shunted.count() if self._shunted is not None else self._inside

    def update(self, shunts: Sequence[Shunt] | Shunts) -> bool:
        """The relay with ``shunts`` on the section: a list, or a live view (kept while the relay is down by a
        standard shunt, so the voltage read later is the one of the shunts then on the section)."""
        if not isinstance(shunts, Shunts):
            shunts = Listed(list(shunts))
        f = self.faults
        self._shunted = None
        if isinstance(self.model, AxleCounter):
            self._inside = shunts.count()
            self.up = self.model.clear(self._inside) and not self.k_switch
            return self.up
        if not f.any() and shunts.standard(self.standard_shunt_ohm):
            # a healthy circuit with a standard (or better) shunt on it: down by design; solve only if asked
            self._shunted = shunts
            self.up = False
            return self.up
        listed = shunts.listed()
        self._inside = len(listed)
        self._evaluate(listed)
        if self.k_switch or self.held_down or self.leak_drop:
            self.up = False
        return self.up

    def _evaluate(self, shunts: Sequence[tuple[float, float]]) -> None:
        f = self.faults
        if not all(math.isfinite(d) for d, _ in shunts):  # a wheelset somewhere unknown: occupied, never clear
            self._voltage, self._cab_current_mA, self.up = 0.0, None, False
            return
        if f.poor_shunt_ohm is not None:
            shunts = [(d, max(r, f.poor_shunt_ohm)) for d, r in shunts]
        if self.kind is CircuitType.phase25hz:
            assert isinstance(self.model, Phase25HzCircuit)
            faults = Phase25HzFaults(broken_rail_at_m=_clip(f.broken_rail_at_m, self.length_m),
                                     ballast_ohm_km=f.ballast_ohm_km, insulation_short=f.insulation_short,
                                     joint_failure=f.joint_failure)
            state = self.model.evaluate(shunts, faults)
            self._voltage = state.voltage_V
            self.up = state.relay_up_after(self.up)
        else:
            from liansuo.circuits.zpw.model import ZpwCircuit, ZpwFaults

            assert isinstance(self.model, ZpwCircuit)
            zf = ZpwFaults(capacitors=dict(f.capacitors), broken_rail_at_m=_clip(f.broken_rail_at_m, self.length_m),
                           ballast_ohm_km=f.ballast_ohm_km, insulation_short=f.insulation_short or f.joint_failure)
            zs = self.model.evaluate(shunts, zf)
            self._voltage = zs.voltage_mV
            self._cab_current_mA = zs.cab_current_mA
            self.up = zs.relay_up_after(self.up)


@dataclass(frozen=True)
class CircuitSpec:
    """What the live circuit of one section is built from, and the state it settles in with nothing on the track and
    no fault: worked out once per station and rule set (:func:`circuit_spec`) for every simulation of it, which
    builds its own circuits from it (:meth:`SectionCircuit.settled`).

    The model is shared: it is the section's physics, whose parameters are fixed when it is made (faults and shunts
    are passed to each evaluation), and what it keeps (a ZPW-2000A model's no-train results per fault set) is a pure
    function of what it was asked. An axle counter's count changes, so each circuit counts with an
    :class:`~.axlecounter.AxleCounter` of its own (``model`` None)."""

    section: str
    kind: CircuitType
    length_m: float
    model: object | None  # Phase25HzCircuit or ZpwCircuit; None: an axle counter
    held_down: str
    up: bool  # the relay, the voltage and the cab current after the first evaluation
    voltage: float
    cab_current_mA: float | None


def circuit_spec(station: Station, section: str, length_m: float, max_25hz_m: float = MAX_LENGTH_M
                 ) -> CircuitSpec:
    """The spec of ``section``'s circuit: ``build_circuit``'s, evaluated once with no shunt as a field does first."""
    c = build_circuit(station, section, length_m, max_25hz_m)
    c.update([])
    return CircuitSpec(section, c.kind, c.length_m, None if c.counter is not None else c.model, c.held_down, c.up,
                       c._voltage, c._cab_current_mA)


def _clip(at: float | None, length: float) -> float | None:
    if at is None:
        return None
    return length / 2 if at < 0 else min(at, length)


def build_circuit(station: Station, section: str, length_m: float, max_25hz_m: float = MAX_LENGTH_M
                  ) -> SectionCircuit:
    """The live circuit of ``section``; a 25 Hz one longer than ``max_25hz_m`` (or the model's range) is held down."""
    sec = station.sections[section]
    if sec.type is CircuitType.axle_counter:
        return SectionCircuit(section, sec.type, length_m, AxleCounter())
    if sec.type is CircuitType.phase25hz:
        length = max(length_m, 1.0)
        limit = min(max_25hz_m, MAX_LENGTH_M)
        circuit = SectionCircuit(section, sec.type, length_m,
                                 Phase25HzCircuit(length, adjusted_params(length), beyond_range=True))
        if length > limit:
            circuit.held_down = (f"25 Hz section {section} is {length:g} m long, past the track-circuit model's "
                                 f"range ({limit:g} m): a train on it might not drop its relay, so it is held "
                                 "occupied; split it with an insulated joint")
        return circuit
    from liansuo.circuits.zpw.adjust import adjusted_circuit
    from liansuo.circuits.zpw.model import capacitor_positions, section_layout

    carrier = sec.carrier or "1700-1"
    caps = sec.capacitors
    length = max(length_m, 1.0)
    model = adjusted_circuit(length, carrier, capacitor_positions(station, section, length_m=length),
                             capacitance_uF=caps.capacitance_uF if caps else None,
                             layout=section_layout(station, section))
    return SectionCircuit(section, sec.type, length_m, model)


__all__ = ["CircuitSpec", "SectionCircuit", "SectionFaults", "build_circuit", "circuit_spec"]

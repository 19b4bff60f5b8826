"""One live track circuit per section: the physical model of its type behind one small interface.

``SectionCircuit.update(shunts)`` re-evaluates the model when the wheelsets on the section or its faults change and
returns the track relay (GJ) state with the model's hysteresis. The teaching base's switch K (``occupy``) forces the
relay down. Faults a section can carry: broken rail, poor shunt (wheelsets shunt through a higher resistance), low
ballast, failed insulation (at an insulated joint or a switch machine), and on ZPW-2000A compensation capacitors.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass, field

from stations.schema import CircuitType
from stations.station import Station

from .phase25hz import Phase25HzCircuit, Phase25HzFaults, adjusted_params


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
        self.up = False  # fail-safe until first evaluated
        self.voltage = 0.0  # V for 25 Hz, mV for ZPW-2000A
        self.cab_current_mA: float | None = None

    def update(self, shunts: Sequence[tuple[float, float]]) -> bool:
        f = self.faults
        if f.poor_shunt_ohm is not None:
            shunts = [(d, max(r, f.poor_shunt_ohm)) for d, r in shunts]
        if self.kind is CircuitType.phase25hz:
            assert isinstance(self.model, Phase25HzCircuit)
            faults = Phase25HzFaults(broken_rail_at_m=_clip(f.broken_rail_at_m, self.length_m),
                                     ballast_ohm_km=f.ballast_ohm_km, insulation_short=f.insulation_short,
                                     joint_failure=f.joint_failure)
            state = self.model.evaluate(shunts, faults)
            self.voltage = state.voltage_V
            self.up = state.relay_up_after(self.up)
        else:
            from .zpw2000a import ZpwCircuit, ZpwFaults

            assert isinstance(self.model, ZpwCircuit)
            zf = ZpwFaults(capacitors=dict(f.capacitors), broken_rail_at_m=_clip(f.broken_rail_at_m, self.length_m),
                           ballast_ohm_km=f.ballast_ohm_km, insulation_short=f.insulation_short or f.joint_failure)
            zs = self.model.evaluate(shunts, zf)
            self.voltage = zs.voltage_mV
            self.cab_current_mA = zs.cab_current_mA
            self.up = zs.relay_up_after(self.up)
        if self.k_switch:
            self.up = False
        return self.up


def _clip(at: float | None, length: float) -> float | None:
    if at is None:
        return None
    return length / 2 if at < 0 else min(at, length)


def build_circuit(station: Station, section: str, length_m: float) -> SectionCircuit:
    sec = station.sections[section]
    if sec.type is CircuitType.phase25hz:
        params = adjusted_params(max(length_m, 1.0))
        return SectionCircuit(section, sec.type, length_m, Phase25HzCircuit(max(length_m, 1.0), params))
    from .zpw2000a import ZpwCircuit, capacitor_positions

    carrier = sec.carrier or "1700-1"
    model = ZpwCircuit(max(length_m, 1.0), carrier, capacitor_positions(station, section))
    return SectionCircuit(section, sec.type, length_m, model)


__all__ = ["SectionCircuit", "SectionFaults", "build_circuit"]

"""The code current a cab signal reads at a train's leading wheelset on a ZPW-2000A section.

Station coding sends the code from the end of the section the train runs towards, against the train (ZPW-2000A
sends against the traffic, :mod:`.zpw.model`): a train running down reads the current of a transmitter at the section's
upper end, a train running up that of a transmitter at its lower end. The current read is the rail current on the
transmitter side of the leading wheelset, with the section's faults (compensation capacitors, broken rail, ballast,
failed insulation) and the wheelset's own shunt resistance (a poor shunt fault raises it). The cab loses the code
below the carrier's minimum (``ZpwCircuit.cab_min_mA``).

The current along the whole section is solved at once (``ZpwCircuit.profile``) for each section, direction, fault set
and shunt resistance, kept, and read at the wheelset by linear interpolation: a train running along a section costs a
binary search a step.
"""

from __future__ import annotations

from bisect import bisect_right

from liansuo.circuits.trackcircuits import SectionCircuit
from liansuo.circuits.zpw.model import End, ZpwCircuit, ZpwFaults

Profile = tuple[list[float], list[float]]  # positions from the section's lower end, cab current mA there


class CabCurrents:
    """The cab current at a point of any ZPW-2000A section of one field, for either direction of travel."""

    def __init__(self) -> None:
        self._models: dict[tuple[str, End], ZpwCircuit] = {}
        self._profiles: dict[tuple[object, ...], Profile] = {}

    def model(self, circuit: SectionCircuit, end: End) -> ZpwCircuit:
        """The section's ZPW-2000A model with its transmitter at ``end`` (the section's own when it is there)."""
        own = circuit.model
        if not isinstance(own, ZpwCircuit):
            raise ValueError(f"section {circuit.section} is not a ZPW-2000A section")
        if own.transmitter_end == end:
            return own
        key = (circuit.section, end)
        found = self._models.get(key)
        if found is None:
            found = self._models[key] = ZpwCircuit(own.length_m, own.carrier, own.capacitors_m, own.params,
                                                   capacitance_uF=own.capacitance_uF, transmitter_end=end)
        return found

    def at(self, circuit: SectionCircuit, x_m: float, end: End, wheel_ohm: float) -> float:
        """Cab current (mA) at ``x_m`` metres from the section's lower end, sent from ``end``, with a wheelset of
        ``wheel_ohm`` there."""
        positions, currents = self.profile(circuit, end, wheel_ohm)
        k = bisect_right(positions, x_m)
        if k <= 0:
            return currents[0]
        if k >= len(positions):
            return currents[-1]
        x0, x1 = positions[k - 1], positions[k]
        c0, c1 = currents[k - 1], currents[k]
        return c0 + (c1 - c0) * (x_m - x0) / (x1 - x0) if x1 > x0 else c1

    def profile(self, circuit: SectionCircuit, end: End, wheel_ohm: float) -> Profile:
        f = circuit.faults
        ohm = max(wheel_ohm, f.poor_shunt_ohm or 0.0)
        # the circuit's faults as the ZPW-2000A model takes them (as ``SectionCircuit`` passes them)
        length = circuit.length_m
        broken = f.broken_rail_at_m
        if broken is not None:
            broken = length / 2 if broken < 0 else min(broken, length)
        faults = ZpwFaults(capacitors=dict(f.capacitors), broken_rail_at_m=broken, ballast_ohm_km=f.ballast_ohm_km,
                           insulation_short=f.insulation_short or f.joint_failure)
        key = (circuit.section, end, faults.key(), ohm)
        found = self._profiles.get(key)
        if found is None:
            pos, _, cab = self.model(circuit, end).profile(faults, shunt_ohm=ohm)
            found = self._profiles[key] = ([float(x) for x in pos], [float(c) for c in cab])
            if len(self._profiles) > 1024:
                self._profiles.pop(next(iter(self._profiles)))
        return found


__all__ = ["CabCurrents"]

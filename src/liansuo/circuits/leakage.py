"""Traction return current leaking through a long dead zone: the next section's relay flickers (闪红光带).

Chen Bo 2023 (docs/references.md) reports a scissors crossover whose dead zone was laid 11.2 m long instead of the
standard design's 6.3 m: with the last wheelsets of a movement standing in it and a heavy traction return current in
the section beyond, the current ran through those wheelsets into the neighbouring section and its relay flickered
down (a flashing red band). A dead zone is *long* when it is longer than the rule set's ``dead_zone_long_m``
(``rules/china/design.yaml``, the standard design's 6.3 m); only such zones couple two sections.

The flicker is deterministic, driven by the field's simulated time: while the leakage lasts the relay is held down
for the first :data:`FLICKER_DOWN_S` of every :data:`FLICKER_PERIOD_S`, counted from the moment the leakage began, and
is left to its track circuit for the rest. Fail-safe: the leakage only ever drops a relay, it never holds one up.
"""

from __future__ import annotations

from dataclasses import dataclass

from liansuo.stations.station import Station

FLICKER_PERIOD_S = 2.0  # one surge of return current every two seconds (modelled)
FLICKER_DOWN_S = 1.0  # the relay is down for the first second of each period


@dataclass(frozen=True)
class LongDeadZone:
    """A dead zone longer than the coupling threshold: positions ``start`` to ``end`` (as ``Track.shunts`` decides,
    ``start <= x < end``) at ``joint`` between ``sections`` (the joint's low and high section)."""

    joint: str
    start: float
    end: float
    sections: tuple[str, str]

    @property
    def length_m(self) -> float:
        return self.end - self.start

    def other(self, section: str) -> str | None:
        """The joint's section across the zone from ``section`` (None if ``section`` is neither)."""
        lo, hi = self.sections
        return hi if section == lo else lo if section == hi else None


def long_dead_zones(station: Station, longer_than_m: float) -> dict[str, list[LongDeadZone]]:
    """The long dead zones touching each track (tracks without one are left out)."""
    zones = {dz.joint: dz for dz in station.dead_zones if dz.end - dz.start > longer_than_m}
    out: dict[str, list[LongDeadZone]] = {}
    for tid, ports in station.track_ports.items():
        for p in ports:
            dz = zones.get(p.node)
            if dz is not None:
                out.setdefault(tid, []).append(
                    LongDeadZone(dz.joint, dz.start, dz.end, station.joint_sections(dz.joint)))
    return out


class Flicker:
    """Which sections' relays the leakage holds down now: ``leak(sections, t)`` says which sections take leakage
    current from ``t`` on, ``down(section, t)`` whether the pattern holds that section's relay down at ``t``."""

    def __init__(self, period_s: float = FLICKER_PERIOD_S, down_s: float = FLICKER_DOWN_S) -> None:
        self.period_s = period_s
        self.down_s = down_s
        self.since: dict[str, float] = {}  # section -> when its leakage began

    def leak(self, sections: set[str], t: float) -> set[str]:
        """Sections taking leakage current from now on; returns the sections whose leakage began or ended."""
        gone = set(self.since) - sections
        for s in gone:
            del self.since[s]
        new = sections - set(self.since)
        for s in new:
            self.since[s] = t
        return gone | new

    def down(self, section: str, t: float) -> bool:
        began = self.since.get(section)
        if began is None:
            return False
        return (t - began + 1e-9) % self.period_s < self.down_s


__all__ = ["FLICKER_DOWN_S", "FLICKER_PERIOD_S", "Flicker", "LongDeadZone", "long_dead_zones"]

"""Where a wheelset shunts: each rail's insulated joints are placed separately.

A wheelset connects the two rails where it stands. It shunts a track circuit only if both rails under it belong to
the same section; between the staggered joints of the two rails (a dead zone, 死区段) it joins one rail of one
section to the other rail of the next, and shunts nothing. A vehicle whose every wheelset stands in dead zones is
invisible to the interlocking. A wheelset whose position is not a finite number (NaN, infinite) stands somewhere
unknown on its track: fail-safe, it shunts its track's section at an unknown place (distance NaN), and the section's
track circuit shows it occupied (:mod:`.trackcircuits`).
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import NamedTuple

from liansuo.stations.station import Station


class Axle(NamedTuple):
    """A wheelset standing on ``track`` at position ``x`` (metres along the line), with its shunt resistance.
    (A named tuple: trains make hundreds of these every step.)"""

    track: str
    x: float
    ohm: float = 0.01


@dataclass(frozen=True)
class Shunt:
    section: str
    distance_m: float  # from the section's lower end (its feed end in the models)
    ohm: float


class RailGeometry:
    def __init__(self, station: Station) -> None:
        self.tracks = station.tracks
        self.track_span = {t: station.track_span(t) for t in station.tracks}
        self.section_low: dict[str, float] = {}
        self.section_length: dict[str, float] = {}
        for sec, tracks in station.section_tracks.items():
            lo = min(self.track_span[t][0] for t in tracks)
            hi = max(self.track_span[t][1] for t in tracks)
            self.section_low[sec] = lo
            self.section_length[sec] = max(hi - lo, 1.0)
        # dead zones touching each track: intervals [start, end) in position
        self.track_dead: dict[str, list[tuple[float, float]]] = {t: [] for t in station.tracks}
        zones = {dz.joint: dz for dz in station.dead_zones}
        for tid, (a, b) in station.track_ports.items():
            for p in (a, b):
                dz = zones.get(p.node)
                if dz is not None:
                    self.track_dead[tid].append((dz.start, dz.end))

    def shunts_of(self, axles: list[Axle]) -> dict[str, list[tuple[float, float]]]:
        """The shunts of many wheelsets, by section: the same as ``shunt`` for each, without the call per axle."""
        out: dict[str, list[tuple[float, float]]] = {}
        span, dead, tracks = self.track_span, self.track_dead, self.tracks
        low, length = self.section_low, self.section_length
        for a in axles:
            lo, hi = span[a.track]
            x = a.x
            if not lo - 1e-6 <= x <= hi + 1e-6:
                if not math.isfinite(x):  # somewhere unknown on its track: occupied, never clear
                    out.setdefault(tracks[a.track].section, []).append((math.nan, a.ohm))
                continue
            zones = dead[a.track]
            if zones and any(z0 <= x < z1 for z0, z1 in zones):
                continue
            sec = tracks[a.track].section
            d = x - low[sec]
            out.setdefault(sec, []).append((0.0 if d < 0 else min(d, length[sec]), a.ohm))
        return out

    def in_dead_zone(self, track: str, x: float) -> bool:
        return any(lo <= x < hi for lo, hi in self.track_dead[track])

    def shunt(self, axle: Axle) -> Shunt | None:
        """The shunt this wheelset makes, or None in a dead zone (or off its track); at distance NaN if its position
        is not a finite number (it shunts its section somewhere unknown)."""
        if not math.isfinite(axle.x):
            return Shunt(self.tracks[axle.track].section, math.nan, axle.ohm)
        lo, hi = self.track_span[axle.track]
        if not lo - 1e-6 <= axle.x <= hi + 1e-6 or self.in_dead_zone(axle.track, axle.x):
            return None
        sec = self.tracks[axle.track].section
        d = min(max(axle.x - self.section_low[sec], 0.0), self.section_length[sec])
        return Shunt(sec, d, axle.ohm)


def geometry_of(station: Station) -> RailGeometry:
    """The station's rail geometry, worked out once per station (``Station.derived``): it never changes, and every
    simulation of the station (verify builds thousands) reads the same."""
    return station.derived(RailGeometry)

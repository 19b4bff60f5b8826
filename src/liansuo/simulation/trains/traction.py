"""Traction current through long dead zones: the sections a train's wheelsets leak it into.

A train drawing traction current whose wheelsets stand in a long dead zone (:mod:`~liansuo.circuits.leakage`)
joins one rail of a section to the other rail of the next; part of the return current runs through them into the
section across the zone from the train's traction, whose relay then flickers (Chen Bo 2023, docs/references.md:
the last wheelsets of a movement standing in an 11.2 m scissors dead zone, the locomotive beyond it). The traction
side is the section of the nearest wheelset ahead of the zone that stands outside it (the train's head side), or,
when the leading wheelsets stand in the zone, of the nearest one behind it. A track trolley draws no traction current.
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Protocol

from liansuo.circuits.leakage import LongDeadZone
from liansuo.simulation.trains.consist import Consist
from liansuo.simulation.trains.movement import Position, TrackGeometry


class Drawing(Protocol):
    """What the leakage needs of a train (:class:`~.fleet.Train`)."""

    traction: bool
    state: str
    pos: Position
    consist: Consist


def leaking_sections(track: TrackGeometry, zones: dict[str, list[LongDeadZone]], trains: Iterable[Drawing]) -> set[str]:
    """The sections the ``trains`` leak traction current into now, through the long dead ``zones`` (by track)."""
    out: set[str] = set()
    tracks = track.station.tracks
    for tr in trains:
        if not tr.traction or tr.state in ("derailed", "left") or not any(m[0] in zones for m in tr.pos.moves):
            continue
        axles = track.axles(tr.pos, tr.consist.axle_offsets_m)
        inside = [next((z for z in zones.get(a.track, ()) if z.start <= a.x < z.end), None) for a in axles]
        for zone in {z for z in inside if z is not None}:
            first = inside.index(zone)
            last = len(inside) - 1 - inside[::-1].index(zone)
            ahead = next((axles[k] for k in range(first - 1, -1, -1) if inside[k] is None), None)
            side = ahead or next((axles[k] for k in range(last + 1, len(axles)) if inside[k] is None), None)
            other = zone.other(tracks[side.track].section) if side is not None else None
            if other is not None:
                out.add(other)
    return out


__all__ = ["leaking_sections"]

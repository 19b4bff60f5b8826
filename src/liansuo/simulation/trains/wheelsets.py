"""A train's wheelsets as the track circuits see them: a :class:`~circuits.shunts.WheelsetGroup`.

A moving train's wheelsets stand somewhere else every cycle, but the sections they shunt change only where a
section's first wheelset enters it or its last one leaves it, at a track end or a dead zone's edge. So those sections
are worked out with a binary search a track instead of a pass over the wheelsets (``sections_shunted``), together
with how far the front can run before they can change (a :class:`Footprint`); until then a step only notes where the
train stands. Where each wheelset stands (``Track.shunts``) is worked out only if the field asks: for a section with
a fault, an axle counter, or a voltage read.
"""

from __future__ import annotations

import math
from bisect import bisect_left, bisect_right
from itertools import pairwise

from liansuo.circuits.railgeometry import RailGeometry
from liansuo.circuits.shunts import Shunt
from liansuo.simulation.trains.movement import OUTSIDE_LENGTH, Position, TrackGeometry
from liansuo.stations.schema import Direction
from liansuo.stations.topology import Move

EDGE_M = 1e-6  # a wheelset this close to an edge may be on either side: far above the rounding of positions

Geo = tuple[float, float, float]  # a track's low end, high end and length (``Track.geo``)


class Footprint:
    """The sections a train shunts, for as long as its front runs on over the same moves from ``from_s`` to short
    of ``until_s``; ``ordered``: the wheelset offsets are in increasing order."""

    __slots__ = ("from_s", "moves", "offsets", "ordered", "sections", "until_s")

    def __init__(self, moves: list[Move], offsets: tuple[float, ...], ordered: bool, sections: frozenset[str],
                 from_s: float, until_s: float) -> None:
        self.moves = moves
        self.offsets = offsets
        self.ordered = ordered
        self.sections = sections
        self.from_s = from_s
        self.until_s = until_s

    def holds(self, pos: Position, offsets: tuple[float, ...]) -> bool:
        return offsets is self.offsets and self.from_s <= pos.front_s < self.until_s and pos.moves == self.moves


def footprint(track: TrackGeometry, pos: Position, offsets: tuple[float, ...], geometry: RailGeometry,
              was: Footprint | None = None) -> Footprint:
    """The sections the train at ``pos`` shunts, and how far they hold (``was``: the train's previous footprint)."""
    moves = list(pos.moves)
    ordered = was.ordered if was is not None and was.offsets is offsets else \
        all(a <= b for a, b in pairwise(offsets))
    if not ordered:  # not front first: placed one by one, and no stretch holds
        return Footprint(moves, offsets, False, frozenset(track.shunts(pos, offsets, geometry, 0.0)), pos.front_s,
                         pos.front_s)
    sections, slack = sections_shunted(track, pos, offsets, geometry)
    return Footprint(moves, offsets, True, sections, pos.front_s, pos.front_s + slack - EDGE_M)


def sections_shunted(track: TrackGeometry, pos: Position, offsets: tuple[float, ...], geometry: RailGeometry
                     ) -> tuple[frozenset[str], float]:
    """The sections where at least one wheelset (``offsets`` behind the front, in increasing order) shunts, exactly
    those of ``Track.shunts``, and how far the front can run on over the same moves before that can change: before
    a stretch of track loses its last wheelset over its front end or takes its first over its back end.

    Like ``Track.shunts`` it goes back from the front move by move, a wheelset standing on the first move it is not
    behind (the same arithmetic for where each move begins), then leaves out the wheelsets standing in dead zones."""
    found: set[str] = set()
    slack = math.inf
    moves, geos, tracks = pos.moves, track.geo, track.station.tracks
    n = len(offsets)
    i = 0  # the first wheelset not yet placed
    idx = len(moves) - 1
    lower = -math.inf  # where the move in front begins, behind the front
    back_of_move = pos.front_s  # where this move begins, behind the front
    while True:
        tid, d = moves[idx]
        geo = geos.get(tid)
        j = bisect_right(offsets, back_of_move, i)  # wheelsets i .. j - 1 stand on this move
        if geo is not None:
            down = d is Direction.down
            zones = geometry.track_dead[tid]
            dead = _dead_wheelsets(offsets, i, j, back_of_move, geo, down, zones) if zones and i < j else 0
            if j - i > dead:
                found.add(tracks[tid].section)
            stretches, cuts = _live_stretches(lower, back_of_move, geo, down, zones)
            for p, q in stretches:
                slack = min(slack, _unchanged_for(offsets, p, q))
            for c in cuts:  # a wheelset on a dead zone's edge, as near as it is placed: look again at the next step
                k = bisect_left(offsets, c - EDGE_M)
                if k < n and offsets[k] <= c + EDGE_M:
                    slack = 0.0
        i = j
        if idx == 0 or i >= n:
            break
        idx -= 1
        lower = back_of_move
        geo = geos.get(moves[idx][0])
        back_of_move += OUTSIDE_LENGTH if geo is None else geo[2]
    return frozenset(found), slack


def _unchanged_for(offsets: tuple[float, ...], p: float, q: float) -> float:
    """How far the train can run before the stretch from ``p`` to ``q`` behind its front (a wheelset at ``q`` on
    it, one at ``p`` not) gains its first wheelset or loses its last one."""
    a, b = bisect_right(offsets, p), bisect_right(offsets, q)
    if b > a:
        return offsets[b - 1] - p  # the last one on it leaves it over its front end
    if b < len(offsets):
        return offsets[b] - q  # the next one behind it enters it over its back end
    return math.inf


def _x_at(offset: float, back_of_move: float, geo: Geo, down: bool) -> float:
    """Position along the line of the wheelset ``offset`` behind the front, on a move beginning ``back_of_move``
    behind the front: the very arithmetic of ``Track.shunts``."""
    lo, hi, length = geo
    frac = (back_of_move - offset) / length
    return lo + (hi - lo) * frac if down else hi - (hi - lo) * frac


def _dead_wheelsets(offsets: tuple[float, ...], i: int, j: int, back_of_move: float, geo: Geo, down: bool,
                    zones: list[tuple[float, float]]) -> int:
    """How many of the wheelsets ``i`` to ``j - 1`` on one move stand in a dead zone, decided as ``Track.shunts``
    decides it (``z0 <= x < z1``). Their positions run monotonically with their offsets (falling on a down move,
    rising on an up move), so each zone holds one run of them, found by binary search."""

    def first(lo: int, below: float | None, at_least: float | None) -> int:
        """The first wheelset from ``lo`` whose position is below ``below`` (down) or at least ``at_least`` (up)."""
        hi = j
        while lo < hi:
            mid = (lo + hi) // 2
            x = _x_at(offsets[mid], back_of_move, geo, down)
            if (below is not None and x < below) or (at_least is not None and x >= at_least):
                hi = mid
            else:
                lo = mid + 1
        return lo

    runs = []
    for z0, z1 in zones:
        if down:
            a = first(i, z1, None)
            b = first(a, z0, None)
        else:
            a = first(i, None, z0)
            b = first(a, None, z1)
        if a < b:
            runs.append((a, b))
    dead, end = 0, i
    for a, b in sorted(runs):  # zones may overlap: each wheelset counted once
        a = max(a, end)
        if b > a:
            dead += b - a
            end = b
    return dead


def _live_stretches(lower: float, back_of_move: float, geo: Geo, down: bool, zones: list[tuple[float, float]]
                    ) -> tuple[list[tuple[float, float]], list[float]]:
    """The stretches of one move (from ``lower`` to ``back_of_move`` behind the front) outside its dead zones, and
    where the zones' edges cut it: as near as rounding allows, for how far the train may run only."""
    if not zones:
        return [(lower, back_of_move)], []
    lo, hi, length = geo
    if hi - lo <= 0.0:
        return [(lower, back_of_move)], []  # no position to place a zone by (and no wheelset is in one)

    def offset_of(x: float) -> float:
        return back_of_move - ((x - lo) if down else (hi - x)) / (hi - lo) * length

    cuts = sorted({c for z in zones for c in (offset_of(z[0]), offset_of(z[1])) if lower < c < back_of_move})
    live = []
    for p, q in pairwise([lower, *cuts, back_of_move]):
        x = _x_at((p + q) / 2 if math.isfinite(p) else q - 1.0, back_of_move, geo, down)
        if not any(z0 <= x < z1 for z0, z1 in zones):
            live.append((p, q))
    return live, cuts


class TrainWheelsets:
    """Where one train's wheelsets stand at one moment: a new one whenever the train moved (the field's
    :class:`~circuits.shunts.WheelsetGroup`)."""

    __slots__ = ("_by_section", "_front_s", "_geometry", "_track", "footprint", "max_ohm")

    def __init__(self, track: TrackGeometry, geometry: RailGeometry, front_s: float, fp: Footprint, ohm: float) -> None:
        self._track = track
        self._geometry = geometry
        self._front_s = front_s
        self.footprint = fp
        self.max_ohm = ohm
        self._by_section: dict[str, list[Shunt]] | None = None

    @property
    def sections(self) -> frozenset[str]:
        return self.footprint.sections

    def stands_at(self, pos: Position, offsets: tuple[float, ...]) -> bool:
        """Every wheelset stands where it stood."""
        fp = self.footprint
        return offsets is fp.offsets and pos.front_s == self._front_s and pos.moves == fp.moves

    def shunts(self, section: str) -> list[Shunt]:
        if self._by_section is None:
            fp = self.footprint
            self._by_section = self._track.shunts(Position(list(fp.moves), self._front_s), fp.offsets,
                                                  self._geometry, self.max_ohm)
        return self._by_section.get(section, [])


def wheelsets_now(track: TrackGeometry, geometry: RailGeometry, was: TrainWheelsets | None, pos: Position,
                  offsets: tuple[float, ...], ohm: float) -> TrainWheelsets:
    """A train's wheelsets where it stands now: ``was`` if it has not moved, its sections worked out again only
    if they can have changed."""
    if was is None:
        return TrainWheelsets(track, geometry, pos.front_s, footprint(track, pos, offsets, geometry), ohm)
    fp = was.footprint
    front_s = pos.front_s
    if offsets is fp.offsets and pos.moves == fp.moves:  # ``stands_at`` and ``Footprint.holds``, asked together
        if front_s == was._front_s:
            return was
        if fp.from_s <= front_s < fp.until_s:
            return TrainWheelsets(track, geometry, front_s, fp, ohm)
    return TrainWheelsets(track, geometry, front_s, footprint(track, pos, offsets, geometry, fp), ohm)


__all__ = ["EDGE_M", "Footprint", "TrainWheelsets", "footprint", "sections_shunted", "wheelsets_now"]

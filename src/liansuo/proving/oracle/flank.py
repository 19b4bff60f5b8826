"""Flank protection (侧面防护) and fouling (侵限) demanded by a path, from the geometry alone.

A movement on a path is endangered from the side by whatever can run into the path where it leaves a turnout or
crosses a diamond. The **first turnout** met from the free leg of a path turnout (across joints, within the throat,
short of a signal that faces movements coming towards the path: that signal protects the flank),
or from either end of a track that crosses the path at a diamond, is a flank turnout when it is met on its normal or
reverse leg: it must lie the other way, away from the path, unless that way also leads straight into the path (as
the other diagonal of a scissors crossover does), in which case it cannot protect and nothing is demanded of it.
Met on its point, it cannot turn anything away either, nor can the crossover partner of a path turnout the path needs
the other way: it lies as its partner does (at a double slip, the partners of the turnouts of one straight road lead
onto the other straight road, which crosses it at the diamond).

A section just beyond a joint on a free leg, where the fouling point (警冲标) lies beyond that joint, is a fouling
section: a vehicle standing there fouls the path, so it must be clear. So is the section of a track that crosses the
path at a diamond: a vehicle standing on the crossing stands in the path.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from liansuo.proving.oracle.authority import other
from liansuo.rules import RuleSet
from liansuo.stations.schema import Direction, SectionRole
from liansuo.stations.station import Station

_WALKABLE = frozenset({SectionRole.throat})


@dataclass(frozen=True)
class Demand:
    turnout: str
    position: str
    why: str


def clearance_m(station: Station, rules: RuleSet) -> float:
    """How far past a fouling point a vehicle must stand to be clear of it (more where EMUs call)."""
    return rules.design.fouling_clearance_emu_m if station.model.emu else rules.design.fouling_clearance_m


class Flank:
    def __init__(self, station: Station, clearance_m: float, *, tables_of: Flank | None = None) -> None:
        """``tables_of``: a flank whose tables to share (they never change once made) instead of working them out."""
        self.st = station
        self._cache: dict[tuple[str, ...], tuple[dict[str, Demand], list[str]]] = {}
        self.role: dict[str, SectionRole]
        self.fouled: set[str]
        self.partners: dict[str, list[str]]
        self.limit: dict[str, float]
        if tables_of is not None:
            self.role, self.fouled = tables_of.role, tables_of.fouled
            self.partners, self.limit = tables_of.partners, tables_of.limit
            return
        self.role = {t: station.sections[tr.section].role for t, tr in station.tracks.items()}
        self.fouled = {fp.track for fp in station.model.fouling_points if fp.track is not None}
        self.partners = {t: [m for m in members if m != t] for members in station.pairs.values() for t in members}
        # turnout -> how far along its legs the fouling limit reaches: a tied fouling point's distance from the
        # turnout, plus the clearance a vehicle needs past it
        self.limit = {}
        for fp in station.model.fouling_points:
            if fp.turnout is not None:
                reach = abs(fp.at - station.turnouts[fp.turnout].at) + clearance_m
                self.limit[fp.turnout] = max(reach, self.limit.get(fp.turnout, 0.0))

    def fresh(self) -> Flank:
        """A flank of its own over the same tables, its memo empty: the memo is keyed by a path's tracks alone, so an
        oracle keeps it to itself, as when it built its flank."""
        return Flank(self.st, 0.0, tables_of=self)

    def of(self, tracks: Sequence[str], turnouts: Mapping[str, str]) -> tuple[dict[str, Demand], list[str]]:
        """(flank turnout -> demand, fouling sections) for a path over ``tracks`` with ``turnouts`` in it."""
        key = tuple(tracks)
        hit = self._cache.get(key)
        if hit is None:
            hit = self._derive(set(tracks), turnouts)
            if len(self._cache) > 4096:
                self._cache.clear()
            self._cache[key] = hit
        return hit

    def _derive(self, path: set[str], turnouts: Mapping[str, str]) -> tuple[dict[str, Demand], list[str]]:
        st = self.st
        crossing = {o for t in path for _, o in st.crossings.get(t, ())} - path
        demands: dict[str, Demand] = {}
        fouling: list[str] = []

        def consider(found: tuple[str, str] | None, why: str) -> None:
            if found is None:
                return
            u, leg = found
            if u in turnouts or leg == "point" or u in demands:
                return
            protective = other(leg)
            if any(turnouts.get(p, protective) != protective for p in self.partners.get(u, ())):
                return  # it lies as its crossover partner in the path, never the protective way
            if self._leads_into(st.leg_track(u, protective), u, path, crossing):
                return  # no position of u leads away from the path
            demands[u] = Demand(u, protective, why)

        for t, pos in turnouts.items():
            free = other(pos)
            start = st.leg_track(t, free)
            consider(self._first_turnout(start, t, path), f"its {free} leg leads onto the free {free} leg of "
                                                            f"turnout {t} in the path")
            sec = self._fouling(start, t)
            if sec is not None and sec not in fouling:
                fouling.append(sec)
        for x in sorted(crossing):
            dia = next(d for p in path for d, o in st.crossings.get(p, ()) if o == x)
            # a vehicle standing on the crossing track fouls the path at the diamond: its section must be clear
            sec = st.tracks[x].section
            if sec not in fouling and not any(st.tracks[p].section == sec for p in path):
                fouling.append(sec)
            for port in st.track_ports[x]:
                if port.leg is not None:
                    found: tuple[str, str] | None = (port.node, port.leg)
                elif port.node in st.joints:
                    lo, hi = st.joint_tracks(port.node)
                    found = self._first_turnout(hi if lo == x else lo, port.node, path)
                else:
                    found = None
                consider(found, f"its leg leads onto track {x}, which crosses the path at diamond {dia}")
        return demands, fouling

    def _first_turnout(self, track: str, node_from: str, path: set[str]) -> tuple[str, str] | None:
        """The first turnout (and the leg it is met on) walking from ``node_from`` along ``track`` and on across
        joints, within the throat; None at an end, outside the throat, back on the path, or at a signal that faces
        movements coming towards the path (they stop at it: the signal protects the flank)."""
        st = self.st
        while True:
            if track in path or self.role[track] not in _WALKABLE:
                return None
            far = st.far_end(track, node_from)
            if far.leg is not None:
                return far.node, far.leg
            if far.node not in st.joints:
                return None
            towards_path = Direction.up if st.node_at(far.node) > st.node_at(node_from) else Direction.down
            if any(s.direction is towards_path for s in st.signals_at(far.node)):
                return None
            track, node_from = st.across(far.node, track), far.node

    def _leads_into(self, track: str, node_from: str, path: set[str], crossing: set[str]) -> bool:
        """Does a movement leaving turnout ``node_from`` along ``track`` reach the path (or a track crossing it)
        before any other turnout?"""
        st = self.st
        while True:
            if track in path or track in crossing:
                return True
            far = st.far_end(track, node_from)
            if far.leg is not None or far.node not in st.joints:
                return False
            track, node_from = st.across(far.node, track), far.node

    def _fouling(self, track: str, turnout: str) -> str | None:
        """The section past the first joint on a free leg, when that joint lies inside the turnout's fouling limit:
        a fouling point beyond the joint, or the joint nearer the turnout than its tied fouling point plus the
        clearance."""
        st = self.st
        node_from = turnout
        while True:
            far = st.far_end(track, node_from)
            if far.leg is not None or far.node not in st.joints:
                return None
            beyond = st.across(far.node, track)
            if st.tracks[beyond].section != st.tracks[track].section:
                inside = abs(st.node_at(far.node) - st.node_at(turnout)) < self.limit.get(turnout, 0.0)
                return st.tracks[beyond].section if beyond in self.fouled or inside else None
            track, node_from = beyond, far.node

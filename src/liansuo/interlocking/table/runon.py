"""Where a shunting movement runs on past the end of its route (调车进路的延续): from a signal of the other direction
it goes on to the next signal of its own, the station limit, an end, or into a station track or spur at sight,
whichever way the turnouts beyond lie; each way is a :class:`~.route.RunOn` with the turnouts it needs."""

from __future__ import annotations

from collections.abc import Sequence

from liansuo.interlocking.table.flank import Flank, driven_turnouts
from liansuo.interlocking.table.route import RouteTurnout, RunOn
from liansuo.stations.schema import Direction, SectionRole, SignalKind, TurnoutPosition
from liansuo.stations.station import Station

_AT_SIGHT = (SectionRole.station_track, SectionRole.spur)


class RunOns:
    """The run-ons of the shunting routes of one station."""

    def __init__(self, station: Station, flank: Flank) -> None:
        self.st = station
        self.topo = station.topology
        self.flank = flank

    def of(self, end_node: str, d: Direction, route_tracks: Sequence[str],
                route_turnouts: set[str]) -> tuple[str | None, tuple[RunOn, ...]]:
        """(track led into at sight, run-ons) of a shunting route ending at a signal of the other direction at
        ``end_node``: the movement goes on to the next signal of its own direction, the station limit, an end, or
        into a station track or spur at sight, whichever way the turnouts beyond lie."""
        st = self.st
        if end_node not in st.joints or any(s.direction is d for s in st.signals_at(end_node)):
            return None, ()  # the end of the network, or a signal of its own direction stops it there
        first = st.entry_track(end_node, d)
        if st.sections[st.tracks[first].section].role in _AT_SIGHT:
            return st.tracks[first].section, ()
        out: list[RunOn] = []
        stack: list[tuple[str, list[str], list[tuple[str, TurnoutPosition]], list[tuple[str, TurnoutPosition]]]] = [
            (first, [], [], [])]
        while stack:
            track, tracks, when, turnouts = stack.pop()
            tracks = [*tracks, track]
            far = self.topo.far_node((track, d))
            if far in st.joints:
                signals = st.signals_at(far)
                nxt = st.entry_track(far, d)
                stop_here = any(s.direction is d for s in signals) or any(
                    s.direction is not d and s.kind is SignalKind.home for s in signals)
                into = st.tracks[nxt].section if st.sections[st.tracks[nxt].section].role in _AT_SIGHT else None
                if not stop_here and into is None:
                    stack.append((nxt, tracks, when, turnouts))
                    continue
                out.append(self._one(tracks, when, turnouts, into, far, route_tracks, route_turnouts))
                continue
            if far in st.ends or len(tracks) > 200:
                out.append(self._one(tracks, when, turnouts, None, far, route_tracks, route_turnouts))
                continue
            leg = next(p.leg for p in st.track_ports[track] if p.node == far)
            if leg == "point":
                for pos in (TurnoutPosition.normal, TurnoutPosition.reverse):
                    stack.append((st.leg_track(far, pos.value), tracks, [*when, (far, pos)],
                                  [*turnouts, (far, pos)]))
            else:
                pos = TurnoutPosition(str(leg))
                stack.append((st.leg_track(far, "point"), tracks, when, [*turnouts, (far, pos)]))
        return None, tuple(sorted(out, key=lambda ro: ro.when))

    def _one(self, tracks: list[str], when: list[tuple[str, TurnoutPosition]],
                    turnouts: list[tuple[str, TurnoutPosition]], into: str | None, end: str,
                    route_tracks: Sequence[str], route_turnouts: set[str]) -> RunOn:
        sections = list(dict.fromkeys(self.st.tracks[t].section for t in tracks))
        needed = [RouteTurnout(t, p, "route") for t, p in turnouts]
        pairs = driven_turnouts(self.st, [t for t, _ in turnouts], dict(turnouts), route_turnouts)
        skip = route_turnouts | {t for t, _ in turnouts} | set(pairs)
        prot, _ = self.flank.of([*route_tracks, *tracks], turnouts, skip)
        needed += [RouteTurnout(t, p, "driven") for t, p in pairs.items()]
        needed += [RouteTurnout(t, p, "protection") for t, p in prot.items()]
        return RunOn(tuple(when), tuple(sections), tuple(needed), into, end)

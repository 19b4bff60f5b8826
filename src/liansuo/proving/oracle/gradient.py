"""What a falling approach calls for, derived for the oracle on its own from the station's geometry and profile.

The published rule (技规 TG/01-2014; TB 10007-2017): where, within braking distance outside a home signal, the line
falls towards the station more steeply than the rule set's ``overlap_gradient_per_mille``, a train received past it
needs an overlap (延续进路) beyond the end of its receiving track, unless the track ends in an isolating device: a
safety line (安全线), whose turnout must then lie towards it. The oracle takes the braking distance from the rule set's
data by line speed, the heights by integrating the profile (a stretch the file does not cover is level), and the
overlap from the end signal through the throat ahead, the straight way, to the station limit (a home signal facing
back), the end of the throat or an end. Nothing here reads the interlocking's derivation.
"""

from __future__ import annotations

from liansuo.rules import RuleSet
from liansuo.stations.schema import Direction, SectionRole, SignalKind
from liansuo.stations.station import Station

Overlap = tuple[tuple[str, ...], dict[str, str]]  # (sections, turnout -> position)


def _height(station: Station, x: float) -> float:
    """Height (metres, relative) at position ``x``, integrating the profile from the lowest position."""
    h = 0.0
    for g in station.model.profile:
        covered = min(x, g.end) - g.start
        if covered > 0:
            h += g.per_mille / 1000.0 * covered
    return h


def steep_homes(station: Station, rules: RuleSet) -> set[str]:
    """The home signals whose approach falls towards the station more steeply than the rule allows within braking
    distance."""
    st = station
    if not st.model.profile:
        return set()
    reach = rules.braking_distance(st.model.line_speed_kmh)
    out: set[str] = set()
    for sig in st.model.signals:
        if sig.kind is not SignalKind.home or (sig.at not in st.joints and sig.at not in st.ends):
            continue
        x = st.node_at(sig.at)
        rear = x - reach if sig.direction is Direction.down else x + reach
        drop = _height(st, rear) - _height(st, x)  # metres lost running in from the rear to the signal
        if drop / reach * 1000.0 > rules.overlap_gradient_per_mille:
            out.add(sig.id)
    return out


def beyond(station: Station, end_signal: str) -> Overlap | None:
    """What protects the far end of a receiving track ending at ``end_signal`` on a falling approach: a safety
    line's turnout lying towards it (no sections), or the overlap the straight way through the throat ahead."""
    st = station
    sig = st.signals[end_signal]
    if sig.at not in st.joints:
        return None
    guard = _safety_line(st, sig.at, sig.direction)
    if guard is not None:
        return (), guard
    tracks, lie = _straight_ahead(st, sig.at, sig.direction)
    if not tracks:
        return None
    return tuple(dict.fromkeys(st.tracks[t].section for t in tracks)), lie


def _safety_line(st: Station, joint: str, d: Direction) -> dict[str, str] | None:
    """The first turnout ahead of ``joint``, met on its point, with one leg leading (across joints only) into a
    safety line: it must lie towards it."""
    lo, hi = st.joint_tracks(joint)
    track, node = (hi if d is Direction.down else lo), joint
    for _ in range(50):
        far = next(p for p in st.track_ports[track] if p.node != node)
        if far.node in st.joints:
            lo, hi = st.joint_tracks(far.node)
            track, node = (hi if lo == track else lo), far.node
            continue
        if far.node not in st.turnouts or far.leg != "point":
            return None
        for leg in ("normal", "reverse"):
            t, n = st.leg_track(far.node, leg), far.node
            for _ in range(50):
                if st.sections[st.tracks[t].section].safety_line:
                    return {far.node: leg}
                end = next(p for p in st.track_ports[t] if p.node != n)
                if end.node not in st.joints:
                    break
                lo, hi = st.joint_tracks(end.node)
                t, n = (hi if lo == t else lo), end.node
        return None
    return None


def _straight_ahead(st: Station, joint: str, d: Direction) -> tuple[list[str], dict[str, str]]:
    tracks: list[str] = []
    lie: dict[str, str] = {}
    node = joint
    lo, hi = st.joint_tracks(joint)
    track = hi if d is Direction.down else lo
    while len(tracks) < 500:
        if st.sections[st.tracks[track].section].role is not SectionRole.throat:
            break
        tracks.append(track)
        far = next(p for p in st.track_ports[track] if p.node != node)
        if far.node in st.joints:
            if any(s.direction is not d and s.kind is SignalKind.home for s in st.signals_at(far.node)):
                break
            lo, hi = st.joint_tracks(far.node)
            track, node = (hi if lo == track else lo), far.node
        elif far.node in st.turnouts:
            leg = far.leg or "point"
            lie[far.node] = "normal" if leg == "point" else leg
            nxt = "normal" if leg == "point" else "point"
            track, node = st.leg_track(far.node, nxt), far.node
            for partner in st.pairs.get(st.turnouts[far.node].pair or "", []):
                lie.setdefault(partner, lie[far.node])
        else:
            break
    return tracks, lie

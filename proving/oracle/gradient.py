"""Overlaps a falling gradient calls for, derived for the oracle on its own from the station's geometry and profile.

The published rule (TB 10007): where the line beyond the end of a receiving track falls more steeply than the rule
set's ``overlap_gradient_per_mille``, a train must be received with an overlap (延续进路) beyond its end signal. The
oracle takes the stretch from the signal through the throat ahead, the straight way, to the station limit (a home
signal facing back), the end of the throat or an end, and its mean gradient by integrating the profile (a stretch the
file does not cover is level). Nothing here reads the interlocking's derivation.
"""

from __future__ import annotations

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


def steep_overlaps(station: Station, min_fall_per_mille: float) -> dict[str, Overlap]:
    """End signal -> the overlap its falling gradient calls for, for every train signal that needs one."""
    st = station
    if not st.model.profile:
        return {}
    out: dict[str, Overlap] = {}
    for sig in st.model.signals:
        if sig.kind is SignalKind.shunting or sig.at not in st.joints:
            continue
        tracks, lie = _straight_ahead(st, sig.at, sig.direction)
        if not tracks:
            continue
        x0 = st.joints[sig.at].at
        last = st.tracks[tracks[-1]]
        ends = [st.node_at(p.node) for p in st.track_ports[last.id]]
        x1 = max(ends) if sig.direction is Direction.down else min(ends)
        drop = _height(st, x0) - _height(st, x1)  # metres lost running from the signal to the end of the stretch
        if abs(x1 - x0) > 0 and drop / abs(x1 - x0) * 1000.0 > min_fall_per_mille:
            out[sig.id] = (tuple(dict.fromkeys(st.tracks[t].section for t in tracks)), lie)
    return out


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

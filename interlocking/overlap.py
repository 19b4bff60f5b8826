"""Overlaps (延续进路) the station's profile calls for.

Where the line beyond a receiving route's end signal falls more steeply than the rule set's
``overlap_gradient_per_mille`` (6 per mille in the Chinese rules: TB 10007), a train that fails to stop at the signal
would run on down the gradient, so the route also locks the throat beyond: from the end signal, along the straight way
(facing turnouts normal, trailing turnouts as they lead), up to the home signal of the other direction (the station
limit), the end of the throat or the end of the line. The gradient is the mean over that stretch. A station file's
own ``overlaps`` entry for the signal replaces what is derived here.
"""

from __future__ import annotations

from dataclasses import dataclass

from liansuo.stations.profile import falling
from liansuo.stations.schema import SectionRole, SignalKind, TurnoutPosition
from liansuo.stations.station import Station


@dataclass(frozen=True)
class ProfileOverlap:
    end_signal: str
    sections: tuple[str, ...]
    turnouts: tuple[tuple[str, TurnoutPosition], ...]
    fall_per_mille: float  # the mean falling gradient beyond the signal that calls for it


def throat_beyond(st: Station, end_signal: str) -> tuple[list[str], list[tuple[str, TurnoutPosition]]]:
    """The tracks and turnouts from ``end_signal`` on through the throat ahead, the straight way, to the station
    limit (a home signal facing the other way), the end of the throat or an end."""
    sig = st.signals[end_signal]
    d = sig.direction
    tracks: list[str] = []
    turnouts: list[tuple[str, TurnoutPosition]] = []
    if sig.at not in st.joints:
        return tracks, turnouts
    track = st.entry_track(sig.at, d)
    for _ in range(500):
        if st.sections[st.tracks[track].section].role is not SectionRole.throat:
            break
        tracks.append(track)
        far = st.topology.far_node((track, d))
        if far in st.joints:
            if any(s.kind is SignalKind.home and s.direction is not d for s in st.signals_at(far)):
                break
            track = st.entry_track(far, d)
        elif far in st.turnouts:
            leg = next(p.leg for p in st.track_ports[track] if p.node == far)
            if leg == "point":
                turnouts.append((far, TurnoutPosition.normal))
                track = st.leg_track(far, "normal")
            else:
                turnouts.append((far, TurnoutPosition(str(leg))))
                track = st.leg_track(far, "point")
        else:
            break
    return tracks, turnouts


def profile_overlap(st: Station, end_signal: str, min_fall_per_mille: float) -> ProfileOverlap | None:
    """The overlap the profile calls for beyond ``end_signal``, or None (no profile, or no steep enough fall)."""
    if not st.model.profile:
        return None
    tracks, turnouts = throat_beyond(st, end_signal)
    if not tracks:
        return None
    sig = st.signals[end_signal]
    start = st.node_at(sig.at)
    end = st.node_at(st.topology.far_node((tracks[-1], sig.direction)))
    fall = falling(st.model.profile, start, end, sig.direction)
    if fall <= min_fall_per_mille:
        return None
    sections = tuple(dict.fromkeys(st.tracks[t].section for t in tracks))
    return ProfileOverlap(end_signal, sections, tuple(turnouts), round(fall, 2))

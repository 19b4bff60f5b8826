"""Overlaps (延续进路) the station's profile calls for.

The rule (技规 TG/01-2014; TB 10007-2017): where, within braking distance OUTSIDE a home signal, the line falls towards
the station more steeply than the rule set's ``overlap_gradient_per_mille`` (6 per mille), a train received past
that signal may fail to stop at the far end of its receiving track. Unless the receiving track ends in an isolating
device (a safety line, 安全线), the receiving route also locks the throat beyond its end signal: from that signal,
along the straight way (facing turnouts normal, trailing turnouts as they lead), up to the home signal of the other
direction (the station limit), the end of the throat or the end of the line. Where a safety line leaves the first
turnout beyond the end signal, that turnout is locked towards it instead, and there is no overlap.

The gradient is the mean over the braking distance in rear of the home signal (the rule set's ``braking_distance_m``
by line speed); a stretch the profile does not cover counts as level. A station file's own ``overlaps`` entry for an
end signal replaces what is derived here.
"""

from __future__ import annotations

from dataclasses import dataclass

from liansuo.rules import RuleSet
from liansuo.stations.profile import falling
from liansuo.stations.schema import Direction, SectionRole, SignalKind, TurnoutPosition
from liansuo.stations.station import Station


@dataclass(frozen=True)
class ProfileOverlap:
    end_signal: str
    sections: tuple[str, ...]  # empty where a safety line isolates the track
    turnouts: tuple[tuple[str, TurnoutPosition], ...]
    fall_per_mille: float  # the mean falling gradient outside the home signal that calls for it
    safety_line: str | None = None  # the safety line's section, where one isolates the receiving track


def approach_fall(st: Station, home: str, rules: RuleSet) -> float:
    """How steeply (per mille, positive downhill) the line falls towards the station over the braking distance
    outside home signal ``home``."""
    sig = st.signals[home]
    if not st.model.profile or (sig.at not in st.joints and sig.at not in st.ends):
        return 0.0
    x = st.node_at(sig.at)
    reach = rules.braking_distance(st.model.line_speed_kmh)
    rear = x - reach if sig.direction is Direction.down else x + reach
    return falling(st.model.profile, rear, x, sig.direction)


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


def safety_line_beyond(st: Station, end_signal: str) -> tuple[str, TurnoutPosition, str] | None:
    """(turnout, position, safety line) where the first turnout beyond ``end_signal``, met facing, leads on one leg
    (through joints only) into a safety line (安全线): the isolating device of the receiving track."""
    sig = st.signals[end_signal]
    if sig.at not in st.joints:
        return None
    track = st.entry_track(sig.at, sig.direction)
    for _ in range(50):
        far = st.topology.far_node((track, sig.direction))
        if far in st.joints:
            track = st.entry_track(far, sig.direction)
            continue
        if far not in st.turnouts or next(p.leg for p in st.track_ports[track] if p.node == far) != "point":
            return None
        for pos in (TurnoutPosition.normal, TurnoutPosition.reverse):
            line = _through_joints(st, st.leg_track(far, pos.value), far)
            if line is not None:
                return far, pos, line
        return None
    return None


def _through_joints(st: Station, track: str, node_from: str) -> str | None:
    """The safety line reached from ``node_from`` along ``track`` and on across joints, before any turnout."""
    for _ in range(50):
        sec = st.tracks[track].section
        if st.sections[sec].safety_line:
            return sec
        far = st.far_end(track, node_from)
        if far.node not in st.joints:
            return None
        track, node_from = st.across(far.node, track), far.node
    return None


def profile_overlap(st: Station, home: str, end_signal: str, rules: RuleSet) -> ProfileOverlap | None:
    """What a receiving route from home signal ``home`` to ``end_signal`` needs beyond its end because of the
    approach gradient: an overlap, or the turnout of a safety line; None where the approach does not fall steeply
    enough."""
    if st.signals[home].kind is not SignalKind.home:
        return None
    fall = approach_fall(st, home, rules)
    if fall <= rules.overlap_gradient_per_mille:
        return None
    isolating = safety_line_beyond(st, end_signal)
    if isolating is not None:
        turnout, pos, line = isolating
        return ProfileOverlap(end_signal, (), ((turnout, pos),), round(fall, 2), line)
    tracks, turnouts = throat_beyond(st, end_signal)
    if not tracks:
        return None
    sections = tuple(dict.fromkeys(st.tracks[t].section for t in tracks))
    return ProfileOverlap(end_signal, sections, tuple(turnouts), round(fall, 2))

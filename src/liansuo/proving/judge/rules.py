"""The published rules' numbers and extents, read from the rule set's data and the station file: what a reference
judge (and ``liansuo verify``) expects of every timer and of approach locking, never what the interlocking or its
derived table says (TB/T 3027-2015, TB 10007-2017, 技规 TG/01-2014; docs/rules.md).
"""

from __future__ import annotations

from liansuo.proving.oracle.authority import Tracer
from liansuo.rules import RuleSet
from liansuo.stations.schema import Direction, LinkKind, SignalKind
from liansuo.stations.station import Station


def release_delay(station: Station, rules: RuleSet, signal: str, kind: str) -> float:
    """Manual time release (总人解) of a route from ``signal``: the signal's own ``release_s``, else the rule set's
    for its kind (180 s train, 30 s shunting)."""
    own = station.signals[signal].release_s
    return own if own is not None else rules.release_s["shunt" if kind == "shunt" else "train"]


def fault_release_delay(rules: RuleSet, kind: str) -> float:
    """Section fault release (区故解) with a train approaching: 180 s (train), the shunting release time (shunt)."""
    return rules.section_fault_release_s if kind == "train" else rules.release_s["shunt"]


def overlap_time(station: Station, rules: RuleSet, end_signal: str) -> float:
    """How long an overlap beyond ``end_signal`` stays locked after the train occupies the receiving track: the
    station file's own overlap's ``release_s``, else the rule set's."""
    own = next((o for o in station.model.overlaps if o.end_signal == end_signal), None)
    return own.release_s if own is not None and own.release_s is not None else rules.overlap_release_s


def approach_extent(station: Station, rules: RuleSet) -> dict[str, tuple[str, ...]]:
    """Each signal's approach (接近区段), as far as the rule set's ``approach_locking`` reaches: a home signal on an
    automatic line the block sections of that many block signals in rear (traced on the track layout), on any other
    line the section in rear; every other signal its sections in rear; the station file's own ``approach`` first."""
    st = station
    tracer = Tracer(st)
    ends_at: dict[str, str] = {}  # signal -> the block signal whose authority ends at it
    for s in st.model.signals:
        if s.kind is SignalKind.block:
            a = tracer.trace(s.id, "train", lambda t: None)
            if a.end_signal is not None:
                ends_at[a.end_signal] = s.id
    reach = rules.approach_locking
    out: dict[str, tuple[str, ...]] = {}
    for sig in st.model.signals:
        if sig.approach:
            out[sig.id] = tuple(sig.approach)
            continue
        rear = st.signal_rear_track(sig.id)
        if rear is None:
            out[sig.id] = ()
            continue
        first = st.tracks[rear].section
        link = next((lk for lk in st.model.links if first in lk.sections), None)
        if sig.kind is SignalKind.home:
            line = "none" if link is None else "automatic" if link.kind is LinkKind.automatic else "64d"
            n = reach.home.get(line, 1)
            if line == "automatic":
                want: list[str] = []
                at = sig.id
                for _ in range(n):
                    block = ends_at.get(at)
                    if block is None:
                        break
                    want += tracer.trace(block, "train", lambda t: None).sections
                    at = block
                out[sig.id] = tuple(dict.fromkeys(want or [first]))
                continue
        else:
            n = reach.other
        out[sig.id] = tuple(_sections_in_rear(st, rear, sig.direction, n))
    return out


def _sections_in_rear(st: Station, track: str, d: Direction, n: int) -> list[str]:
    """``n`` sections from ``track`` backwards (against ``d``), across joints, stopping at a turnout or an end."""
    out = [st.tracks[track].section]
    back = Direction.up if d is Direction.down else Direction.down
    while len(out) < n:
        far = st.topology.far_node((track, back))
        if far not in st.joints:
            break
        track = st.entry_track(far, back)
        sec = st.tracks[track].section
        if sec not in out:
            out.append(sec)
    return out

"""The approach sections of a signal (接近区段): where a train makes its cleared route approach-locked."""

from __future__ import annotations

from liansuo.rules import RuleSet
from liansuo.stations.schema import Direction, Link, SignalKind
from liansuo.stations.station import Station


def sections(st: Station, rules: RuleSet, signal: str) -> tuple[str, ...]:
    """The sections in rear of ``signal`` where a train makes its cleared route approach-locked (接近区段): the
    rule set gives how many block sections for a home signal, by the kind of line in rear, and how many track
    sections for the other signals. A signal's own ``approach`` in the station file overrides it."""
    sig = st.signals[signal]
    if sig.approach:
        return tuple(sig.approach)
    rear = st.signal_rear_track(signal)
    if rear is None:
        return ()
    locking = rules.approach_locking
    back = Direction.up if sig.direction is Direction.down else Direction.down
    line = _line_in_rear(st, rear, back) if sig.kind is SignalKind.home else None
    blocks = line is not None and line.kind.value == "automatic"
    count = locking.home.get(line.kind.value if line else "none", locking.other) \
        if sig.kind is SignalKind.home else locking.other
    out: list[str] = []
    track, passed = rear, 0
    while True:
        sec = st.tracks[track].section
        if sec not in out:
            out.append(sec)
            if not blocks and len(out) >= count:
                break
        near = st.topology.far_node((track, back))
        if near not in st.joints:
            break
        if blocks and any(s.direction is sig.direction for s in st.signals_at(near)):
            passed += 1
            if passed >= count:
                break
        track = st.entry_track(near, back)
    return tuple(out)

def _line_in_rear(st: Station, track: str, back: Direction) -> Link | None:
    for _ in range(100):
        near = st.topology.far_node((track, back))
        if near in st.ends:
            return next((lk for lk in st.model.links if lk.end == near), None)
        if near not in st.joints:
            return None
        track = st.entry_track(near, back)
    return None

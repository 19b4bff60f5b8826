"""What the interlocking's core looks up in its station (:class:`Index`), worked out once per station
(``Station.derived``) for every core of it, and read only."""

from __future__ import annotations

from liansuo.interlocking.aspects import stop_aspect
from liansuo.interlocking.autoblock import AutoBlock
from liansuo.stations.schema import SectionRole
from liansuo.stations.station import Station

# sections the interlocking locks at power-up (上电锁闭): all of the station's own, not the lines'
INTERLOCKED = frozenset({SectionRole.throat, SectionRole.station_track, SectionRole.spur})


class Index:
    """What the core looks up in its station, worked out once per station (``Station.derived``) for every core of it:
    only names and the automatic block chain, none of which changes once made (:class:`~.autoblock.AutoBlock` keeps
    no state of its own between cycles)."""

    def __init__(self, st: Station) -> None:
        self.stop = {s.id: stop_aspect(st, s.id) for s in st.model.signals}  # each signal's stop aspect
        # signal -> (shows USU, its stop aspect, which has a lamp of its own): what its lamp supervision needs
        self.lamp_check = {s.id: (s.usu, self.stop[s.id], self.stop[s.id] in [lamp.value for lamp in s.lamps])
                           for s in st.model.signals}
        self.links = tuple((lk.id, lk.sections[0] if lk.sections else "") for lk in st.model.links
                           if lk.kind.value == "64d")
        self.auto_links = {lk.id: tuple(lk.sections) for lk in st.model.links if lk.kind.value == "automatic"}
        self.station_links = tuple((lk.id, tuple(lk.sections)) for lk in st.model.links if lk.kind.value == "station")
        self.turnouts = tuple((t, st.turnout_section[t], st.turnouts[t].trailable) for t in st.turnouts)
        self.entry_section = {s: st.tracks[st.signal_entry_track(s)].section for s in st.signals}
        self.signal_by_entry: dict[str, list[str]] = {}
        for sig_id, sec in self.entry_section.items():
            self.signal_by_entry.setdefault(sec, []).append(sig_id)
        self.platform_doors = {p.section: [f"{p.id}:{d.side.value}" for d in p.screen_doors]
                               for p in st.model.platforms if p.screen_doors}
        self.autoblock = AutoBlock(st)
        self.interlocked = tuple(name for name, section in st.sections.items() if section.role in INTERLOCKED)
        # signal -> the automatic lines a movement passing it comes from (the section in rear lies on the line)
        line_of = {sec: lk.id for lk in st.model.links if lk.kind.value == "automatic" for sec in lk.sections}
        self.receives_from: dict[str, str] = {}
        for sig in st.signals:
            rear = st.signal_rear_track(sig)
            if rear is not None and st.tracks[rear].section in line_of:
                self.receives_from[sig] = line_of[st.tracks[rear].section]


def guide_area(st: Station, signal: str) -> tuple[frozenset[str], frozenset[str]]:
    """The sections of the throat ``signal`` leads into, and the tracks that border it (station tracks, spurs, the
    lines), whichever way its turnouts lie: where a train guided from it under guide total lock may go."""
    outside = (SectionRole.station_track, SectionRole.approach, SectionRole.block, SectionRole.departure,
               SectionRole.spur)
    start = st.signal_entry_track(signal)
    seen, todo = {start}, [start]
    throat, border = {st.tracks[start].section}, set()
    while todo:
        track = todo.pop()
        for port in st.track_ports[track]:
            for _, nxt in st.node_tracks[port.node]:
                sec = st.tracks[nxt].section
                if nxt in seen or nxt == st.signal_rear_track(signal):
                    continue
                seen.add(nxt)
                if st.sections[sec].role in outside:
                    border.add(sec)
                else:
                    throat.add(sec)
                    todo.append(nxt)
    return frozenset(throat), frozenset(border)

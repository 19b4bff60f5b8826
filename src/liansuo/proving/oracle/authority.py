"""Movement authorities traced from the track layout and the turnouts as they lie.

An open signal gives a movement authority: the path a movement that passes it would run, following each turnout
the way its switch rails lie, to the end of that authority. Nothing here reads the interlocking table or asks the
interlocking anything; the path comes from the station's geometry and the field.

Where an authority ends:

- a **train** runs to the next train signal (home, starting, route or block) facing the same way, a buffer stop or
  the boundary of the station model; shunting signals on the way do not govern it. Where the station file asks for
  an overlap (延续进路) beyond that signal, or a train received past a home signal on a steep falling approach needs
  one (:mod:`.gradient`), the overlap's sections and turnouts belong to the authority too.
- a **shunting** movement runs to the next signal facing the same way, a buffer stop, or the station limit (a home
  signal faced from inside). Signals facing the other way do not stop it: where a shunting route ends at one, the
  movement goes past it to reverse, and nothing on the track tells how far. Where it enters a station track or a
  spur from the throat it goes on at sight (it may couple to vehicles standing there): the authority ends at the
  entry and *leads into* that track.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from typing import Literal

from liansuo.proving.oracle.gradient import Overlap, beyond, steep_homes
from liansuo.rules import RuleSet
from liansuo.stations.schema import Direction, SectionRole, SignalKind
from liansuo.stations.station import Station

Kind = Literal["train", "shunt"]
Lies = Callable[[str], "str | None"]  # turnout -> where its switch rails lie ('normal', 'reverse' or None)

AT_SIGHT = frozenset({SectionRole.station_track, SectionRole.spur})
LINE = frozenset({SectionRole.approach, SectionRole.departure, SectionRole.block})
TRAIN_SIGNALS = frozenset({SignalKind.home, SignalKind.starting, SignalKind.route, SignalKind.block})


def other(position: str) -> str:
    return "reverse" if position == "normal" else "normal"


@dataclass
class Authority:
    """One movement authority: the path from a signal to the end of its authority, and what it takes in."""

    signal: str
    kind: Kind
    direction: Direction
    tracks: list[str] = field(default_factory=list)  # the path, in order
    sections: list[str] = field(default_factory=list)  # sections of the path, in order
    turnouts: dict[str, str] = field(default_factory=dict)  # path turnout -> the position the path needs
    trailing: set[str] = field(default_factory=set)  # path turnouts run through from a leg to the point
    against: list[str] = field(default_factory=list)  # trailing turnouts lying against the path
    decided: list[str] = field(default_factory=list)  # facing turnouts whose lying chose the path
    diamonds: set[str] = field(default_factory=set)
    end: str = ""  # signal, buffer, boundary, limit, track, broken, loop
    end_node: str = ""
    end_signal: str | None = None
    broken_at: str | None = None  # the facing turnout between positions where the path cannot be traced
    link: str | None = None  # block link the path runs out onto
    leads_into: str | None = None  # station track or spur entered at sight
    overlap_sections: tuple[str, ...] = ()
    overlap_turnouts: dict[str, str] = field(default_factory=dict)
    overlap_release_s: float = 0.0

    @property
    def all_sections(self) -> list[str]:
        """Every section the authority takes in: path and overlap."""
        return self.sections + [s for s in self.overlap_sections if s not in self.sections]

    def needed(self) -> dict[str, str]:
        """Every turnout whose position the authority depends on: path and overlap."""
        out = dict(self.overlap_turnouts)
        out.update(self.turnouts)
        return out


class Tracer:
    """Traces authorities over one station."""

    def __init__(self, station: Station, *, overlap_release_s: float = 0.0, rules: RuleSet | None = None) -> None:
        """``overlap_release_s``: the rule set's overlap release time, for an overlap whose station file gives none
        (only an oracle that times overlaps needs it); ``rules``: the rule set whose data says where a falling
        approach calls for an overlap beyond the receiving track (None: only the file's overlaps)."""
        self.st = station
        self.overlap_release_s = overlap_release_s
        self.topo = station.topology
        self.role = {s: sec.role for s, sec in station.sections.items()}
        self.section_of = {t: tr.section for t, tr in station.tracks.items()}
        self.link_at = {lk.end: lk.id for lk in station.model.links}
        # home signals on a steep falling approach: their trains need an overlap beyond the receiving track
        self.steep = steep_homes(station, rules) if rules is not None else set()
        self._beyond: dict[str, Overlap | None] = {}
        # end signal -> the file's own overlaps (sections, turnout lie, release time); alternatives after the basic
        self.overlaps: dict[str, list[tuple[tuple[str, ...], dict[str, str], float]]] = {}
        for o in station.model.overlaps:
            self.overlaps.setdefault(o.end_signal, []).append((
                tuple(o.sections), {t.turnout: t.position.value for t in o.turnouts},
                o.release_s if o.release_s is not None else overlap_release_s))
        # the port of a track at a turnout: (track, turnout) -> leg
        self.leg_at: dict[tuple[str, str], str] = {}
        for tid, ports in station.track_ports.items():
            for p in ports:
                if p.leg is not None:
                    self.leg_at[(tid, p.node)] = p.leg

    def trace(self, signal: str, kind: Kind, lies: Lies) -> Authority:
        st = self.st
        sig = st.signals[signal]
        d = sig.direction
        a = Authority(signal, kind, d)
        track = st.entry_track(sig.at, d)
        seen: set[str] = set()
        while True:
            if track in seen:
                a.end = "loop"
                return a
            seen.add(track)
            self._add(a, track)
            far = self.topo.far_node((track, d))
            a.end_node = far
            if far in st.ends:
                a.end = st.ends[far].kind.value
                a.link = self.link_at.get(far)
                break
            if far in st.joints:
                nxt = st.entry_track(far, d)
                if self._stops_at_joint(a, far, track, nxt):
                    break
                track = nxt
                continue
            leg = self.leg_at[(track, far)]
            if leg == "point":  # facing: the rails choose the way
                pos = lies(far)
                if pos is None:
                    a.end = "broken"
                    a.broken_at = far
                    return a
                a.turnouts[far] = pos
                a.decided.append(far)
                track = st.leg_track(far, pos)
            else:  # trailing: the path needs the rails lying to the leg it comes from
                a.turnouts[far] = leg
                a.trailing.add(far)
                if lies(far) != leg:
                    a.against.append(far)
                track = st.leg_track(far, "point")
        if kind == "train" and a.end == "signal" and a.end_signal in self.overlaps:
            # of alternative overlaps, the one the turnouts beyond lie for (else the basic one, whose turnouts
            # then lie against it)
            options = self.overlaps[a.end_signal]
            chosen = next((o for o in options if all(lies(t) == p for t, p in o[1].items())), options[0])
            a.overlap_sections, turnouts, a.overlap_release_s = chosen
            a.overlap_turnouts = dict(turnouts)
        elif kind == "train" and a.end == "signal" and signal in self.steep and a.end_signal is not None:
            if a.end_signal not in self._beyond:
                self._beyond[a.end_signal] = beyond(self.st, a.end_signal)
            found = self._beyond[a.end_signal]
            if found is not None:  # an overlap, or a safety line's turnout (no sections)
                a.overlap_sections, a.overlap_turnouts = found[0], dict(found[1])
                a.overlap_release_s = self.overlap_release_s
        return a

    def _add(self, a: Authority, track: str) -> None:
        a.tracks.append(track)
        sec = self.section_of[track]
        if not a.sections or a.sections[-1] != sec:
            a.sections.append(sec)
        for dia, _ in self.st.crossings.get(track, ()):
            a.diamonds.add(dia)

    def _stops_at_joint(self, a: Authority, joint: str, track: str, nxt: str) -> bool:
        """Does the authority end at ``joint`` (between ``track`` and ``nxt``)? Sets how it ends."""
        d = a.direction
        signals = self.st.signals_at(joint)
        same = [s for s in signals if s.direction is d]
        facing_it = [s for s in signals if s.direction is not d]
        if a.kind == "train":
            for s in same:
                if s.kind in TRAIN_SIGNALS:
                    a.end, a.end_signal = "signal", s.id
                    return True
            return False
        if same:
            a.end, a.end_signal = "signal", same[0].id
            return True
        if any(s.kind is SignalKind.home for s in facing_it):
            a.end = "limit"  # shunting stops at the station limit
            return True
        beyond = self.section_of[nxt]
        if self.role[beyond] in AT_SIGHT and self.role[self.section_of[track]] not in AT_SIGHT:
            a.end, a.leads_into = "track", beyond
            return True
        return False

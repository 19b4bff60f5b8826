"""A reference judge of the operator's commands and of the releases, apart from the interlocking and the oracle.

The oracle (:mod:`proving.oracle`) judges what the field shows: authorities, aspects, turnouts. It has no view of
approach locking, release timing or the power-up lock. The judge has, from the published rules alone (its numbers
from the rule set's data: :mod:`.rules`) and what an observer of the console sees (the commands and whether they were
accepted, the aspects lit, the sections shown locked, the track relays):

- ``cancel``: a route whose signal has been given, with a train in its approach (接近锁闭), is never cancelled at
  once (TB/T 3027: only a manual time release frees it); a guide aspect under guide total lock has no route, and
  cancelling it only closes it (the throat's lock stays until the operator's sealed guide-unlock);
- ``release``: a manual time release (总人解) of an approach-locked route keeps the route locked for the whole
  delay (180 s train, 30 s shunting, or the signal's own), unless a train enters it;
- ``released-occupied``: no section of a route's path is released while its track relay shows it occupied (but
  the receiving track the train stands on);
- ``power-up``: after the interlocking starts, nothing is set and no turnout thrown before the power-up release
  (上电解锁), and that release is never given with a section of the station showing occupied;
- ``reopen``: a signal closed abnormally is never reopened (重复开放) while a section of its route shows occupied;
- ``guide``: a guide aspect (引导, HB) closes once the guided train has entered, and closes by itself after the rule
  set's ``guide_close_s`` unused;
- ``overlap-time``: an overlap (延续进路) stays locked for its release time after the train reached the receiving
  track, and the fault release of the overlap or of a station track is never granted.

Each finding is an :class:`~liansuo.proving.oracle.records.Finding`, reported by the watch beside the oracle's.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from liansuo.proving.judge.rules import approach_extent, fault_release_delay, overlap_time, release_delay
from liansuo.proving.oracle.authority import Tracer
from liansuo.proving.oracle.gradient import beyond, steep_homes
from liansuo.proving.oracle.lamps import LampReader
from liansuo.proving.oracle.records import Finding
from liansuo.proving.oracle.view import FieldView
from liansuo.rules import RuleSet
from liansuo.stations.schema import SectionRole, SignalKind
from liansuo.stations.station import Station

TOLERANCE_S = 1.0  # what the judge lets pass of a timer: a cycle to see, a cycle to act, a little more
_SETS = ("route", "shunt", "guide")
_STATION = (SectionRole.throat, SectionRole.station_track, SectionRole.spur)


@dataclass
class Claim:
    """A route the operator set from ``signal`` (an accepted ``route``, ``shunt`` or ``guide``), as the judge
    follows it: whether its signal has been given, the path its authority took, and what is owed."""

    signal: str
    kind: str  # train, shunt
    given: bool = False
    path: tuple[str, ...] = ()  # the sections of its authority the last time its signal was given, in order
    end_signal: str | None = None
    entered: bool = False  # its first section was occupied after the signal was given
    hold_until: float | None = None  # a time release counting down: the path stays locked until then
    guide_since: float | None = None  # the guide aspect lit since
    guide_approached: bool = False
    guide_entered_at: int | None = None  # checks since the guided train entered (the signal must close by then)
    guide_first_clear: bool = True  # the first section showed clear when the guide aspect lit (else it is the red
    # band the guide is for: the train has entered once it has passed the signal, its approach clear again)
    overlap_owed: bool = True  # the overlap time has not started yet
    first_clear: bool = True  # its first section showed clear when its signal was first given
    guided: bool = False  # a guide aspect was given for it: a guided train runs at sight, with no overlap
    total_lock: bool = False  # a guide aspect under guide total lock: no route, the throat's lock holds the turnouts,
    # and cancelling closes the aspect only (nothing is released that approach locking would keep)


@dataclass
class OverlapHold:
    """Sections that must stay locked until ``until`` (an overlap behind a received train)."""

    what: str
    sections: tuple[str, ...]
    until: float


@dataclass
class JudgeMemory:
    claims: dict[str, Claim] = field(default_factory=dict)
    holds: list[OverlapHold] = field(default_factory=list)
    powered_up: bool = False  # since a restart, until the power-up release
    locked: set[str] = field(default_factory=set)  # sections shown locked at the last check
    commanded: bool = False  # a command that releases by hand was accepted since the last check
    active: set[str] = field(default_factory=set)  # findings of the last check: reported when they start, once
    # the first sections of claims waiting for their signal that showed occupied when the claim was made and at
    # each check since: one occupied only since then is a movement entering as the aspect lit, not a red band
    occupied_before: frozenset[str] = frozenset()


class JudgeTables:
    """What the judge reads of a station and rule set, once."""

    def __init__(self, station: Station, rules: RuleSet) -> None:
        self.tracer = Tracer(station, overlap_release_s=rules.overlap_release_s, rules=rules)
        self.extent = approach_extent(station, rules)
        self.reader = LampReader(rules.aspects)
        self.steep = steep_homes(station, rules)
        self.station_sections = tuple(s for s, sec in station.sections.items() if sec.role in _STATION)
        # the first section of any authority a signal gives: the one a movement passing it enters
        self.entry = {sig.id: station.tracks[station.signal_entry_track(sig.id)].section
                      for sig in station.model.signals}
        self.overlaps: dict[tuple[str, str], tuple[tuple[str, ...], float]] = {}  # (home, end) -> sections, time
        for sig in station.model.signals:
            if sig.kind is not SignalKind.home:
                continue
            for end in station.model.signals:
                own = [o for o in station.model.overlaps if o.end_signal == end.id]
                if own:
                    self.overlaps[(sig.id, end.id)] = (tuple(own[0].sections), overlap_time(station, rules, end.id))
                elif sig.id in self.steep:
                    found = beyond(station, end.id)
                    if found is not None and found[0]:
                        self.overlaps[(sig.id, end.id)] = (found[0], overlap_time(station, rules, end.id))


class Judge:
    def __init__(self, station: Station, rules: RuleSet, *, reaction: int = 2) -> None:
        self.st = station
        self.rules = rules
        self.reaction = reaction
        self.tables = station.derived(JudgeTables, rules)
        self.memory = JudgeMemory()

    def busy(self) -> bool:
        """Does a check depend on time alone? Only while a guide aspect is lit (it must close by itself unused): a
        time release or an overlap kept too short shows as a lock released, which the watch sees anyway."""
        return any(c.guide_since is not None for c in self.memory.claims.values())

    # ---- commands ----------------------------------------------------------------------------------------------
    def note(self, words: list[str], accepted: bool, view: FieldView, now: float) -> list[Finding]:
        if not accepted or not words:
            return []
        m, word = self.memory, words[0]
        out: list[Finding] = []
        if word in ("cancel", "release", "fault-release", "restart", "power-up-release", "guide-unlock"):
            m.commanded = True  # what it releases, it releases on the operator's word
        if word == "restart":
            m.claims.clear()
            m.locked = set()
            m.powered_up = True
            return out
        if m.powered_up and word in (*_SETS, "throw"):
            out.append(self._finding("power-up", words, f"'{' '.join(words)}' was accepted before the power-up "
                                     "release (上电解锁): the station stays locked until it is given"))
        if word == "power-up-release":
            m.powered_up = False
            occupied = [s for s in self.tables.station_sections if not view.clear(s)]
            if occupied:
                out.append(self._finding("power-up", words, f"the power-up release was given with {occupied[0]} "
                                         "showing occupied"))
            return out
        sig = words[1] if len(words) > 1 else ""
        if word in _SETS and len(words) >= 3:
            m.claims[sig] = Claim(sig, "shunt" if word == "shunt" else "train")
            m.occupied_before = self._occupied(view)
        elif word == "guide" and len(words) == 2 and sig not in m.claims:
            m.claims[sig] = Claim(sig, "train", total_lock=True)
            m.occupied_before = self._occupied(view)
        elif word == "guide" and len(words) == 2:  # given again over its route: a new aspect, its time starts now
            c = m.claims[sig]
            c.guide_since, c.guide_approached, c.guide_entered_at = now, False, None
            c.guide_first_clear = not c.path or view.clear(c.path[0])
        elif word == "cancel" and sig in m.claims:
            if self._approach_locked(m.claims[sig], view) and not m.claims[sig].total_lock:
                out.append(self._finding("cancel", words, f"'cancel {sig}' was accepted at once with a train "
                                         f"approaching {sig} after its signal was given (接近锁闭)"))
            del m.claims[sig]
        elif word == "release" and sig in m.claims:
            c = m.claims[sig]
            if self._approach_locked(c, view):
                c.hold_until = now + release_delay(self.st, self.rules, sig, c.kind)
            else:
                del m.claims[sig]
        elif word == "fault-release":
            out += self._fault_release(words, view, now)
        elif word == "reopen" and sig in m.claims:
            busy = [s for s in m.claims[sig].path if not view.clear(s)]
            if busy:
                out.append(self._finding("reopen", words, f"'reopen {sig}' was accepted with {busy[0]} of its route "
                                         "showing occupied (重复开放 needs the conditions back)"))
        return out

    def _fault_release(self, words: list[str], view: FieldView, now: float) -> list[Finding]:
        section = words[1] if len(words) > 1 else ""
        if section in self.st.sections and self.st.is_station_track(section):
            return [self._finding("fault-release", words, f"section fault release of station track {section} was "
                                  "accepted")]
        out = []
        for c in self.memory.claims.values():
            if section not in c.path:
                continue
            if c.guide_since is None and c.given and self._showing(c.signal, view):
                out.append(self._finding("fault-release", words, f"section fault release of {section} was accepted "
                                         f"under the open signal {c.signal}"))
            elif self._approach_locked(c, view) and not c.entered:
                c.hold_until = now + fault_release_delay(self.rules, c.kind)
        for h in self.memory.holds:
            if section in h.sections:
                out.append(self._finding("overlap-time", words, f"section fault release of {section} was accepted "
                                         f"while {h.what} holds it (its time is not over)"))
        return out

    # ---- every cycle -----------------------------------------------------------------------------------------
    def check(self, view: FieldView, now: float, showing: tuple[str, ...]) -> list[Finding]:
        m = self.memory
        out: list[Finding] = []
        if not m.claims and not m.holds and not m.active:
            m.locked, m.commanded, m.occupied_before = set(), False, frozenset()
            return out
        # only what the claims and holds look at: a hub has hundreds of sections and signals
        watched = {s for c in m.claims.values() for s in c.path} | {s for h in m.holds for s in h.sections}
        locked = {s for s in watched if view.section_locked(s)}
        lit = set(showing)
        guide = self.rules.aspects.guide
        for sig, c in list(m.claims.items()):
            aspect = self.tables.reader.read(view.lit(sig), view.flashing(sig)) if sig in lit else ""
            open_ = self.rules.aspects.is_proceed(aspect)
            if open_:
                a = self.tables.tracer.trace(sig, "shunt" if aspect == self.rules.aspects.shunt else "train",
                                             view.rails)
                if not c.given:
                    c.first_clear = self._first_clear(a.sections, view)
                c.given, c.path, c.end_signal = True, tuple(a.sections), a.end_signal
                c.guided = c.guided or aspect == guide
            if c.given and c.path and not c.entered and not view.clear(c.path[0]) and (
                    c.first_clear or not any(not view.clear(s) for s in self.tables.extent.get(c.signal, ()))):
                c.entered = True  # the first section taken after the signal was given (not the red band it was for)
            out += self._guide(c, aspect == guide, view, now)
            out += self._released(c, locked, view, now)
            self._arrival(c, view, now)
            if not open_ and c.given and c.path and c.hold_until is None \
                    and not any(view.section_locked(s) for s in c.path):
                del m.claims[sig]  # released
        keep = []
        for h in m.holds:
            if now >= h.until - TOLERANCE_S:
                continue
            free = [s for s in h.sections if not view.section_locked(s)]
            if free:
                out.append(Finding(f"overlap-time:{h.what}", "overlap-time", f"{h.what} was released "
                                   f"{h.until - now:.1f} s before its time ({', '.join(free)} free)"))
                continue
            keep.append(h)
        m.holds = keep
        # what is locked of what the claims and holds look at now (a path just traced included)
        watched = {s for c in m.claims.values() for s in c.path} | {s for h in m.holds for s in h.sections}
        m.locked = {s for s in watched if view.section_locked(s)}
        m.commanded = False
        m.occupied_before = self._occupied(view) if any(not c.given for c in m.claims.values()) else frozenset()
        new = [f for f in out if f.key not in m.active]
        m.active = {f.key for f in out}
        return new

    def _released(self, c: Claim, locked: set[str], view: FieldView, now: float) -> list[Finding]:
        out = []
        before = self.memory.locked
        for s in c.path if not self.memory.commanded else ():
            if s in before and s not in locked and not view.clear(s) and not self.st.is_station_track(s):
                out.append(Finding(f"released-occupied:{s}", "released-occupied", f"section {s} of the route of "
                                   f"{c.signal} was released while it shows occupied"))
        if c.hold_until is not None:
            if c.entered or now >= c.hold_until - TOLERANCE_S:
                c.hold_until = None
            else:
                free = [s for s in c.path if s not in locked]
                if free and any(s in before for s in free):
                    out.append(Finding(f"release:{c.signal}", "release", f"the route of {c.signal} was released "
                                       f"{c.hold_until - now:.1f} s before the end of its time release "
                                       f"({', '.join(free)} free)"))
                    c.hold_until = None
        return out

    def _guide(self, c: Claim, lit: bool, view: FieldView, now: float) -> list[Finding]:
        if not lit:
            c.guide_since, c.guide_approached, c.guide_entered_at = None, False, None
            return []
        approach = any(not view.clear(s) for s in self.tables.extent.get(c.signal, ()))
        if c.guide_since is None:
            c.guide_since = now
            c.guide_first_clear = self._first_clear(c.path, view)
        if approach:
            c.guide_approached = True
        out = []
        entered = (not view.clear(c.path[0]) if c.guide_first_clear else not approach) if c.path else False
        if c.guide_approached and entered:
            c.guide_entered_at = (c.guide_entered_at or 0) + 1
            if c.guide_entered_at > self.reaction + 1:
                out.append(Finding(f"guide:{c.signal}:entered", "guide", f"the guide aspect of {c.signal} is still lit "
                                   f"after the guided train entered {c.path[0]}"))
        if not c.guide_approached and now - c.guide_since > self.rules.guide_close_s + TOLERANCE_S:
            out.append(Finding(f"guide:{c.signal}:unused", "guide", f"the guide aspect of {c.signal} is still lit "
                               f"{now - c.guide_since:.0f} s after it was given, unused (the rules close it after "
                               f"{self.rules.guide_close_s:g} s)"))
        return out

    def _arrival(self, c: Claim, view: FieldView, now: float) -> None:
        """A received train stands on its track: the overlap's time starts."""
        if not (c.given and c.entered and c.overlap_owed and c.path and c.end_signal) or c.guided:
            return
        last = c.path[-1]
        if not self.st.is_station_track(last) or view.clear(last):
            return
        c.overlap_owed = False
        found = self.tables.overlaps.get((c.signal, c.end_signal))
        if found is not None and all(view.section_locked(s) for s in found[0]):  # (one never locked: verify's)
            sections, time = found
            hold = OverlapHold(f"the overlap of {c.signal} beyond {c.end_signal}", sections, now + time)
            self.memory.holds.append(hold)

    # ---- helpers -----------------------------------------------------------------------------------------------
    def _occupied(self, view: FieldView) -> frozenset[str]:
        """The first sections of the claims waiting for their signal that show occupied."""
        entries = {self.tables.entry[c.signal] for c in self.memory.claims.values() if not c.given}
        return frozenset(s for s in entries if not view.clear(s))

    def _first_clear(self, path: tuple[str, ...] | list[str], view: FieldView) -> bool:
        """The first section of ``path`` was clear when its signal was given: clear now, or occupied only since the
        last look (the movement entered as the aspect lit)."""
        return not path or view.clear(path[0]) or path[0] not in self.memory.occupied_before

    def _approach_locked(self, c: Claim, view: FieldView) -> bool:
        return c.given and any(not view.clear(s) for s in self.tables.extent.get(c.signal, ()))

    def _showing(self, signal: str, view: FieldView) -> bool:
        return self.rules.aspects.is_proceed(self.tables.reader.read(view.lit(signal), view.flashing(signal)))

    def _finding(self, prop: str, words: list[str], text: str) -> Finding:
        return Finding(f"{prop}:{' '.join(words)}", prop, text)

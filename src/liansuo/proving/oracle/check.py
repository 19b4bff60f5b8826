"""The safety oracle: each cycle, the movement authorities of the open signals and of the movements under way,
judged against the safety properties (docs/safety.md), from the station topology and the field alone.

An **open authority** belongs to a signal showing a proceed aspect. When that signal closes because its movement
has entered (its first section occupied), the authority stays with the movement **in use**: what the movement has
passed (occupied and clear again) falls away behind it, a receiving track is taken as reached once the movement is
on it, and an overlap is held for its release time after that. An authority whose movement has left it (none of
its sections occupied any more) ends.

Findings are **violations** (the interlocking let something unsafe happen) or **hazards** (the danger exists but the
interlocking cannot see it by design: a vehicle hidden in a dead zone or shunting poorly). A violation caused by the
world (a section occupied, a lamp or an indication lost, a door opening, the aspect ahead changing) is reported only
when the interlocking has not answered within ``reaction`` checks: a real CBI needs one cycle to see a relay and
the lamps one more to follow its command. What the interlocking does itself (moving a turnout, letting two
authorities meet, reopening a signal) is reported at once.
"""

from __future__ import annotations

from collections.abc import Iterable

from liansuo.proving.oracle.authority import Authority
from liansuo.proving.oracle.ceiling import permits
from liansuo.proving.oracle.flank import Demand
from liansuo.proving.oracle.lamps import UNDEFINED
from liansuo.proving.oracle.meet import head_on, shared
from liansuo.proving.oracle.records import Finding, Held, InUse
from liansuo.proving.oracle.tables import Tables
from liansuo.proving.oracle.view import FieldView
from liansuo.rules import RuleSet
from liansuo.stations.schema import SectionRole, SignalKind
from liansuo.stations.station import Station

TURNOUT_AREA_M = 40.0  # wheelsets this close to a turnout's point stand on its switch panel


class Oracle:
    def __init__(self, station: Station, rules: RuleSet, *, cycle_s: float = 0.25, reaction: int = 2) -> None:
        self.st = station
        tables = station.derived(Tables, rules)  # read only: shared by every oracle of this station and rule set
        self.tracer = tables.tracer
        self.flank = tables.flank.fresh()
        self.aspects = rules.aspects
        self.reader = tables.reader
        self.ceiling = tables.ceiling
        self.onto_track = tables.onto_track
        self.cycle_s = cycle_s
        self.reaction = reaction
        self.kind = tables.kind
        self.lamps = tables.lamps
        self.rear = tables.rear
        self.doors = tables.doors
        self.role = tables.role
        self.section_of = tables.section_of
        self.turnout_section = tables.turnout_section
        self.turnout_sections = tables.turnout_sections
        self.turnout_tracks = tables.turnout_tracks
        self.pair_of = tables.pair_of
        self.lines = tables.lines
        # what the oracle remembers between checks
        self.open: dict[str, Authority] = {}  # signal -> its authority at the last check
        self.shown: dict[str, str] = {}  # signal -> the proceed aspect it showed at the last check
        self.in_use: list[InUse] = []
        self.guide_given: set[str] = set()  # signals open on an authority given as a guide aspect
        self.closed: set[str] = set()  # signals that closed and have not been reopened by the operator since
        self.allowed: set[str] = set()  # signals the operator may open again (an accepted route, reopen or guide)
        self.pending: dict[str, int] = {}  # delayed finding -> consecutive checks it has lasted
        self.active: set[str] = set()
        self.was_moving: dict[str, str | None] = {}
        self.approached: set[str] = set()  # open signals whose section in rear was occupied at the last check
        self.operated: set[str] = set()  # open guide aspects the operator answers for
        self.guide_locked: set[str] = set()  # throats (named by their home signal) under guide total lock
        # sections the operator released by section fault release (区故解) while a movement's authority still reached
        # over them: the interlocking grants it on the operator's word, so what follows there is a hazard
        self.fault_released: set[str] = set()
        self.turnout_sections_occupied: set[str] = set()  # turnout sections occupied at the last check
        self.now = 0.0

    def busy(self) -> bool:
        """Does the next check depend on time alone: a finding waiting for the interlocking's answer, or an overlap
        held for its release time?"""
        return bool(self.pending) or any(u.reached_at is not None and u.auth.overlap_sections and not u.guided
                                         for u in self.in_use)

    # ---- the operator's commands ----------------------------------------------------------------------------------
    def note(self, words: list[str], accepted: bool) -> None:
        """An operator command and whether the interlocking accepted it: a route set from a signal, ``reopen`` and
        ``guide`` are what may open a signal that closed."""
        if accepted and len(words) >= 2 and words[0] in ("route", "shunt", "reopen", "guide"):
            self.allowed.add(words[1])
        if accepted and len(words) >= 2 and words[0] == "guide-lock":
            self.guide_locked.add(words[1])
        elif accepted and len(words) >= 2 and words[0] == "guide-unlock":
            self.guide_locked.discard(words[1])
        elif accepted and len(words) >= 2 and words[0] == "fault-release":
            self.fault_released.add(words[1])
        elif accepted and words[:1] == ["restart"]:
            self.guide_locked.clear()
            self.fault_released.clear()

    # ---- one check ---------------------------------------------------------------------------------------------------
    def check(self, view: FieldView, now: float, showing: Iterable[str]) -> list[Finding]:
        """Judge the world as ``view`` shows it; ``showing`` are the signals with a lamp lit other than their stop
        lamp. Returns the findings that start at this check."""
        self.now = now
        found: dict[str, Finding] = {}
        shown = self._read(view, showing, found)
        held: list[Held] = []
        for sig, aspect in shown.items():
            a = self.open[sig]
            held.append(self._judge_open(sig, aspect, a, view, shown, found))
        self._lines(held, view, found)
        held += self._in_use(view)
        self.fault_released &= {s for u in self.in_use for s in u.sections}  # the movement's authority is gone
        self._across(held, found)
        self._moving(view, held, found)
        return self._report(found)

    def _report(self, found: dict[str, Finding]) -> list[Finding]:
        new: list[Finding] = []
        active: set[str] = set()
        pending: dict[str, int] = {}
        for key, f in found.items():
            if f.delayed:
                n = self.pending.get(key, 0) + 1
                pending[key] = n
                if n <= self.reaction:
                    continue
            active.add(key)
            if key not in self.active:
                new.append(f)
        self.pending = pending
        self.active = active
        return new

    # ---- signals: what they show, opening and closing ----------------------------------------------------------------
    def _read(self, view: FieldView, showing: Iterable[str], found: dict[str, Finding]) -> dict[str, str]:
        shown: dict[str, str] = {}
        for sig in showing:
            aspect = self.reader.read(view.lit(sig), view.flashing(sig))
            if aspect == UNDEFINED:
                found[f"lamps:{sig}"] = Finding(f"lamps:{sig}", "lamps", f"signal {sig} lights "
                                                f"{'+'.join(sorted(view.lit(sig)))}, which no aspect lights",
                                                delayed=True)
            elif self.aspects.is_proceed(aspect):
                shown[sig] = aspect
        for sig in [s for s in self.shown if s not in shown]:
            a = self.open.pop(sig)
            rear = self.rear[sig]
            entered = rear is None or sig in self.approached or not view.clear(rear)
            if entered and not view.clear(a.sections[0]):
                # given as a guide aspect, whatever its lamps showed last (HB with its red lamp dark shows B alone)
                self._start_in_use(a, view, sig in self.operated, guided=sig in self.guide_given)
            self.guide_given.discard(sig)
            self.operated.discard(sig)
            if self.kind[sig] is not SignalKind.block:
                self.closed.add(sig)
        for sig, aspect in shown.items():
            if sig not in self.shown:
                if sig in self.closed and sig not in self.allowed:
                    found[f"reopened:{sig}"] = Finding(f"reopened:{sig}", "reopened", f"signal {sig} opened again "
                                                       f"({aspect}) after it closed, with no route, reopen or guide "
                                                       "command from the operator")
                self.closed.discard(sig)
                self.allowed.discard(sig)
            kind = "shunt" if aspect == self.aspects.shunt else "train"
            self.open[sig] = self._trace(sig, kind, view)
        self.shown = shown
        self.guide_given |= {sig for sig, aspect in shown.items() if aspect == self.aspects.guide}
        self.approached = {sig for sig in shown if (rear := self.rear[sig]) is not None and not view.clear(rear)}
        return shown

    def _trace(self, sig: str, kind: str, view: FieldView) -> Authority:
        old = self.open.get(sig)
        if old is not None and old.kind == kind and old.end != "broken" and not old.against \
                and all(view.rails(t) == p for t, p in old.turnouts.items()):
            return old
        return self.tracer.trace(sig, kind, view.rails)  # type: ignore[arg-type]

    def _repertoire(self, sig: str, aspect: str) -> bool:
        kind, names = self.kind[sig], self.aspects
        if kind is SignalKind.shunting:
            return aspect == names.shunt
        if kind is SignalKind.block:
            return aspect in names.automatic_block
        if aspect == names.shunt:
            return kind is SignalKind.starting
        if aspect == names.guide or aspect in names.diverging:
            return kind in (SignalKind.home, SignalKind.route)
        return True

    # ---- an open authority -------------------------------------------------------------------------------------------
    def _judge_open(self, sig: str, aspect: str, a: Authority, view: FieldView, shown: dict[str, str],
                    found: dict[str, Finding]) -> Held:
        guide = aspect == self.aspects.guide
        if not self._repertoire(sig, aspect):
            found[f"aspect:{sig}"] = Finding(f"aspect:{sig}", "aspect", f"{self.kind[sig].value} signal {sig} shows "
                                             f"{aspect}, which it never may", delayed=True)
        demands, fouling = self.flank.of(a.tracks, a.turnouts)
        h = Held(sig, a, set(a.all_sections), set(a.sections), set(a.overlap_sections), set(a.diamonds),
                  set(fouling))
        # a guide aspect over turnouts without indication, or under guide total lock (引导总锁闭, where the
        # interlocking checks no route by design): the operator has checked the way by sight and answers for the
        # guided route; what the oracle finds on it is a hazard
        h.guided = guide
        h.operator = guide and (a.end == "broken" or sig in self.guide_locked
                                or any(view.proven(t) != p for t, p in a.turnouts.items()))
        if h.operator:
            self.operated.add(sig)
        else:
            self.operated.discard(sig)
        if a.end == "broken":
            h.unsettled = True
            found[f"turnout:{sig}:{a.broken_at}"] = Finding(
                f"turnout:{sig}:{a.broken_at}", "turnout", f"signal {sig} shows {aspect} but turnout {a.broken_at} "
                "in its path lies between positions", hazard=h.operator, delayed=True)
        # a guided train runs at sight (≤ 20 km/h, ready to stop): it needs no overlap beyond its end signal
        overlap = {} if guide else a.overlap_turnouts
        if guide:
            h.sections -= h.overlap - set(a.sections)
            h.overlap = set()
        for role, wanted in (("path", a.turnouts), ("overlap", overlap)):
            for t, pos in wanted.items():
                h.needed[t] = (pos, role)
                if self._turnout(sig, aspect, t, pos, role, view, found, h.operator):
                    h.unsettled = True
        for t, d in demands.items():
            h.needed.setdefault(t, (d.position, "flank"))
            self._flank_turnout(sig, aspect, d, guide, view, found, h.operator)
        if not guide:
            self._clear(sig, aspect, a, fouling, view, found)
        self._doors(sig, aspect, a, view, found)
        if a.kind == "train":
            ahead = shown.get(a.end_signal or "", "")
            if a.end_signal and a.end_signal not in shown:
                ahead = self.reader.read(view.lit(a.end_signal), view.flashing(a.end_signal))
            ahead_path = self.open.get(a.end_signal or "") if a.end_signal in shown else None
            if not guide:
                self._aspect(sig, aspect, a, ahead, ahead_path, view, found)
        if not guide:
            self._invisible(sig, a, view, found)
        return h

    def _aspect(self, sig: str, aspect: str, a: Authority, ahead: str, ahead_path: Authority | None,
                view: FieldView, found: dict[str, Finding]) -> None:
        """The aspect shown against the ceiling of its path. The lamps may show less than their relays prove (a bad
        contact in a relay flasher, 闪光灯接点不良, darkens the flashing lamp while its check stays up): judged on
        what the relays prove, the interlocking answers for the aspect; what the lamps alone show wrong is a
        hazard it cannot see."""
        limit = self.ceiling.of(a, view, ahead, ahead_path)
        if permits(limit.aspect, aspect, self.aspects):
            return
        known = self.reader.read(*view.proven_lit(sig))
        ahead_known = self.reader.read(*view.proven_lit(a.end_signal)) if a.end_signal else ahead
        known_limit = self.ceiling.of(a, view, ahead_known, ahead_path) if ahead_known != ahead else limit
        hidden = permits(known_limit.aspect, known, self.aspects)
        note = ""
        if hidden:
            note = f"; the lamp relays prove {sig} {known}" + (f" and {a.end_signal} {ahead_known}"
                                                                 if ahead_known != ahead else "")
        found[f"aspect:{sig}"] = Finding(f"aspect:{sig}", "aspect", f"signal {sig} shows {aspect}; its path allows "
                                         f"at most {limit.aspect} ({limit.why}{note})", hazard=hidden, delayed=True)

    def _turnout(self, sig: str, aspect: str, t: str, pos: str, role: str, view: FieldView,
                 found: dict[str, Finding], operator: bool = False) -> bool:
        """A turnout the authority runs over: where it must lie, proven and locked. True when it is not there."""
        key = f"turnout:{sig}:{t}"
        rails = view.rails(t)
        if rails != pos:
            where = "between positions" if rails is None else rails
            found[key] = Finding(key, "turnout", f"signal {sig} shows {aspect} but turnout {t} ({role}) lies "
                                 f"{where}, the {role} needs it {pos}", hazard=operator, delayed=True)
            return True
        if view.proven(t) != pos:
            if not operator:
                found[key] = Finding(key, "turnout", f"signal {sig} shows {aspect} but turnout {t} ({role}) is not "
                                     f"proven {pos} (no indication)", delayed=True)
            return True
        if not view.locked(t):
            found[key] = Finding(key, "turnout", f"signal {sig} shows {aspect} but turnout {t} ({role}, {pos}) is "
                                 "not locked", hazard=operator, delayed=True)
        return False

    def _flank_turnout(self, sig: str, aspect: str, d: Demand, guide: bool, view: FieldView,
                       found: dict[str, Finding], operator: bool = False) -> None:
        key = f"flank:{sig}:{d.turnout}"
        rails = view.rails(d.turnout)
        if not guide and (rails != d.position or view.proven(d.turnout) != d.position):
            where = "between positions" if rails is None else rails
            found[key] = Finding(key, "flank", f"signal {sig} shows {aspect} but flank turnout {d.turnout} lies "
                                 f"{where}; it must lie {d.position}, proven ({d.why})", delayed=True)
        elif not view.locked(d.turnout):
            found[key] = Finding(key, "flank", f"signal {sig} shows {aspect} but flank turnout {d.turnout} is not "
                                 f"locked ({d.why})", hazard=operator, delayed=True)

    def _clear(self, sig: str, aspect: str, a: Authority, fouling: list[str], view: FieldView,
               found: dict[str, Finding]) -> None:
        occupied = [s for s in a.all_sections if not view.clear(s)]
        if a.kind == "shunt" and occupied:
            # a shunting signal stays open until the whole consist is past it: with the section in rear occupied,
            # the occupied sections from the first one on are the consist passing
            rear = self.rear[sig]
            k = 0
            while k < len(a.sections) and not view.clear(a.sections[k]):
                k += 1
            if rear is not None and not view.clear(rear):
                occupied = [s for s in occupied if s not in a.sections[:k]]
        occupied += [s for s in fouling if not view.clear(s) and s not in occupied]
        if occupied:
            key = f"clear:{sig}"
            found[key] = Finding(key, "clear", f"signal {sig} shows {aspect} over occupied section "
                                 f"{', '.join(occupied)}", delayed=True)

    def _doors(self, sig: str, aspect: str, a: Authority, view: FieldView, found: dict[str, Finding]) -> None:
        for sec in [*a.sections, self.rear[sig]]:
            if sec in self.doors and not view.doors_safe(sec):
                key = f"doors:{sig}:{sec}"
                found[key] = Finding(key, "doors", f"signal {sig} shows {aspect} with the screen doors at {sec} "
                                     "neither closed and locked nor bypassed", delayed=True)

    def _invisible(self, sig: str, a: Authority, view: FieldView, found: dict[str, Finding]) -> None:
        """A vehicle in a section the authority runs over that the section's track circuit does not see (in a dead
        zone, or shunting poorly): the interlocking believes the section clear."""
        tracks = {t for sec in a.all_sections for t in self.st.section_tracks[sec]}
        for track, x in view.wheelsets(tracks):
            sec = self.section_of[track]
            if view.clear(sec):
                key = f"invisible:{sig}:{sec}"
                found[key] = Finding(key, "invisible", f"a vehicle the track circuit does not see stands in section "
                                     f"{sec} ({track} at {x:g} m, the section shows clear), which the authority of "
                                     f"signal {sig} runs over", hazard=True)
                return

    # ---- movements under way -----------------------------------------------------------------------------------------
    def _start_in_use(self, a: Authority, view: FieldView, operator: bool = False, guided: bool = False) -> None:
        secs = a.sections
        seen = [not view.clear(s) for s in secs]
        # sections occupied beyond a clear one were occupied before the movement got there (a red band)
        pre: set[int] = set()
        k = 0
        while k < len(secs) and seen[k]:
            k += 1
        pre = {i for i in range(k, len(secs)) if seen[i]}
        self.in_use.append(InUse(a, [bool(v) and i not in pre for i, v in enumerate(seen)], pre, operator=operator,
                                 guided=guided))

    def _in_use(self, view: FieldView) -> list[Held]:
        out: list[Held] = []
        keep: list[InUse] = []
        for u in self.in_use:
            secs = u.sections
            a = u.auth
            last = len(a.sections) - 1
            for i in range(u.passed, len(secs)):
                if i not in u.pre and not view.clear(secs[i]):
                    u.seen[i] = True
            while u.passed < len(secs):
                i = u.passed
                if i in u.pre:
                    if any(u.seen[i + 1:]):
                        u.passed += 1
                        continue
                    break
                if not u.seen[i]:
                    break
                if i == last and u.reached_at is None:
                    u.reached_at = self.now
                if view.clear(secs[i]) or (i == last and self.role[secs[i]] is SectionRole.station_track):
                    u.passed += 1
                    continue
                break
            overlap_held = not u.guided and bool(a.overlap_sections) and (
                u.reached_at is None
                or self.now - u.reached_at < a.overlap_release_s - (self.reaction + 1) * self.cycle_s)
            remaining = secs[u.passed:]
            moving_in = any(not view.clear(s) for s in remaining if secs.index(s) not in u.pre)
            if not remaining and not overlap_held:
                continue
            if not moving_in and not overlap_held:
                continue
            keep.append(u)
            rem = set(remaining)
            tracks = [t for t in a.tracks if self.section_of[t] in rem]
            turnouts = {t: p for t, p in a.turnouts.items() if self.turnout_section.get(t) in rem}
            h = Held(f"{a.signal} (in use)", a, rem | (set(a.overlap_sections) if overlap_held else set()), rem,
                      set(a.overlap_sections) if overlap_held else set(),
                      {d for t in tracks for d, _ in self.st.crossings.get(t, ())}, operator=u.operator, in_use=True,
                      guided_in=u.guided)
            for t, p in turnouts.items():
                h.needed[t] = (p, "path")
            if overlap_held:
                for t, p in a.overlap_turnouts.items():
                    h.needed[t] = (p, "overlap")
            demands, foul = self.flank.of(tracks, turnouts)
            h.fouling = set(foul)
            for t, d in demands.items():
                h.needed.setdefault(t, (d.position, "flank"))
            out.append(h)
        self.in_use = keep
        return out

    # ---- across authorities ------------------------------------------------------------------------------------------
    def _across(self, held: list[Held], found: dict[str, Finding]) -> None:
        by_element: dict[str, list[int]] = {}
        for i, h in enumerate(held):
            for e in [*h.sections, *h.fouling, *(f"diamond {d}" for d in h.diamonds)]:
                by_element.setdefault(e, []).append(i)
            if h.auth.leads_into is not None:
                by_element.setdefault(h.auth.leads_into, []).append(i)
        pairs = {(i, j) for ids in by_element.values() for n, i in enumerate(ids) for j in ids[n + 1:] if i != j}
        for i, j in sorted(pairs):
            a, b = held[i], held[j]
            if a.auth is b.auth:
                continue
            # a guide aspect (its track circuits unchecked by design: the operator has looked at the way) towards a
            # movement already under way is the operator's; two signals given at once, guided or not, are the
            # interlocking's
            hazard = ((a.guided or a.operator) and b.in_use) or ((b.guided or b.operator) and a.in_use)
            # a guide aspect given again over its route, the guided train still taken to be in it (its red band is
            # no sign of where it is): the operator's, like any guide aspect towards a movement under way
            hazard = hazard or (a.in_use and b.in_use and a.auth.signal == b.auth.signal
                                 and (a.guided_in or b.guided_in))
            delayed = a.unsettled or b.unsettled
            # where the operator released a section of one of them by hand, what follows is on the operator's word
            hazard = hazard or bool(self.fault_released & {*a.sections, *b.sections})
            for element in shared(a, b):
                key = f"shared:{element}:{a.name}:{b.name}"
                found[key] = Finding(key, "shared", f"the authorities of {a.name} and {b.name} share {element}",
                                     hazard=hazard, delayed=delayed)
            track = head_on(a, b, self.onto_track)
            if track is not None:
                key = f"head-on:{track}:{a.name}:{b.name}"
                found[key] = Finding(key, "head-on", f"{a.name} ({a.auth.kind}) and {b.name} ({b.auth.kind}) lead "
                                     f"head-on onto {track}", hazard=hazard, delayed=delayed)

    def _lines(self, held: list[Held], view: FieldView, found: dict[str, Finding]) -> None:
        """An automatic line is worked one way at a time: no signal may give a train out onto it while another gives
        one in from it (a home or block signal facing the station, its section in rear on the line, route or guide
        aspect alike), nor receive a train from it while its direction is set for departures (改方). A shunting
        movement from the line's first section into the station is judged by the sections it shares."""
        for link, (sections, out) in self.lines.items():
            leaving = [h.name for h in held if h.auth.kind == "train" and h.auth.direction is out
                       and not sections.isdisjoint(h.auth.sections)]
            coming = [h.name for h in held if h.auth.kind == "train" and h.auth.direction is not out
                      and self.rear[h.auth.signal] in sections]
            if not coming:
                continue
            key = f"line:{link}"
            if leaving:
                found[key] = Finding(key, "line", f"signal {leaving[0]} gives a movement out onto line {link} while "
                                     f"signal {coming[0]} gives one in from it: they run at each other on the line",
                                     delayed=True)
            elif view.line_outbound(link):  # the block signals follow a direction change a cycle later
                found[key] = Finding(key, "line", f"line {link} is set for departures from this station (改方) while "
                                     f"signal {coming[0]} gives a movement in from it", delayed=True)

    def _moving(self, view: FieldView, held: list[Held], found: dict[str, Finding]) -> None:
        moving = {t: view.target(t) for t in view.moving()}
        needs: dict[str, list[tuple[Held, str, str]]] = {}
        for h in held:
            for t, (pos, role) in h.needed.items():
                needs.setdefault(t, []).append((h, pos, role))
                pair = self.pair_of.get(t)
                if pair:
                    for partner in self.st.pairs[pair]:
                        if partner != t:
                            needs.setdefault(partner, []).append((h, pos, f"{role}, crossover {pair}"))
        for t, target in moving.items():
            # a turnout in a section the operator released by hand while the movement's authority reached over it
            # moves on the operator's word, as a route set there does
            released = self.turnout_section[t] in self.fault_released
            for h, pos, role in needs.get(t, ()):
                key = f"moved:{t}:{h.name}"
                found[key] = Finding(key, "moved", f"turnout {t} is moving towards {target} while the authority of "
                                     f"{h.name} needs it {pos} ({role})", hazard=h.operator or released)
            if self.was_moving.get(t, "") == target:
                continue
            sec = self.turnout_section[t]
            if not view.clear(sec):
                # occupied before the interlocking could see it (a movement entering as the move began, such as a
                # train passing a signal at danger) is the world's hazard; occupied before that, the interlocking's
                key = f"moved:{t}:occupied"
                late = sec not in self.turnout_sections_occupied
                found[key] = Finding(key, "moved", f"turnout {t} started moving towards {target} with its section "
                                     f"{sec} occupied" + (" (entered as the move began)" if late else ""),
                                     hazard=late)
                continue
            near = [(tr, x) for tr, x in view.wheelsets(self.turnout_tracks[t])
                    if abs(x - self.st.turnouts[t].at) <= TURNOUT_AREA_M]
            if near:
                key = f"invisible:{t}"
                found[key] = Finding(key, "invisible", f"turnout {t} started moving under a vehicle the track circuit "
                                     f"does not see ({near[0][0]} at {near[0][1]:g} m; {sec} shows clear)",
                                     hazard=True)
        self.was_moving = moving
        self.turnout_sections_occupied = view.occupied(self.turnout_sections)


"""What can happen next in an explored state: every console command with every argument that may do something, every
field event a movement or a fault can cause, and time running on to the next moment that matters.

Each action is a line of the command language (so a sequence of them is a runnable script), with its **footprint**:
the sections, turnouts and signals it reads or changes, for the partial-order reduction (:mod:`.search`). Two
actions whose footprints are disjoint commute: either order leads to the same state, so only one order is explored.
A footprint errs on the large side; ``GLOBAL`` (time, a restart, a line's direction, block lines, a lamp whose
failure reaches the signals in rear) depends on everything.

The field events (docs/explore.md):

- a section becomes occupied at an entry to the station (the section beyond a boundary, a spur's buffer stop) or next
  to an occupied section (a movement moving on); an occupied section clears (a movement left it, a red band ends);
- a turnout of a route, or one moving, loses its indication (and gets it back), or sticks (an obstruction);
- a lamp lit on a signal giving a movement authority fails (both filaments), and is repaired;
- a screen door at a platform a route enters or leaves sticks open, and is repaired.
"""

from __future__ import annotations

from collections.abc import Iterator
from dataclasses import dataclass

from liansuo.interlocking.core import Core
from liansuo.interlocking.locks import Hold
from liansuo.interlocking.table.route import Route
from liansuo.simulation.sim import Simulation
from liansuo.stations.schema import EndKind, LinkKind, SignalKind
from liansuo.stations.station import Station

GLOBAL = frozenset({"*"})
# an action that may take up or free the room a bound leaves depends on every other one that may
ROUTES, OCCUPIED, FAULTS, MARKS = (frozenset({f"bound:{b}"}) for b in ("routes", "occupied", "faults", "marks"))
ADVANCE = "advance"  # time runs on to the next moment that matters; written as 'run Ns' in a script


@dataclass(frozen=True)
class Action:
    line: str  # the command line ('advance' for time)
    footprint: frozenset[str]
    rank: str  # its place in a fixed order of every action (the reduction explores that order): its line

    def independent(self, other: Action) -> bool:
        return "*" not in self.footprint and "*" not in other.footprint and self.footprint.isdisjoint(other.footprint)


@dataclass(frozen=True)
class Bounds:
    """How much may be going on at once (the explored model's bounds, docs/explore.md): routes set (guide routes and
    guide aspects under guide total lock among them), faults active, sections occupied by a movement or a red band,
    turnouts single-locked or single-blocked, throats under guide total lock. A command that would go past a bound
    is not tried; every state within them is."""

    routes: int = 2
    faults: int = 1
    occupied: int = 2
    turnout_marks: int = 1
    guide_locks: int = 1


class Model:
    """The actions of one station: worked out once, then picked per state from what the interlocking and the field
    hold, within ``bounds``."""

    def __init__(self, sim: Simulation, bounds: Bounds | None = None) -> None:
        st: Station = sim.station
        self.bounds = bounds or Bounds()
        self.st = st
        table = sim.table
        self.routes = list(table.routes.values())
        self.route_fp = {r.id: self._route_footprint(r) for r in self.routes}
        self.turnout_fp = {t: self._turnout_footprint(t) for t in st.turnouts}
        self.neighbours = self._neighbour_sections()
        self.entries = self._entries()
        self.home_guides = [s.id for s in st.model.signals if s.kind in (SignalKind.home, SignalKind.route)
                            and sim.rules.aspects.can_show(sim.rules.aspects.guide, [lp.value for lp in s.lamps])]
        self.throats = list(table.throats)
        self.links64 = [lk.id for lk in st.model.links if lk.kind is LinkKind.semi_auto_64d]
        self.station_lines = [lk.id for lk in st.model.links if lk.kind is LinkKind.station]
        self.bidirectional = [lk.id for lk in st.model.links if lk.bidirectional]
        self.platform_of = {p.section: p.id for p in st.model.platforms if p.screen_doors}

    # ---- footprints -------------------------------------------------------------------------------------------
    def _route_footprint(self, r: Route) -> frozenset[str]:
        st = self.st
        secs = {*r.all_sections, *r.approach, *r.line_sections, *(s for ro in r.run_on for s in ro.sections)}
        secs |= {s for s in (r.beyond, r.leads_into) if s}
        secs |= {ro.leads_into for ro in r.run_on if ro.leads_into}
        turnouts = {t.id for t in r.all_turnouts} | {t.id for ro in r.run_on for t in ro.turnouts}
        turnouts |= {m for t in list(turnouts) for m in st.pairs.get(st.turnouts[t].pair or "", [])}
        secs |= {st.turnout_section[t] for t in turnouts}
        marks = {f"signal:{r.signal}"} | ({f"signal:{r.end_signal}"} if r.end_signal else set())
        if r.exit_link:
            lk = next(x for x in st.model.links if x.id == r.exit_link)
            secs |= set(lk.sections)
        return frozenset(secs | {f"turnout:{t}" for t in turnouts} | marks)

    def _turnout_footprint(self, t: str) -> frozenset[str]:
        st = self.st
        members = st.pairs.get(st.turnouts[t].pair or "", [t])
        return frozenset({st.turnout_section[m] for m in members} | {f"turnout:{m}" for m in members})

    def _neighbour_sections(self) -> dict[str, set[str]]:
        """Sections next to each section, across a joint or through a turnout section."""
        st = self.st
        out: dict[str, set[str]] = {s: set() for s in st.sections}
        for items in st.node_tracks.values():
            secs = {st.tracks[tid].section for _, tid in items}
            for s in secs:
                out[s] |= secs - {s}
        return out

    def _entries(self) -> list[str]:
        """Sections a movement may first appear in: those at a boundary (the line) or a buffer stop."""
        st = self.st
        return sorted({st.tracks[st.node_tracks[e.id][0][1]].section for e in st.model.ends
                       if e.kind in (EndKind.boundary, EndKind.buffer)})

    def _act(self, line: str, footprint: frozenset[str]) -> Action:
        return Action(line, footprint, line)  # the order is the lines' (the same in every process)

    # ---- the actions in a state ---------------------------------------------------------------------------------
    def actions(self, sim: Simulation, areas: list[frozenset[str]] | None = None) -> list[Action]:
        """Every action worth trying in the state ``sim`` is in, in the fixed order. Each footprint takes in the
        whole of every area in play it touches (``areas``: a route set, an authority the oracle holds): two events
        that both reach one route may not commute, whatever else they touch."""
        out = list(self._operator(sim)) + list(self._field(sim)) + [self._act(ADVANCE, GLOBAL)]
        areas = self.areas(sim) if areas is None else areas
        closed = [a if "*" in a.footprint else Action(a.line, a.footprint.union(*(x for x in areas
                                                                                    if not x.isdisjoint(a.footprint))),
                                                       a.rank)
                  for a in out]
        return sorted(closed, key=lambda a: a.rank)

    def areas(self, sim: Simulation) -> list[frozenset[str]]:
        """The routes set, with everything they read."""
        return [self.route_fp[rid] for rid in sim.interlocking.core.routes]

    def _operator(self, sim: Simulation) -> Iterator[Action]:
        core = sim.interlocking.core
        st = self.st
        b = self.bounds
        if len(core.routes) + len(core.guide_only) < b.routes:
            for r in self.routes:
                word = "route" if r.kind == "train" else "shunt"
                fp = self.route_fp[r.id] | ROUTES
                yield self._act(" ".join([word, *r.buttons]), fp)
                if r.kind == "train" and r.category == "receiving" and r.signal in self.home_guides \
                        and not r.overlap_alternative:
                    yield self._act(" ".join(["guide", *r.buttons]), fp)
        for sig in sorted(core.by_signal):
            fp = self.route_fp[core.by_signal[sig]] | ROUTES
            for word in ("cancel", "release", "reopen", "guide"):
                yield self._act(f"{word} {sig}", fp)
        for sig in self.home_guides:
            if sig not in core.by_signal and sig not in core.guide_only \
                    and len(core.routes) + len(core.guide_only) < b.routes:
                yield self._act(f"guide {sig}", GLOBAL)
        for sig in sorted(core.guide_only):
            yield self._act(f"cancel {sig}", GLOBAL)
        for sec in sorted(s for s in core.locks.sections if not st.is_station_track(s)):
            holders = core.locks.section_holders(sec)
            fp = frozenset({sec}).union(*(self.route_fp.get(h, GLOBAL) for h in holders))
            yield self._act(f"fault-release {sec}", fp if holders else GLOBAL)
        done: set[str] = set()
        marks = sum(1 for t in st.turnouts if _single(core, t)) + len(core.locks.blocked)
        for t in st.turnouts:
            if t in done:
                continue
            pair = st.turnouts[t].pair
            done |= set(st.pairs.get(pair or "", [t]))
            name = pair or t
            fp = self.turnout_fp[t]
            marked = fp | MARKS
            rails = sim.field.machines[t].rails
            yield self._act(f"throw {name} {'reverse' if rails == 'normal' else 'normal'}", fp)
            if _single(core, t):
                yield self._act(f"unlock {name}", marked)
            elif marks < b.turnout_marks:
                yield self._act(f"lock {name}", marked)
            if t in core.locks.blocked:
                yield self._act(f"unblock {name}", marked)
            elif marks < b.turnout_marks:
                yield self._act(f"block {name}", marked)
        locked = [th for th in self.throats if _guide_locked(core, th)]
        for throat in self.throats:
            if throat in locked:
                yield self._act(f"guide-unlock {throat}", GLOBAL)
            elif len(locked) < b.guide_locks:
                yield self._act(f"guide-lock {throat}", GLOBAL)
        yield self._act("restart", GLOBAL)
        if core.power_up_locked:
            yield self._act("power-up-release", GLOBAL)
        for link in self.bidirectional:
            yield self._act(f"line-direction {link} {'in' if link in core.line_out else 'out'}", GLOBAL)
        for link in self.links64:
            for word in ("request", "accept", "cancel", "restore"):
                yield self._act(f"block-line {link} {word}", GLOBAL)

    def _field(self, sim: Simulation) -> Iterator[Action]:
        st = self.st
        f = sim.field
        core = sim.interlocking.core
        occupied = {s for s, c in f.circuits.items() if c.k_switch}
        down = {s for s in st.sections if not f.track_up(s)}
        reachable = set(self.entries)
        for s in down:
            reachable |= self.neighbours[s]
        if len(occupied) < self.bounds.occupied:  # next to an occupied section: what enables it is read too
            for s in sorted(reachable - down):
                yield self._act(f"occupy {s}", frozenset({s, *self.neighbours[s]}) | OCCUPIED)
        for s in sorted(occupied):
            yield self._act(f"vacate {s}", frozenset({s, *self.neighbours[s]}) | OCCUPIED)
        for link in self.links64:
            for word in ("request", "depart", "restore"):
                yield self._act(f"neighbour {link} {word}", GLOBAL)
        for link in self.station_lines:
            for word in ("block", "cancel"):
                yield self._act(f"neighbour {link} {word}", GLOBAL)
        faults = set(f.faults)
        for kind, target in sorted(faults):
            fp = self.turnout_fp.get(target, GLOBAL)
            yield self._act(f"repair {kind} {target}", fp | FAULTS)
        if len(faults) >= self.bounds.faults:
            return
        in_play = {t.id for rs in core.routes.values() for t in rs.all_turnouts} | set(core.moving)
        for t in sorted(in_play):
            for kind in ("no-indication", "obstruction"):
                yield self._act(f"fault {kind} {t}", self.turnout_fp[t] | FAULTS)
        for sig, lamps in sorted(f.lamps.items()):
            if sig in core.by_signal or sig in core.guide_only:
                for lamp in sorted(lamps.commanded):
                    yield self._act(f"fault filament {sig} lamp={lamp} which=both", GLOBAL)
        platforms = {self.platform_of[s] for rs in core.routes.values() for s in rs.sections if s in self.platform_of}
        for p in sorted(platforms):
            yield self._act(f"fault psd-stuck {p}", GLOBAL)


def _guide_locked(core: Core, throat: str) -> bool:
    turnouts = core.table.throats.get(throat, ())
    return bool(turnouts) and all(any(lk.hold is Hold.guide and lk.holder == throat
                                      for lk in core.locks.turnouts.get(t, ())) for t in turnouts)


def _single(core: Core, turnout: str) -> bool:
    """The turnout is single-locked (单锁)."""
    return any(lk.hold is Hold.single for lk in core.locks.turnouts.get(turnout, ()))

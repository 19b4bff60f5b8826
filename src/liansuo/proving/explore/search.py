"""The search: every sequence of actions up to a depth, breadth first, each state once.

Level by level, every state of the frontier is expanded: each action of :class:`~.actions.Model` is tried on it (a
refused command changes nothing and leads nowhere), and each state reached is judged by the oracle on the way, every
cycle, and kept if its key (:mod:`.key`) is new. A frontier state is kept as its trace (the actions from the start),
and the expander replays traces from the nearest state it has kept (:class:`Expander`), so a frontier of millions
costs a few bytes each, and the frontier splits into chunks that any worker can take (Dask, ``proving.spread``).

Breadth first, the first sequence that shows a finding is a shortest one: each finding (the oracle's key, the same
finding met again is not reported again) is kept with the first such sequence.

**The reduction** (partial-order, docs/explore.md): from a state reached by action ``a``, an action ``b`` that
commutes with ``a`` (disjoint footprints) and comes before it in the fixed order is not tried: the same state is
reached by ``b`` then ``a``, which the search does try. Only one order of each run of commuting actions is explored.
"""

from __future__ import annotations

import time
from collections.abc import Callable, Iterator, Sequence
from dataclasses import dataclass, field
from typing import Any

from liansuo.interlocking.state import RouteStage
from liansuo.proving.explore.actions import ADVANCE, GLOBAL, Action, Bounds, Model
from liansuo.proving.explore.key import state_key
from liansuo.proving.explore.snapshot import Shared, restore, take
from liansuo.proving.oracle.watch import Violation, Watch
from liansuo.proving.spread import RETRIES
from liansuo.rules import RuleSet
from liansuo.simulation.sim import Simulation
from liansuo.stations.station import Station

ADVANCE_CAP_S = 400.0  # time runs on at most this long at once (longer than every timer of the rule set)
ANSWER_CYCLES = 12  # after a command or an event, the interlocking answers within this many cycles (a few, in fact)


@dataclass(frozen=True)
class TraceStep:
    """One action of a trace: its line as a script writes it, and what the reduction needs of it."""

    line: str  # 'run 4.75s' for time
    footprint: frozenset[str]
    rank: str
    calm: bool = False  # no timer ran and no machine moved in the state it was done in, and it starts none itself


Trace = tuple[TraceStep, ...]


@dataclass
class Found:
    """A finding met on the way from a frontier state: the trace that shows it ends with its step."""

    violation: Violation
    trace: Trace


@dataclass
class Expansion:
    """What expanding one frontier state gave: each new state reached (its key and trace), the findings met, the
    transitions tried and how many led somewhere."""

    children: list[tuple[bytes, Trace]] = field(default_factory=list)
    found: list[Found] = field(default_factory=list)
    tried: int = 0
    accepted: int = 0


class Expander:
    """One process's simulation of the station, branched from state to state."""

    def __init__(self, station: Station, rules: RuleSet, cycle_s: float = 0.25, *, reduce: bool = True,
                 bounds: Bounds | None = None) -> None:
        self.sim = Simulation(station, rules=rules, cycle_s=cycle_s)
        self.watch = Watch(self.sim)
        self.shared = Shared(self.sim, self.watch)
        self.model = Model(self.sim, bounds)
        self.reduce = reduce
        self.root = take(self.sim, self.watch, self.shared)
        self.root_key = state_key(self.sim, self.watch)
        self._path: list[tuple[Trace, bytes]] = [((), self.root)]  # snapshots along the last trace replayed

    # ---- reaching a state -----------------------------------------------------------------------------------
    def goto(self, trace: Trace) -> None:
        """Put the simulation in the state ``trace`` leads to, replaying from the longest kept prefix."""
        path = self._path
        while len(path) > 1 and trace[:len(path[-1][0])] != path[-1][0]:
            path.pop()
        prefix, snap = path[-1]
        restore(self.sim, self.watch, self.shared, snap)
        for step in trace[len(prefix):]:
            self.replay(step.line)
            path.append((path[-1][0] + (step,), take(self.sim, self.watch, self.shared)))
        self.watch.violations, self.watch.hazards = [], []  # each was reported with the step that showed it

    def replay(self, line: str) -> None:
        for part in line.split("; "):
            if part.startswith("run "):
                self.sim.run(float(part.split()[1].rstrip("s")))
            else:
                self.sim.command(part)

    # ---- one action ----------------------------------------------------------------------------------------
    def apply(self, action: Action) -> str | None:
        """Do ``action`` and let the interlocking answer it: the lines that did it (a command and the cycles of its
        answer, ``route X XI; run 0.5s``; for time, how long it ran), or None when it was refused."""
        if action.line == ADVANCE:
            return self.advance()
        if not self.sim.command(action.line).ok:
            return None
        n = self.answer()
        return f"{action.line}; run {n * self.sim.cycle_s:g}s"

    def answer(self) -> int:
        """Cycles until the interlocking has taken every relay change and is at rest again, and no finding waits
        for its answer (switch machines may run on, timers may count: time runs on for those in ``advance``)."""
        sim, oracle = self.sim, self.watch.oracle
        n = 0
        while n < ANSWER_CYCLES:
            before = self._signature()
            sim.step()
            n += 1
            if self._signature() == before and not sim.interlocking.core.board.pending() and not oracle.pending:
                break
        return n

    def advance(self) -> str | None:
        """Time runs on, cycle by cycle (stretches at rest in one go), until the first cycle that changes something
        (a relay, a lock, an event, an output, a finding): the next moment that matters. None when nothing changes
        within ``ADVANCE_CAP_S``."""
        sim = self.sim
        cap = round(ADVANCE_CAP_S / sim.cycle_s)
        before = self._signature()
        n = 0
        while n < cap:
            rested = sim.rest(cap - n)
            if rested:
                n += rested
                if self._signature() != before:
                    break
                continue
            sim.step()
            n += 1
            if self._signature() != before:
                break
        else:
            return None
        return f"run {n * sim.cycle_s:g}s"

    def calm(self) -> bool:
        """No timer runs and no switch machine moves: the order of two actions here can only matter through what
        they both touch (a timer started by one would run out before or after the other's, a different state)."""
        core = self.sim.interlocking.core
        return (not core.moving and not core.queue and not core.overlap_pending and not core.guide_only
                and not self.sim.field.machines_running() and not self.watch.oracle.pending
                and not any(u.reached_at is not None for u in self.watch.oracle.in_use)
                and all(rs.release_at is None and rs.overlap_release_at is None and not rs.fault_release_at
                        and rs.stage is not RouteStage.guide for rs in core.routes.values())
                and all(ts.no_indication_since is None or ts.squeeze_alarmed for ts in core.turnouts.values()))

    def areas(self) -> list[frozenset[str]]:
        """What is in play: the routes set, and the authorities the oracle holds (signals open, movements under
        way), each with the sections and turnouts it takes in."""
        out = self.model.areas(self.sim)
        o = self.watch.oracle
        auths = [*o.open.values(), *(u.auth for u in o.in_use)]
        st = self.sim.station
        for a in auths:
            turnouts = set(a.needed())
            out.append(frozenset({*a.all_sections, *(st.turnout_section[t] for t in turnouts),
                                  *(f"turnout:{t}" for t in turnouts), f"signal:{a.signal}"}))
        return out

    def _signature(self) -> tuple[object, ...]:
        sim, core = self.sim, self.sim.interlocking.core
        o = self.watch.oracle
        return (core.logged, core.locks.version, len(core.alarms), sim.field.stamp, sim.field.lamp_stamp,
                tuple(sorted(core.out.signals.items())), len(self.watch.violations), len(self.watch.hazards),
                tuple(sorted(o.pending.items())), frozenset(o.active), len(core.moving), len(core.queue))

    # ---- a frontier state ------------------------------------------------------------------------------------
    def expand(self, trace: Trace) -> Expansion:
        """Every action from the state ``trace`` leads to."""
        self.goto(trace)
        parent = self._path[-1][1]
        last = trace[-1] if trace else None
        out = Expansion()
        dirty = False
        calm = self.calm()
        for action in self.model.actions(self.sim, self.areas()):
            if self.reduce and last is not None and last.calm and action.rank < last.rank and _commute(action, last):
                continue
            if dirty:
                restore(self.sim, self.watch, self.shared, parent)
                dirty = False
            out.tried += 1
            done = self.apply(action)
            if done is None:
                dirty = action.line == ADVANCE  # a refused command changed nothing; time may have run
                continue
            dirty = True
            out.accepted += 1
            step = TraceStep(done, action.footprint, action.rank, calm and self.calm())
            child = (*trace, step)
            for v in (*self.watch.violations, *self.watch.hazards):
                out.found.append(Found(v, child))
            out.children.append((state_key(self.sim, self.watch), child))
        if dirty:
            restore(self.sim, self.watch, self.shared, parent)
        return out


def _commute(a: Action, last: TraceStep) -> bool:
    return "*" not in a.footprint and "*" not in last.footprint and a.footprint.isdisjoint(last.footprint)


@dataclass
class Level:
    depth: int
    states: int  # new states found at this depth
    transitions: int
    seconds: float


@dataclass
class SearchOutcome:
    """What a search found: the findings (each with its shortest trace), the levels, whether it saturated."""

    station: str
    depth: int  # the depth fully explored
    states: int
    transitions: int
    seconds: float
    saturated: bool
    levels: list[Level]
    findings: dict[str, Found]  # finding key -> first (shortest) trace
    hazards: dict[str, Found]
    stopped: str = ""  # why it stopped short of the depth asked ('' when it reached it)


Expand = Callable[[Sequence[Trace]], Iterator[list[Expansion]]]
PILE = 48  # frontier states in one piece of work


def search(station: Station, expand: Expand, root_key: bytes, depth: int, *, budget_s: float | None = None,
           progress: Callable[[int, int, int, int, float], None] | None = None, first: bool = False) -> SearchOutcome:
    """Breadth first to ``depth``: ``expand(frontier)`` yields the expansions of each pile of ``PILE`` frontier states
    in order (worked in this process or on Dask). Within ``budget_s`` seconds where given: the last level is then
    explored in part, and the outcome says how far. ``first``: stop at the first violation (its sequence is still a
    shortest one: every shorter sequence was explored before). ``progress(depth, frontier done, states,
    transitions, s)``."""
    start = time.monotonic()
    seen: set[bytes] = {root_key}
    frontier: list[Trace] = [()]
    findings: dict[str, Found] = {}
    hazards: dict[str, Found] = {}
    levels: list[Level] = []
    transitions = 0
    saturated = False
    stopped = ""
    reached = 0
    for d in range(1, depth + 1):
        t0 = time.monotonic()
        new: list[Trace] = []
        level_transitions = 0
        done = 0
        for piece in expand(frontier):
            for ex in piece:
                level_transitions += ex.tried
                for f in ex.found:
                    target = hazards if f.violation.hazard else findings
                    target.setdefault(f"{f.violation.prop}:{f.violation.key}", f)
                for key, trace in ex.children:
                    if key not in seen:
                        seen.add(key)
                        new.append(trace)
            done += len(piece)
            if progress is not None:
                progress(d, done, len(seen), transitions + level_transitions, time.monotonic() - start)
            if budget_s is not None and time.monotonic() - start > budget_s and done < len(frontier):
                stopped = f"the time budget ran out at depth {d}: {done} of its {len(frontier)} states expanded"
                break
            if first and findings:
                stopped = f"stopped at the first violation, at depth {d}"
                break
        transitions += level_transitions
        levels.append(Level(d, len(new), level_transitions, time.monotonic() - t0))
        if stopped:
            break
        reached = d
        if not new:
            saturated = True
            break
        frontier = new
    return SearchOutcome(station.id, reached, len(seen), transitions, time.monotonic() - start, saturated, levels,
                         findings, hazards, stopped)


def piles(frontier: Sequence[Trace]) -> list[Sequence[Trace]]:
    """The frontier cut into pieces of work, in order (neighbours share prefixes: a replay starts from the last)."""
    return [frontier[i:i + PILE] for i in range(0, len(frontier), PILE)]


def expand_here(expander: Expander) -> Expand:
    """``expand`` in this process."""
    def expand(frontier: Sequence[Trace]) -> Iterator[list[Expansion]]:
        for pile in piles(frontier):
            yield [expander.expand(t) for t in pile]
    return expand


Job = tuple[str, Station, RuleSet, Bounds, bool]  # a search's token, station, rules, bounds and reduction
_EXPANDERS: dict[str, Expander] = {}  # in a worker process: the expander of the search in hand


def expand_pile(job: Job, pile: Sequence[Trace]) -> list[Expansion]:
    """A worker's task: expand ``pile`` with the expander it keeps for the search ``job`` names."""
    token, station, rules, bounds, reduce = job
    ex = _EXPANDERS.get(token)
    if ex is None:
        _EXPANDERS.clear()  # one search at a time per worker
        ex = _EXPANDERS[token] = Expander(station, rules, bounds=bounds, reduce=reduce)
    return [ex.expand(t) for t in pile]


def expand_on(client: Any, job: Job) -> Expand:
    """``expand`` on a Dask cluster: every pile of a level a task, the results taken in frontier order."""
    from dask.distributed import as_completed

    handle = client.scatter(job, broadcast=True)

    def expand(frontier: Sequence[Trace]) -> Iterator[list[Expansion]]:
        work = piles(frontier)
        futures = {client.submit(expand_pile, handle, pile, retries=RETRIES, pure=False): i
                   for i, pile in enumerate(work)}
        ready: dict[int, list[Expansion]] = {}
        nxt = 0
        try:
            for fut in as_completed(futures):  # type: ignore[no-untyped-call]
                ready[futures[fut]] = fut.result()
                while nxt in ready:
                    yield ready.pop(nxt)
                    nxt += 1
        finally:
            for fut in futures:
                fut.cancel()
    return expand


__all__ = ["GLOBAL", "Expander", "Found", "SearchOutcome", "Trace", "TraceStep", "expand_here", "expand_on", "search"]

"""One experiment of the interlocking test: a fresh simulation driven only through the command language, with the
safety oracle watching every cycle.

Every line a probe sends (and every stretch of simulated time it waits) is kept, so a failed check comes with a YAML
test script that replays it (``liansuo test``). Whatever the oracle finds during any probe is a failure of its own
(check ``oracle``), whichever item of the test the probe was for.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from liansuo.interlocking.aspects import is_open, stop_aspect
from liansuo.interlocking.io import Result
from liansuo.interlocking.table.build import InterlockingTable, Route
from liansuo.proving.oracle import Watch
from liansuo.rules import RuleSet
from liansuo.simulation.sim import Simulation
from liansuo.stations.station import Station

REST_S = 2.0  # how long the turnouts must have been at rest before a wait for "nothing happens" ends


@dataclass
class Failure:
    """A check that did not hold: what was checked, on which route or pair, why, and the steps that show it."""

    check: str
    subject: str  # route id, "A + B" for a pair, or a station item
    detail: str
    steps: list[str] = field(default_factory=list)
    key: str = ""  # what the oracle found (its text without the time): reported once per run

    def as_dict(self) -> dict[str, object]:
        return {"check": self.check, "subject": self.subject, "detail": self.detail, "steps": list(self.steps)}


@dataclass
class Context:
    """What every probe of one verify run shares: the station, its table (built once), the rules, the tallies."""

    station: Station
    table: InterlockingTable
    rules: RuleSet
    cycle_s: float = 0.25
    checks: int = 0
    failures: list[Failure] = field(default_factory=list)
    warnings: list[Failure] = field(default_factory=list)
    oracle_seen: set[str] = field(default_factory=set)  # what the oracle found, once each

    stop_at_first: bool = False  # raise FirstFailure at the first failure (for the mutation run)

    def record(self, ok: bool, check: str, subject: str, detail: str, probe: Probe | None = None) -> bool:
        self.checks += 1
        if not ok:
            self.fail(Failure(check, subject, detail, probe.script() if probe else []))
        return ok

    def fail(self, failure: Failure) -> None:
        self.failures.append(failure)
        if self.stop_at_first:
            raise FirstFailure(failure)


class FirstFailure(Exception):
    """The first failure of a verify run asked to stop there."""


class Probe:
    def __init__(self, ctx: Context) -> None:
        self.ctx = ctx
        self.sim = Simulation(ctx.station, cycle_s=ctx.cycle_s, rules=ctx.rules, table=ctx.table)
        self.watch = Watch(self.sim)
        self._reported = 0
        self.lines: list[str] = []
        self._cycles = 0  # cycles run since the last line written

    def __del__(self) -> None:
        """A dropped probe lets its simulation go at once: the watch's wrappers and the simulation refer to each
        other, which only the garbage collector would otherwise free (:meth:`~proving.oracle.watch.Watch.detach`)."""
        try:
            watch = self.watch
        except AttributeError:  # the simulation could not be built
            return
        watch.detach()

    def _oracle(self) -> None:
        """Record what the oracle found since the last look, each finding once per verify run."""
        found = self.watch.violations
        for v in found[self._reported:]:
            if v.text not in self.ctx.oracle_seen:
                self.ctx.oracle_seen.add(v.text)
                self.ctx.fail(Failure(v.source, v.prop, f"at t = {v.t:g} s: {v.text}", self.script(), v.text))
        self._reported = len(found)

    # ---- driving ------------------------------------------------------------------------------------------------
    def do(self, line: str) -> Result:
        self._flush()
        self.lines.append(line)
        result = self.sim.command(line)
        self._oracle()
        return result

    def _forward(self, limit: int) -> int:
        """Up to ``limit`` cycles at rest in one go (``World.rest``), else one real cycle; how many ran."""
        n = self.sim.rest(limit)
        if not n:
            self.sim.step()
            n = 1
        self._cycles += n
        return n

    def run(self, seconds: float) -> None:
        """Run ``seconds`` of simulated time (at least a cycle); the stretches at rest in one go."""
        n = max(1, round(seconds / self.ctx.cycle_s))
        i = 0
        while i < n:
            i += self._forward(n - i)
        self._oracle()

    def until(self, done: Callable[[], bool], timeout_s: float) -> bool:
        """Run until ``done()`` holds or ``timeout_s`` of simulated time passed, asking it after every cycle or
        stretch at rest (which leaves what it reads as it was)."""
        total = round(timeout_s / self.ctx.cycle_s)
        i = 0
        while i < total:
            if done():
                self._oracle()
                return True
            i += self._forward(total - i)
        self._oracle()
        return done()

    def settle(self, timeout_s: float = 60.0) -> None:
        """Run until the turnouts have been at rest for ``REST_S`` of simulated time (no switch machine running, and
        the interlocking neither driving one nor holding a move in its queue, so a move that cannot end has failed
        at the interlocking's own time-out), or until ``timeout_s`` passed: the wait before checking that something
        did not happen (a signal that must stay closed). What the interlocking does once its turnouts are at rest
        (lock the route, open the signal) it does within a cycle or two, well inside ``REST_S``; waiting on after
        that would only show the same state again. ``timeout_s`` only bounds a wait on turnouts that never rest: the
        rounds of moves the interlocking makes at once, each up to its time-out, end well before it."""
        rest = max(1, round(REST_S / self.ctx.cycle_s))
        sim = self.sim
        total = round(timeout_s / self.ctx.cycle_s)
        still = i = 0
        busy = False
        while i < total and still < rest:
            # a stretch at rest leaves the turnouts as they are: busy as after the last real cycle
            rested = sim.rest(total - i if busy else min(total - i, rest - still)) if i else 0
            if rested:
                i += rested
                self._cycles += rested
                still = 0 if busy else still + rested
                continue
            sim.step()
            self._cycles += 1
            i += 1
            busy = bool(sim.view.driving() or sim.field.machines_running())
            still = 0 if busy else still + 1
        self._oracle()

    def expect(self, what: str) -> Result:
        """An ``expect`` line of the command language, kept in the script."""
        return self.do(f"expect {what}")

    def _flush(self) -> None:
        if self._cycles:
            ms = round(self._cycles * self.ctx.cycle_s * 1000)
            self.lines.append(f"run {ms / 1000:g}s" if ms % 1000 == 0 else f"run {ms}ms")
            self._cycles = 0

    def script(self) -> list[str]:
        self._flush()
        return list(self.lines)

    # ---- reading --------------------------------------------------------------------------------------------------
    def aspect(self, signal: str) -> str:
        return self.sim.aspect(signal)

    def is_open(self, signal: str) -> bool:
        return is_open(self.sim.aspect(signal))

    def closed(self, signal: str) -> bool:
        return self.sim.aspect(signal) == stop_aspect(self.ctx.station, signal)

    def state(self, route: Route) -> str:
        return self.sim.route_state(route.id)

    def blocker(self, route: Route) -> str:
        """Why the route's signal is not open (the engine's own words), for failure messages."""
        rs = self.sim.interlocking.routes.get(route.id)
        if rs is None:
            return f"route {route.id} is not set"
        why = self.sim.interlocking.core.open_blocker(rs)
        return f"route {route.id} is {rs.stage.value}" + (f": {why}" if why else "")


def route_line(r: Route) -> str:
    """The console command that selects ``r``."""
    word = "route" if r.kind == "train" else "shunt"
    return " ".join([word, *r.buttons])


def turnout_groups(station: Station, r: Route) -> list[tuple[str, str]]:
    """(turnout, position) for every turnout the route needs, one per crossover pair (a pair moves together)."""
    out: list[tuple[str, str]] = []
    seen: set[str] = set()
    for t in r.all_turnouts:
        if t.id in seen:
            continue
        pair = station.turnouts[t.id].pair
        seen.update(station.pairs[pair] if pair else [t.id])
        out.append((t.id, t.position.value))
    return out


def prepare(p: Probe, r: Route) -> None:
    """Liaison a route needs before its signal may open: a 64D departure asks the neighbour (闭塞) and waits for
    its acceptance; a departure against the running direction of a bidirectional line changes its direction (改方)."""
    il = p.sim.interlocking
    if r.exit_link in il.core.auto_links and against_running(p.ctx.station, r.exit_link) \
            and not p.sim.line_outbound(r.exit_link):
        p.do(f"line-direction {r.exit_link} out")
    link = il.core.links.get(r.exit_link or "")
    if link is None or link.state.value != "idle":
        return
    p.do(f"block-line {link.id} request")
    p.until(lambda: link.state.value == "permitted", 10.0)


def against_running(station: Station, link: str) -> bool:
    """A departure onto ``link`` runs against its running direction (towards this station)."""
    return station.link_running(link) == "inbound"


def open_route(p: Probe, *routes: Route, timeout_s: float = 40.0) -> bool:
    """Prepare, select and wait until every signal of ``routes`` is open; False if one was refused or stayed
    closed."""
    for r in routes:
        prepare(p, r)
    for r in routes:
        if not p.do(route_line(r)).ok:
            return False
    if not p.until(lambda: all(p.state(r) == "open" for r in routes), timeout_s):
        return False
    p.run(1.0)  # let the aspect chain settle (a signal follows the one ahead a cycle later)
    return all(p.state(r) == "open" for r in routes)


def other(position: str) -> str:
    return "reverse" if position == "normal" else "normal"

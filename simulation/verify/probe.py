"""One experiment of the interlocking test: a fresh simulation driven only through the command language.

Every line a probe sends (and every stretch of simulated time it waits) is kept, so a failed check comes with a YAML
test script that replays it (``liansuo test``).
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from interlocking.aspects import is_open, stop_aspect
from interlocking.io import Result
from interlocking.rules import RuleSet
from interlocking.table import InterlockingTable, Route
from stations.station import Station

from ..sim import Simulation


@dataclass
class Failure:
    """A check that did not hold: what was checked, on which route or pair, why, and the steps that show it."""

    check: str
    subject: str  # route id, "A + B" for a pair, or a station item
    detail: str
    steps: list[str] = field(default_factory=list)

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

    def record(self, ok: bool, check: str, subject: str, detail: str, probe: Probe | None = None) -> bool:
        self.checks += 1
        if not ok:
            self.failures.append(Failure(check, subject, detail, probe.script() if probe else []))
        return ok


class Probe:
    def __init__(self, ctx: Context) -> None:
        self.ctx = ctx
        self.sim = Simulation(ctx.station, cycle_s=ctx.cycle_s, rules=ctx.rules, table=ctx.table)
        self.lines: list[str] = []
        self._cycles = 0  # cycles run since the last line written

    # ---- driving ------------------------------------------------------------------------------------------------
    def do(self, line: str) -> Result:
        self._flush()
        self.lines.append(line)
        return self.sim.command(line)

    def run(self, seconds: float) -> None:
        n = max(1, round(seconds / self.ctx.cycle_s))
        for _ in range(n):
            self.sim.step()
        self._cycles += n

    def until(self, done: Callable[[], bool], timeout_s: float) -> bool:
        """Run cycle by cycle until ``done()`` holds or ``timeout_s`` of simulated time passed."""
        for _ in range(round(timeout_s / self.ctx.cycle_s)):
            if done():
                return True
            self.sim.step()
            self._cycles += 1
        return done()

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
        why = self.sim.interlocking.open_blocker(rs)
        return f"route {route.id} is {rs.stage.value}" + (f": {why}" if why else "")


def route_line(r: Route) -> str:
    """The console command that selects ``r``."""
    word = "route" if r.kind == "train" else "shunt"
    return " ".join([word, r.start, *r.via, r.end])


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
    its acceptance."""
    il = p.sim.interlocking
    link = il.links.get(r.exit_link or "")
    if link is None or link.state.value != "idle":
        return
    p.do(f"block-line {link.id} request")
    p.until(lambda: link.state.value == "permitted", 10.0)


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

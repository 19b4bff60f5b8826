"""Pairs of routes: conflicting routes (敌对进路) can never be locked together, compatible ones can.

Each route in turn is set on a fresh simulation. Every route that conflicts with it must then be refused, both while
it is still setting and once its signal is open (so each conflicting pair is tried both ways round; a refused
command changes nothing, so they can all be tried on the one simulation). Then every compatible route after it in
the table is set as well: both signals must be open together (with their liaison given); it is cancelled again
before the next. A failure is replayed on a fresh simulation, so its script shows just the two routes.
"""

from __future__ import annotations

from collections.abc import Iterable
from functools import partial

from liansuo.interlocking.table import Route
from liansuo.stations.schema import TurnoutPosition

from .probe import Context, Probe, open_route, prepare, route_line

SETTLE_S = 30.0


def released(p: Probe, r: Route) -> bool:
    return p.state(r) == "released"


def conflicting(a: Route, b: Route) -> bool:
    return b.id in a.conflicts or a.id in b.conflicts or a.signal == b.signal


def conditional(a: Route, b: Route) -> bool:
    """Enemies only for some ways the turnouts beyond a shunting route's end lie."""
    return b.id in a.conditional or a.id in b.conditional


class PairTest:
    def __init__(self, ctx: Context) -> None:
        self.ctx = ctx
        self.tested = 0
        self.conflicting = 0
        self.compatible = 0

    def run(self, routes: Iterable[Route], focus: set[str] | None = None) -> None:
        order = list(routes)
        for i, a in enumerate(order):
            rivals = [b for b in order if b is not a and conflicting(a, b) and (not focus or {a.id, b.id} & focus)]
            later = [b for b in order[i + 1:] if not conflicting(a, b) and not conditional(a, b)
                     and (not focus or {a.id, b.id} & focus)]
            for b in order[i + 1:]:
                if focus and a.id not in focus and b.id not in focus:
                    continue
                self.tested += 1
                if conflicting(a, b):
                    self.conflicting += 1
                elif conditional(a, b):
                    self.conflicting += 1
                    self.compatible += 1
                    self.conditionally(a, b)
                else:
                    self.compatible += 1
                if (b.id in a.conflicts) != (a.id in b.conflicts) or (b.id in a.conditional) != (
                        a.id in b.conditional):
                    self.ctx.record(False, "conflict-symmetry", f"{a.id} + {b.id}",
                                    "the table lists the conflict on one route only")
            if rivals or later:
                self.first(a, rivals, later)

    def conditionally(self, a: Route, b: Route) -> None:
        """A pair that conflicts only for some ways the turnouts beyond a shunting route's end lie: with them lying
        so, the second is refused; lying a way no condition names, both are set and open together."""
        conds = [c for c, _ in a.conditional.get(b.id, ())]
        p = Probe(self.ctx)
        self._lay(p, dict(conds[0]))
        prepare(p, a)
        first = p.do(route_line(a))
        second = p.do(route_line(b))
        self.ctx.record(first.ok and not second.ok, "conflict", f"{a.id} + {b.id}",
                        f"with {_words(dict(conds[0]))}, {b.id} conflicts with {a.id} but "
                        f"'{route_line(a)}' was {_word(first.ok)} and '{route_line(b)}' {_word(second.ok)}", p)
        free = next((w for w in _ways(a, b) if not any(all(w.get(t) is pos for t, pos in c) for c in conds)), None)
        if free is None:
            return
        p = Probe(self.ctx)
        self._lay(p, free)
        ok = open_route(p, a, b, timeout_s=SETTLE_S)
        self.ctx.record(ok, "compatible", f"{a.id} + {b.id}", f"with {_words(free)} they do not conflict but "
                        f"could not both be set and open: {p.blocker(a)}; {p.blocker(b)}", p)

    @staticmethod
    def _lay(p: Probe, positions: dict[str, TurnoutPosition]) -> None:
        for t, pos in positions.items():
            p.do(f"throw {t} {pos.value}")
        p.until(lambda: all(p.sim.turnout_state(t)[0] == pos.value for t, pos in positions.items()), SETTLE_S)

    def why(self, a: Route, b: Route) -> str:
        return a.conflicts.get(b.id) or b.conflicts.get(a.id) or f"both start at {a.signal}"

    def first(self, a: Route, rivals: list[Route], later: list[Route]) -> None:
        p = Probe(self.ctx)
        prepare(p, a)
        if not self.ctx.record(p.do(route_line(a)).ok, "pair-setup", a.id,
                               f"'{route_line(a)}' was refused on a fresh station", p):
            return
        if not self._rivals_refused(p, a, rivals, "setting"):
            return
        if not p.until(lambda: p.state(a) == "open", SETTLE_S):
            self.ctx.record(False, "pair-setup", a.id, f"signal {a.signal} did not open: {p.blocker(a)}", p)
            return
        if not self._rivals_refused(p, a, rivals, "open"):
            return
        for b in later:
            ok = open_route(p, b, timeout_s=SETTLE_S) and p.state(a) == "open"
            if ok:
                self.ctx.record(True, "compatible", f"{a.id} + {b.id}", "")
            else:
                self.replay_together(a, b)
            result = p.do(f"cancel {b.signal}")
            if not result.ok or not p.until(partial(released, p, b), 5.0) or p.state(a) != "open":
                p = Probe(self.ctx)  # could not get back to 'a alone': start again for the rest
                if not open_route(p, a, timeout_s=SETTLE_S):
                    return

    def _rivals_refused(self, p: Probe, a: Route, rivals: list[Route], when: str) -> bool:
        """Every conflicting route is refused while ``a`` is ``when``; a failure is replayed and recorded."""
        for b in rivals:
            if p.do(route_line(b)).ok:
                self.replay_conflict(a, b, when)
                return False
            self.ctx.record(True, "conflict", f"{a.id} + {b.id}", "")
        return True

    def replay_conflict(self, a: Route, b: Route, when: str) -> None:
        """``b`` was accepted with ``a`` set: record the failure with a script of just the two routes."""
        p = Probe(self.ctx)
        prepare(p, a)
        p.do(route_line(a))
        if when == "open":
            p.until(lambda: p.state(a) == "open", SETTLE_S)
        result = p.do(route_line(b))
        p.run(1.0)
        self.ctx.record(False, "conflict", f"{a.id} + {b.id}", f"{b.id} conflicts with {a.id} ({self.why(a, b)}) "
                        f"but was accepted with {a.id} {when}" + ("" if result.ok else " (only after the routes "
                                                                  "tried before it)"), p)

    def replay_together(self, a: Route, b: Route) -> None:
        p = Probe(self.ctx)
        ok = open_route(p, a, b, timeout_s=SETTLE_S)
        detail = f"{p.blocker(a)}; {p.blocker(b)}"
        self.ctx.record(False, "compatible", f"{a.id} + {b.id}", f"{a.id} and {b.id} do not conflict but could not "
                        f"both be set and open: {detail}" + (" (only after the routes tried before it)" if ok else ""),
                        p)


def _ways(a: Route, b: Route) -> list[dict[str, TurnoutPosition]]:
    """Every way the turnouts beyond both routes' ends may lie together."""
    out = []
    for wa in [ro.when for ro in a.run_on] or [()]:
        for wb in [ro.when for ro in b.run_on] or [()]:
            merged = dict(wa)
            if all(merged.get(t, p) is p for t, p in wb):
                merged.update(dict(wb))
                out.append(merged)
    return out


def _words(positions: dict[str, TurnoutPosition]) -> str:
    return ", ".join(f"turnout {t} {p.value}" for t, p in sorted(positions.items()))


def _word(ok: bool) -> str:
    return "accepted" if ok else "refused"

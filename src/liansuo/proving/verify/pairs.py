"""Pairs of routes: conflicting routes (敌对进路) can never be locked together, compatible ones can.

Enemies (:meth:`PairTest.rivals`): a route is set on a fresh simulation; every route that conflicts with it must then
be refused, both while it is still setting and once its signal is open (so each conflicting pair is tried both ways
round). A refused command changes nothing and takes no time, so they are all tried on the one simulation.

Compatible routes (:meth:`PairTest.batches`): a group of pairwise compatible routes (:func:`.plan.cover`) is set
together; every signal open together proves every pair of the group, and the group is cancelled before the next of
its chain is set on the same simulation. A group that does not all open is tried pair by pair, so a failure is
replayed on a fresh simulation and its script shows just the two routes.
"""

from __future__ import annotations

from liansuo.interlocking.table.build import Route
from liansuo.proving.verify.probe import Context, Probe, open_route, prepare, route_line
from liansuo.stations.schema import TurnoutPosition

SETTLE_S = 30.0
MOVE_S = 8.0  # a turnout move with its indication, allowed per round of moves the interlocking drives at once


class PairTest:
    def __init__(self, ctx: Context) -> None:
        self.ctx = ctx

    def batches(self, chain: list[tuple[list[Route], list[tuple[Route, Route]]]]) -> None:
        """Each batch of ``chain`` set together: all open proves each of its pairs, and the batch is cancelled before
        the next is set on the same simulation. A batch that does not all open is tried pair by pair on fresh
        simulations (and the next batch starts on a fresh one)."""
        p: Probe | None = None
        for routes, pairs in chain:
            p = p or Probe(self.ctx)
            moves = len({t.id for r in routes for t in r.all_turnouts})
            timeout = SETTLE_S + MOVE_S * (moves // self.ctx.rules.turnout_concurrency + 1)
            if not open_route(p, *routes, timeout_s=timeout):
                self.one_by_one(pairs)
                p = None
                continue
            for a, b in pairs:
                self.ctx.record(True, "compatible", f"{a.id} + {b.id}", "")
            if not self._cancel_all(p, routes):
                p = None

    @staticmethod
    def _cancel_all(p: Probe, routes: list[Route]) -> bool:
        for r in routes:
            p.do(f"cancel {r.signal}")
        return p.until(lambda: all(p.state(r) == "released" for r in routes), SETTLE_S)

    def one_by_one(self, pairs: list[tuple[Route, Route]]) -> None:
        for a, b in pairs:
            p = Probe(self.ctx)
            ok = open_route(p, a, b, timeout_s=SETTLE_S)
            self.ctx.record(ok, "compatible", f"{a.id} + {b.id}", f"{a.id} and {b.id} do not conflict but could not "
                            f"both be set and open: {p.blocker(a)}; {p.blocker(b)}", p)

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

    def rivals(self, a: Route, rivals: list[Route]) -> None:
        """``a`` set on a fresh station: every route in ``rivals`` is refused while it sets and once it is open."""
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
        self._rivals_refused(p, a, rivals, "open")

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

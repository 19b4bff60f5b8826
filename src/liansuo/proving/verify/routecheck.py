"""One route under the interlocking test: its tally and the way each check is recorded.

:class:`RouteCheck` is what every part of a route's test shares: the opening and locking items
(:mod:`.routes`) and the release, guide, doors and aspect items (:mod:`.release`) both record through it, so
neither needs the other.
"""

from __future__ import annotations

from collections.abc import Callable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass, field
from typing import TypeVar

from liansuo.interlocking.table.build import Route
from liansuo.proving.verify.probe import Context, Probe, open_route

T = TypeVar("T")


@dataclass
class RouteResult:
    id: str
    checks: int = 0
    failures: int = 0
    aspects_seen: set[str] = field(default_factory=set)
    not_applicable: list[str] = field(default_factory=list)
    order: tuple[str, ...] = ()  # the rule set's aspects, most permissive first: how aspects_seen is listed

    def as_dict(self, aspects: tuple[str, ...]) -> dict[str, object]:
        order = {a: i for i, a in enumerate(self.order)}
        return {"id": self.id, "checks": self.checks, "failures": self.failures,
                "aspects_table": list(aspects),
                "aspects_seen": sorted(self.aspects_seen, key=lambda a: order.get(a, 99)),
                "not_applicable": list(self.not_applicable)}


class RouteCheck:
    """The checks of one route so far: ``check`` records one item, ``opened`` opens the route on a probe."""

    def __init__(self, ctx: Context, r: Route) -> None:
        self.ctx = ctx
        self.r = r
        self.res = RouteResult(r.id, order=ctx.rules.aspects.by_rank)

    def check(self, ok: bool, check: str, detail: str, p: Probe | None = None) -> bool:
        self.res.checks += 1
        if not ok:
            self.res.failures += 1
        return self.ctx.record(ok, check, self.r.id, detail, p)

    @contextmanager
    def trial(self) -> Iterator[Context]:
        """Checks made inside go to a scratch tally (yielded), not to the run's."""
        ctx, res = self.ctx, self.res
        self.ctx = Context(ctx.station, ctx.table, ctx.rules, ctx.cycle_s)
        self.res = RouteResult(res.id, order=res.order)
        try:
            yield self.ctx
        finally:
            self.ctx, self.res = ctx, res

    def in_turn(self, items: Sequence[T], start: Callable[[], Probe | None], one: Callable[[Probe, T], bool],
                alone: Callable[[T], object]) -> None:
        """The check of each item, one after the other on one simulation from ``start()`` (a refused command changes
        nothing; a signal reopened after a fault is as it was), while they pass: ``one(p, item)`` says whether the
        simulation is still as it was before the item. An item that fails there, or leaves it otherwise, is checked
        ``alone`` on fresh simulations, as every item used to be, so its failure comes with its own script; the
        next item starts a fresh shared simulation. What the oracle saw on a shared simulation is kept even when the
        item alone does not show it."""
        p: Probe | None = None
        for item in items:
            with self.trial() as scratch:
                if p is None:
                    p = start()
                elif p is not None:
                    p.ctx = scratch  # what the oracle finds goes with this item
                clean = p is not None and one(p, item)
                tally = self.res
            if clean and not scratch.failures:
                self.ctx.checks += scratch.checks
                self.res.checks += tally.checks
                self.res.aspects_seen |= tally.aspects_seen
                continue
            p = None
            before = len(self.ctx.failures)
            alone(item)
            if len(self.ctx.failures) == before:
                for f in scratch.failures:
                    if f.check == "oracle":
                        self.res.failures += 1
                        self.ctx.fail(f)

    def opened(self, p: Probe, check: str) -> bool:
        """Open the route on a fresh probe; a failure to open is recorded under ``check``."""
        ok = open_route(p, self.r)
        if ok:
            self.res.aspects_seen.add(p.aspect(self.r.signal))
        return self.check(ok, check, f"signal {self.r.signal} did not open: {p.blocker(self.r)}", p)


class RouteItems:
    """A group of the items of one route's test, run on its :class:`RouteCheck` ``rt``."""

    def __init__(self, rt: RouteCheck) -> None:
        self.rt = rt
        self.ctx = rt.ctx
        self.r = rt.r
        self.st = rt.ctx.station

    def na(self, what: str) -> None:
        """An item that does not apply to this route, and why."""
        self.rt.res.not_applicable.append(what)

"""One route under the interlocking test: its tally and the way each check is recorded.

:class:`RouteCheck` is what every part of a route's test shares: the opening and locking items
(:mod:`.routes`) and the release, guide, doors and aspect items (:mod:`.release`) both record through it, so
neither needs the other.
"""

from __future__ import annotations

from dataclasses import dataclass, field

from liansuo.interlocking.table import Route

from .probe import Context, Probe, open_route


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

    def opened(self, p: Probe, check: str) -> bool:
        """Open the route on a fresh probe; a failure to open is recorded under ``check``."""
        ok = open_route(p, self.r)
        if ok:
            self.res.aspects_seen.add(p.aspect(self.r.signal))
        return self.check(ok, check, f"signal {self.r.signal} did not open: {p.blocker(self.r)}", p)

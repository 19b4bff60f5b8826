"""``liansuo verify``: the automatic interlocking test (联锁试验) of a whole station.

Every route of the table goes through the items of a real test record (:mod:`.routes`, :mod:`.release`), every
pair of routes is tried together (:mod:`.pairs`) unless the two are compatible and apart (:mod:`.apart`), the
station data is checked against the topology and the design rules (:mod:`.data`), and the throats' guide total lock
is tried. Each dynamic check runs on a fresh simulation
driven only through the command language, so every failure comes with the script that shows it.
"""

from __future__ import annotations

import time
from concurrent.futures import ThreadPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

from liansuo.interlocking.table.build import InterlockingTable, Route
from liansuo.kit.fit import fit_all, plural
from liansuo.proving.oracle.pairs import PaperOracle
from liansuo.proving.progress import progress
from liansuo.proving.spread import WAIT_S
from liansuo.proving.verify.against import approach_extent, pair_conflicts, route_demands, spec
from liansuo.proving.verify.apart import near_masks, table_reach
from liansuo.proving.verify.data import check_station
from liansuo.proving.verify.plan import Unit, UnitResult, again, merge, plan
from liansuo.proving.verify.probe import Failure, FirstFailure
from liansuo.proving.verify.routecheck import RouteResult
from liansuo.proving.verify.units import Bench, frozen, run_here, spread_units
from liansuo.rules import RuleSet, load_rules
from liansuo.stations.loader import load
from liansuo.stations.station import Station


@dataclass
class VerifyReport:
    station: str
    name: str
    routes: int
    routes_tested: int
    pairs_tested: int
    pairs_conflicting: int
    pairs_compatible: int
    checks: int
    failures: list[Failure]
    warnings: list[Failure]
    results: list[RouteResult] = field(default_factory=list)
    table: InterlockingTable | None = None
    elapsed_s: float = 0.0
    strict: bool = False
    pairs_apart: int = 0  # compatible pairs proven apart (.apart), not simulated
    simulate_all: bool = False  # every compatible pair simulated, those apart too

    @property
    def ok(self) -> bool:
        return not self.failures and not (self.strict and self.warnings)

    def as_dict(self) -> dict[str, object]:
        aspects = {r.id: r.aspects for r in self.table.routes.values()} if self.table else {}
        return {
            "station": self.station,
            "routes": self.routes,
            "routes_tested": self.routes_tested,
            "pairs_tested": self.pairs_tested,
            "pairs_conflicting": self.pairs_conflicting,
            "pairs_compatible": self.pairs_compatible,
            "pairs_apart": self.pairs_apart,
            "simulate_all_pairs": self.simulate_all,
            "checks": self.checks,
            "failures": [f.as_dict() for f in self.failures],
            "warnings": [f.as_dict() for f in self.warnings],
            "strict": self.strict,
            "ok": self.ok,
            "route_results": [r.as_dict(aspects.get(r.id, ())) for r in self.results],
            "elapsed_s": round(self.elapsed_s, 2),
        }


def verify_station(station: str | Path | Station, *, routes: list[str] | None = None, pairs: bool = True,
                   strict: bool = False, rules: RuleSet | None = None, cycle_s: float = 0.25,
                   stop_at_first: bool = False, workers: int = 0, scheduler: str | None = None,
                   show_progress: bool | None = False, simulate_all: bool = False,
                   cluster_wait_s: float = WAIT_S) -> VerifyReport:
    """Run the whole interlocking test; ``routes`` limits route and pair checks to those routes. The table is held
    against the oracle first (quick), then every unit of the dynamic test (:mod:`.plan`) runs: here, one after the
    other (``workers`` 0), or fanned out on Dask over ``workers`` local processes or the cluster at ``scheduler``
    (:mod:`proving.spread`; ``cluster_wait_s``: how long to wait for that scheduler and its first worker). The report
    is the same either way.
    Compatible pairs of routes apart (:mod:`.apart`) are proven without a simulation unless ``simulate_all``; those
    of a route that failed on its own are simulated after the other units.
    ``stop_at_first``: stop at the first failure (the mutation run only needs to know that one was found; here only).
    ``show_progress``: a bar on stderr (None: when it is a terminal)."""
    t0 = time.perf_counter()
    rules = rules or load_rules()
    st = station if isinstance(station, Station) else load(station, rules=rules)
    bench = Bench.build(st, rules, cycle_s)
    table = bench.table
    ctx = bench.context(stop_at_first)
    focus = set(routes) if routes else None
    order = list(table.routes.values())
    results: list[UnitResult] = []

    def run(units: list[Unit], what: str) -> list[UnitResult]:
        with progress(what, len(units), show=show_progress) as advance:
            if workers and not stop_at_first:
                return spread_units(bench, units, workers, scheduler, advance, cluster_wait_s)
            return list(run_here(bench, units, stop_at_first=stop_at_first, done=advance))

    with frozen():  # before planning too: on a hub the plan makes millions of objects, the table is millions more
        oracle = PaperOracle(st, ctx.rules)
        prints = [oracle.footprint(spec(r)) for r in order] if pairs else []
        near = None if simulate_all or not pairs else near_routes(st, order, prints, focus)
        work = plan(table, focus, pairs=pairs, near=near)
        apart = work.pairs_apart

        def table_checks() -> None:
            if focus:
                for rid in sorted(focus - set(table.routes)):
                    ctx.record(False, "route", rid, f"there is no route {rid}; see 'liansuo table {st.id}'")
            for r in order:
                if not focus or r.id in focus:
                    route_demands(ctx, oracle, r)
            if pairs:
                pair_conflicts(ctx, oracle, focus, prints)
                for a, b in work.asymmetric:
                    ctx.record(False, "conflict-symmetry", f"{a} + {b}", "the table lists the conflict on one route "
                               "only")
            if not focus:
                approach_extent(ctx)
            check_station(ctx, focus)

        try:
            if workers and not stop_at_first:
                # the table is held against the oracle here while the workers run the units (on a hub it takes
                # half a minute, which a core would otherwise spend waiting); only this thread writes to ctx
                with ThreadPoolExecutor(1) as pool:
                    checked = pool.submit(table_checks)
                    results = run(work.units, f"verify {st.id}")
                    checked.result()
            else:
                table_checks()
                results = run(work.units, f"verify {st.id}")
            failed = {r.route.id for r in results if isinstance(r.route, RouteResult) and r.route.failures}
            if apart and failed and not stop_at_first:
                units, moved = again(work, order, failed)
                apart -= moved
                results += run(units, f"verify {st.id}: pairs of routes that failed on their own")
            ctx.checks += apart  # each pair apart proven (see .apart): a check as a simulation of it would be
        except FirstFailure:  # in the checks against the oracle (the units stop by themselves)
            pass
    checks, failures, warnings = merge([UnitResult(ctx.checks, ctx.failures, ctx.warnings), *results])
    return VerifyReport(st.id, st.display_name(), len(table.routes),
                        sum(1 for u in work.units if u.kind == "route"), work.pairs_tested, work.pairs_conflicting,
                        work.pairs_compatible, checks, failures, warnings,
                        [r.route for r in results if isinstance(r.route, RouteResult)], table,
                        time.perf_counter() - t0, strict, apart, simulate_all)


def near_routes(st: Station, order: list[Route], prints: list[frozenset[str]], focus: set[str] | None
                ) -> list[int]:
    """Which routes are near which (:mod:`.apart`), as bit sets in table order. With a ``focus``, the routes outside
    it have no route unit of their own to stand on: they count as near every route."""
    near = near_masks([table_reach(st, r) | fp for r, fp in zip(order, prints, strict=True)])
    if focus:
        everyone = (1 << len(order)) - 1
        outside = sum(1 << k for k, r in enumerate(order) if r.id not in focus)
        near = [everyone if outside >> k & 1 else m | outside for k, m in enumerate(near)]
    return near


def report_text(rep: VerifyReport, *, verbose: bool = False) -> str:
    lines = [f"liansuo verify {rep.station}: {rep.name}"]
    lines.append(f"routes    {rep.routes_tested} of {rep.routes} tested")
    aspects = {r.id: r.aspects for r in rep.table.routes.values()} if rep.table else {}
    for res in rep.results:
        table = aspects.get(res.id, ())
        shown = [a for a in table if a in res.aspects_seen]
        status = "ok  " if not res.failures else f"FAIL {res.failures}"
        lines.append(f"  {res.id:16} {status:7} {res.checks:4} checks   aspects {'/'.join(shown) or '-':10} of "
                     f"{'/'.join(table)}")
    lines.append(f"pairs     {rep.pairs_tested} tested: {rep.pairs_conflicting} conflicting (each refused after the "
                 f"other, both ways), {rep.pairs_compatible} compatible (both set and open"
                 + (f"; {rep.pairs_apart} of them apart, proven without a simulation)" if rep.pairs_apart else ")"))
    for w in rep.warnings:
        lines.append(f"WARN {w.check} {w.subject}: {w.detail}")
    for f in rep.failures:
        lines.append(f"FAIL {f.check} {f.subject}: {f.detail}")
        if f.steps and verbose:
            lines += ["    station: " + rep.station, "    steps:"] + [f"      - {s}" for s in f.steps]
    if rep.failures and not verbose and any(f.steps for f in rep.failures):
        lines.append("(-v prints the steps that reproduce each failure; --format json includes them)")
    verdict = "PASS" if rep.ok else "FAIL"
    lines.append(f"{verdict}: {plural(rep.checks, 'check')}, {plural(len(rep.failures), 'failure')}, "
                 f"{plural(len(rep.warnings), 'warning')} ({plural(rep.routes_tested, 'route')}, "
                 f"{plural(rep.pairs_tested, 'pair')}) in {rep.elapsed_s:.1f} s")
    return fit_all(lines)

"""Running units of the interlocking test (:mod:`.plan`): each on its own tally, so units can run anywhere and their
results be put together in plan order.

:class:`Bench` is what every unit of one run shares: the station, its rules and its table, built once per process.
"""

from __future__ import annotations

import gc
import uuid
from collections.abc import Callable, Iterable, Iterator, Sequence
from contextlib import contextmanager
from dataclasses import dataclass

from liansuo.interlocking.table.build import InterlockingTable, build_table
from liansuo.proving.progress import Advance
from liansuo.proving.spread import WAIT_S, deal, fan_out
from liansuo.proving.verify.lines import guide_area, line_direction
from liansuo.proving.verify.pairs import PairTest
from liansuo.proving.verify.plan import Unit, UnitResult
from liansuo.proving.verify.probe import Context, FirstFailure
from liansuo.proving.verify.release import throat_checks
from liansuo.proving.verify.routes import RouteTest
from liansuo.proving.verify.station import power_up, queued_move, red_lamp_transfer
from liansuo.rules import RuleSet
from liansuo.stations.station import Station


@dataclass
class Bench:
    station: Station
    rules: RuleSet
    table: InterlockingTable
    cycle_s: float = 0.25

    @staticmethod
    def build(station: Station, rules: RuleSet, cycle_s: float = 0.25, table: InterlockingTable | None = None
              ) -> Bench:
        return Bench(station, rules, table or build_table(station, rules), cycle_s)

    def context(self, stop_at_first: bool = False) -> Context:
        return Context(self.station, self.table, self.rules, self.cycle_s, stop_at_first=stop_at_first)


@contextmanager
def frozen() -> Iterator[None]:
    """The station and table live as long as the run and never change: the garbage collector need not look through
    them again at every collection (a hub's table is millions of objects, and a run builds and drops thousands of
    simulations). Everything alive on entry is set aside until exit."""
    gc.collect()
    gc.freeze()
    try:
        yield
    finally:
        gc.unfreeze()


def run_unit(bench: Bench, unit: Unit, *, stop_at_first: bool = False) -> UnitResult:
    """Run one unit on a tally of its own. With ``stop_at_first`` its first failure ends it (and is raised on)."""
    ctx = bench.context(stop_at_first)
    routes = bench.table.routes
    route = None
    if unit.kind == "route":
        route = RouteTest(ctx, routes[unit.routes[0]]).run()
    elif unit.kind == "rivals":
        a, *rivals = (routes[r] for r in unit.routes)
        PairTest(ctx).rivals(a, rivals)
    elif unit.kind == "batches":
        PairTest(ctx).batches([([routes[r] for r in group], [(routes[a], routes[b]) for a, b in pairs])
                               for group, pairs in unit.batches])
    elif unit.kind == "conditional":
        PairTest(ctx).conditionally(routes[unit.routes[0]], routes[unit.routes[1]])
    elif unit.item == "throats":
        throat_checks(ctx)
    elif unit.item == "power-up":
        power_up(ctx)
    elif unit.item == "red-lamp-transfer":
        red_lamp_transfer(ctx)
    elif unit.item == "line-direction":
        line_direction(ctx)
    elif unit.item == "guide-area":
        guide_area(ctx)
    elif unit.item == "queued-move":
        queued_move(ctx)
    else:
        raise ValueError(f"unknown unit {unit}")
    return UnitResult(ctx.checks, ctx.failures, ctx.warnings, route)


def run_here(bench: Bench, units: Iterable[Unit], *, stop_at_first: bool = False,
             done: Callable[[int], None] | None = None) -> Iterator[UnitResult]:
    """Units one after the other in this process; ``done(n)`` after each. With ``stop_at_first`` the first unit
    that fails is the last."""
    for unit in units:
        try:
            res = run_unit(bench, unit, stop_at_first=stop_at_first)
        except FirstFailure as exc:
            yield UnitResult(1, [exc.args[0]])
            return
        if done:
            done(1)
        yield res


PILES_PER_WORKER = 16  # piles of units per worker: enough to keep every worker busy to the end
_BENCHES: dict[str, Bench] = {}  # in a worker process: the bench of the run in hand, built at its first pile


def spread_units(bench: Bench, units: Sequence[Unit], workers: int, scheduler: str | None,
                 advance: Advance, wait_s: float = WAIT_S) -> list[UnitResult]:
    """Every unit on Dask (:mod:`proving.spread`); results in the order of ``units``. Workers get the station and
    rules once and build the table themselves (it is derived, deterministic, and larger than its station)."""
    piles = deal(units, workers * PILES_PER_WORKER)
    shared = (uuid.uuid4().hex, bench.station, bench.rules, bench.cycle_s)
    done = fan_out(shared, [[units[i] for i in pile] for pile in piles], run_pile, workers=workers,
                   scheduler=scheduler, advance=advance, size=len, wait_s=wait_s)
    out: list[UnitResult] = [UnitResult()] * len(units)
    for pile, results in zip(piles, done, strict=True):
        for i, res in zip(pile, results, strict=True):
            out[i] = res
    return out


def run_pile(shared: tuple[str, Station, RuleSet, float], units: list[Unit]) -> list[UnitResult]:
    """A worker's task: ``units`` of the run ``shared`` names, on the bench it keeps for that run."""
    token, station, rules, cycle_s = shared
    bench = _BENCHES.get(token)
    if bench is None:
        _BENCHES.clear()  # one run at a time per worker: a finished run's bench is dropped
        gc.unfreeze()
        bench = _BENCHES[token] = Bench.build(station, rules, cycle_s)
        gc.collect()
        gc.freeze()  # as in frozen(), for as long as this worker serves the run
    return [run_unit(bench, unit) for unit in units]

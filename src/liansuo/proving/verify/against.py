"""The interlocking table held against the oracle (``liansuo verify``): what the table lists must be what the track
geometry demands, as the oracle judges it on its own (:mod:`proving.oracle.pairs`), not as the table's derivation
does.

- every turnout the oracle finds in a route's flank must be in the route, lying the way that protects it; every
  fouling section must be in the route; every section of the route's authority (its path, the run-on past a signal
  of the other direction, the overlap) must be locked by it; a train route's block sections beyond the station are
  the block's, not the route's;
- every pair of routes the oracle says may not be open together (for some way the turnouts they leave free may lie)
  must be listed as conflicting (for that way, where the table gives a condition); every pair it says may be open
  together must not be (the dynamic pair test then sets them together).
"""

from __future__ import annotations

from liansuo.interlocking.table.build import Route
from liansuo.proving.judge.rules import approach_extent as rules_extent
from liansuo.proving.oracle.pairs import PaperOracle, RouteSpec
from liansuo.proving.verify.probe import Context
from liansuo.stations.schema import SectionRole

_LINE = (SectionRole.approach, SectionRole.departure, SectionRole.block)


def spec(r: Route) -> RouteSpec:
    return RouteSpec(r.id, r.signal, r.kind, {t.id: t.position.value for t in r.all_turnouts})


def route_demands(ctx: Context, oracle: PaperOracle, r: Route) -> None:
    st = ctx.station
    auths, flank, fouling = oracle.demands(spec(r))
    have = {t.id: t.position.value for t in r.all_turnouts}
    for run_on in r.run_on:
        for rt in run_on.turnouts:
            have.setdefault(rt.id, rt.position.value)
    for turnout, d in flank.items():
        ok = have.get(turnout) == d.position
        ctx.record(ok, "flank-protection", r.id, f"turnout {turnout} must protect the route lying {d.position} "
                   f"({d.why}); the table has it {have.get(turnout) or 'not at all'}")
    covered = set(r.all_sections) | {s for ro in r.run_on for s in ro.sections}
    for s in fouling:
        ctx.record(s in covered, "fouling", r.id, f"section {s} lies inside the fouling point of a turnout of the "
                   "route; the table does not check it")
    for a in auths:
        ro = r.run_on_for({t: p for t, p in a.turnouts.items()})
        locked = set(r.all_sections) | (set(ro.sections) if ro else set())
        missing = [s for s in a.all_sections if s not in locked
                   and not (r.kind == "train" and st.sections[s].role in _LINE)]
        ctx.record(not missing, "route-extent", r.id, f"the movement's authority ({_how(a)}) runs over "
                   f"{', '.join(missing)}, which the route does not lock")


def _how(a: object) -> str:
    end = getattr(a, "end", "")
    into = getattr(a, "leads_into", None)
    sig = getattr(a, "end_signal", None)
    return f"to signal {sig}" if sig else f"into {into}" if into else f"to the {end}"


def approach_extent(ctx: Context) -> None:
    """Every route's approach (接近区段) reaches as far as the rule set says, traced on the track layout from the
    block signals in rear (:func:`proving.judge.rules.approach_extent`, which the reference judge reads too)."""
    extent = rules_extent(ctx.station, ctx.rules)
    for sig in ctx.station.model.signals:
        if sig.approach:
            continue  # the station file says
        want = extent.get(sig.id, ())
        for r in ctx.table.routes.values():
            if r.signal == sig.id:
                missing = [s for s in want if s not in r.approach]
                ctx.record(not missing, "approach-locking", r.id, f"a train in {', '.join(missing)} approaches "
                           f"{sig.id}, but the route's approach is {', '.join(r.approach) or 'empty'}")


def pair_conflicts(ctx: Context, oracle: PaperOracle, focus: set[str] | None,
                   prints: list[frozenset[str]] | None = None) -> tuple[int, int]:
    """Every pair of routes from different signals; returns (pairs judged, pairs the oracle keeps apart). Pairs whose
    footprints (:meth:`PaperOracle.footprint`; ``prints``, in table order, if already found) share nothing are judged
    compatible without tracing them together."""
    routes = list(ctx.table.routes.values())
    # the enemies the station file adds are the designer's word, not the oracle's to judge: the pair tests check that
    # the interlocking keeps them apart
    added = {frozenset((e.route, e.enemy)) for e in ctx.station.model.overrides.enemies}
    if prints is None:
        prints = [oracle.footprint(spec(r)) for r in routes]
    holders: dict[str, set[int]] = {}
    for i, fp in enumerate(prints):
        for element in fp:
            holders.setdefault(element, set()).add(i)
    judged = apart = 0
    for i, a in enumerate(routes):
        near = set().union(*(holders[e] for e in prints[i]))
        for j in range(i + 1, len(routes)):
            b = routes[j]
            if a.signal == b.signal or (focus and a.id not in focus and b.id not in focus):
                continue
            judged += 1
            why, lies = oracle.apart_when(spec(a), spec(b)) if j in near else ("", {})
            listed = b.id in a.conflicts
            when = [c for c, _ in a.conditional.get(b.id, ())]
            if why:
                apart += 1
                covered = listed or any(all(lies.get(t) == p.value for t, p in c) for c in when)
                ctx.record(covered, "omitted-conflict", f"{a.id} + {b.id}", f"{why}, but the table does not list "
                           "them as conflicting" + (" for that" if when else ""))
            elif frozenset((a.id, b.id)) not in added:
                ctx.record(not listed and not when, "needless-conflict", f"{a.id} + {b.id}",
                           f"the table lists them as conflicting ({a.conflicts.get(b.id) or 'conditionally'}), but "
                           "the oracle finds nothing they share and no way they meet")
    return judged, apart

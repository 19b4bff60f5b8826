"""Which compatible pairs of routes need a simulation at all: those whose routes touch a common element.

The interlocking couples two routes only through what both name: it refuses a route for a conflicting route in the
table, for a signal that already has a route, or for a section, turnout or block link another route holds
(``interlocking/operations.py``), and it keeps a signal open on the route's own turnouts, sections and liaison, and
on the signal ahead for the aspect (``interlocking/core.py``). So two compatible routes are *apart* when

- their rows of the interlocking table name no element in common (:func:`table_reach`: buttons, signals, the signal
  ahead, turnouts with their crossover partners, sections with the fouling, overlap, approach, run-on and line
  sections, the track led into, diamonds, block link; not the section beyond the end, which the interlocking reads
  only for its occupancy as a train releases the route, and which no route set or opened changes), and
- the oracle's footprints do not meet either (``PaperOracle.footprint``: every element the safety of either route
  turns on, derived from the track geometry, not from the table);

and each route opens on its own (its route unit). Such a pair is proven by that argument, not simulated; every other
compatible pair is set and opened together with its partner as before (:mod:`.pairs`). A pair with a route that
failed on its own is simulated after all, so what fails is reported with the same scripts as when every pair is
simulated (``--simulate-all-pairs``, which simulates the apart pairs too).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

from liansuo.interlocking.table.build import Route
from liansuo.stations.station import Station


def table_reach(station: Station, r: Route) -> frozenset[str]:
    """Every station element the route's row of the table names, as ``kind id`` (the oracle's footprint names
    sections, turnouts and diamonds the same way)."""
    out = {f"signal {r.signal}", *(f"button {b}" for b in (r.start, *r.via, r.end))}
    if r.overlap_end:
        out.add(f"button {r.overlap_end}")
    if r.end_signal:
        out.add(f"signal {r.end_signal}")
    if r.exit_link:
        out.add(f"link {r.exit_link}")
    sections = {*r.all_sections, *r.approach, *r.line_sections, *(s for ro in r.run_on for s in ro.sections)}
    sections |= {s for s in (r.leads_into, *(ro.leads_into for ro in r.run_on)) if s}
    out |= {f"section {s}" for s in sections}
    turnouts = {t.id for t in r.all_turnouts} | {t.id for ro in r.run_on for t in ro.turnouts}
    for t in list(turnouts):
        pair = station.turnouts[t].pair
        turnouts.update(station.pairs[pair] if pair else ())
    out |= {f"turnout {t}" for t in turnouts}
    out |= {f"diamond {d}" for d in r.diamonds}
    return frozenset(out)


def near_masks(reaches: Sequence[Iterable[str]]) -> list[int]:
    """For each route (by position in ``reaches``), the routes whose reach meets its own, as a bit set (bit ``j``
    for route ``j``; its own bit included)."""
    holders: dict[str, int] = {}
    for i, reach in enumerate(reaches):
        for e in reach:
            holders[e] = holders.get(e, 0) | 1 << i
    out = []
    for reach in reaches:
        m = 0
        for e in reach:
            m |= holders[e]
        out.append(m)
    return out

"""Enemy routes (敌对进路) of the interlocking table.

Two routes are enemies when they hold the same section (a fouling section only against a route that runs over it:
several routes may check one fouling section), need a turnout in opposite positions, run over the same diamond, or
lead head-on onto one station track as the rule set's ``enemy_onto_track`` classes say (a train route and an
opposing train or shunting route onto the same track). A receiving route's overlap is not an enemy of the route that
continues from its end signal in the same direction over the overlap: that is a through movement.

A shunting route that runs on past its end (:class:`~interlocking.route.RunOn`) has one variant per way the turnouts
beyond may lie; an enmity that holds for some variants only is conditional (``<2>D2-D4``: enemy with turnout 2
normal). Hubs have millions of conflicting pairs, so the common case is worked in bulk, not pair by pair.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass

from stations.schema import Direction, TurnoutPosition

from .route import Condition, Route
from .rules import RuleSet


@dataclass(frozen=True)
class _Variant:
    route: Route
    when: Condition
    sections: frozenset[str]  # route, overlap and run-on sections
    fouling: frozenset[str]
    turnouts: tuple[tuple[str, TurnoutPosition], ...]
    diamonds: frozenset[str]
    leads_into: str | None

    @property
    def key(self) -> tuple[str, Condition]:
        return (self.route.id, self.when)


def _variants(r: Route) -> list[_Variant]:
    base_sections = set(r.sections) | set(r.overlap_sections)
    base_turnouts = [(t.id, t.position) for t in r.all_turnouts]
    fouling = frozenset(f.section for f in r.fouling) - base_sections
    if not r.run_on:
        return [_Variant(r, (), frozenset(base_sections), fouling, tuple(base_turnouts), frozenset(r.diamonds),
                         r.leads_into)]
    return [_Variant(r, ro.when, frozenset(base_sections | set(ro.sections)), fouling - set(ro.sections),
                     tuple(base_turnouts + [(t.id, t.position) for t in ro.turnouts]), frozenset(r.diamonds),
                     ro.leads_into) for ro in r.run_on]


def derive_conflicts(routes: dict[str, Route], rules: RuleSet) -> None:
    """Fill ``conflicts``, ``conditional``, ``head_on`` and ``opposing`` of every route."""
    variants = [v for r in routes.values() for v in _variants(r)]
    found: dict[tuple[str, Condition], dict[tuple[str, Condition], str]] = defaultdict(dict)

    def bulk(ids: Iterable[_Variant], others: Iterable[_Variant], why: str) -> None:
        other_keys = {o.key for o in others}
        for v in ids:
            c = found[v.key]
            new = other_keys - c.keys()
            if new:
                c.update(dict.fromkeys(new, why))

    by_section: dict[str, list[_Variant]] = defaultdict(list)
    by_fouling: dict[str, list[_Variant]] = defaultdict(list)
    by_turnout: dict[tuple[str, TurnoutPosition], list[_Variant]] = defaultdict(list)
    by_diamond: dict[str, list[_Variant]] = defaultdict(list)
    overlap_of: dict[str, set[str]] = defaultdict(set)  # section -> routes it is an overlap section of
    for v in variants:
        for s in v.sections:
            by_section[s].append(v)
        for s in v.fouling:
            by_fouling[s].append(v)
        for t in v.turnouts:
            by_turnout[t].append(v)
        for d in v.diamonds:
            by_diamond[d].append(v)
        for s in v.route.overlap_sections:
            if s not in v.route.sections:
                overlap_of[s].add(v.route.id)
    for s, vs in by_section.items():
        why = f"section {s}"
        if s in overlap_of:
            for a in vs:
                for b in vs:
                    if a.route is not b.route and not _continues(a.route, b.route, s) \
                            and not _continues(b.route, a.route, s):
                        found[a.key].setdefault(b.key, why)
        else:
            bulk(vs, vs, why)
        if s in by_fouling:
            bulk(vs, by_fouling[s], f"fouling section {s}")
            bulk(by_fouling[s], vs, f"fouling section {s}")
    for (turnout, pos), vs in by_turnout.items():
        flip = TurnoutPosition.reverse if pos is TurnoutPosition.normal else TurnoutPosition.normal
        opposite = by_turnout.get((turnout, flip))
        if opposite:
            bulk(vs, opposite, f"turnout {turnout} {pos.value}/{flip.value}")
    for d, vs in by_diamond.items():
        bulk(vs, vs, f"diamond {d}")
    enemies = {frozenset(pair) for pair in rules.enemy_onto_track}
    onto: dict[str, list[_Variant]] = defaultdict(list)
    for v in variants:
        if v.leads_into is not None:
            onto[v.leads_into].append(v)
    head_on: dict[tuple[str, str], str] = {}
    for track, leading in onto.items():
        meeting = {id(v): v for v in by_section.get(track, [])} | {id(v): v for v in leading}
        for a in leading:
            for b in meeting.values():
                if a.route.direction is not b.route.direction \
                        and frozenset({a.route.kind, b.route.kind}) in enemies:
                    why = f"both lead onto {track} from opposite ends"
                    found[a.key].setdefault(b.key, why)
                    found[b.key].setdefault(a.key, why)
                    head_on[(a.route.id, b.route.id)] = head_on[(b.route.id, a.route.id)] = track
    _collapse(routes, variants, found, head_on)


def _continues(first: Route, then: Route, section: str) -> bool:
    """``then`` starts at ``first``'s end signal, in the same direction, over ``first``'s overlap section."""
    return (then.signal == first.end_signal and then.direction is first.direction
            and section in first.overlap_sections and section not in first.sections)


def _collapse(routes: dict[str, Route], variants: list[_Variant],
              found: dict[tuple[str, Condition], dict[tuple[str, Condition], str]],
              head_on: dict[tuple[str, str], str]) -> None:
    count = {r.id: max(1, len(r.run_on)) for r in routes.values()}
    for r in routes.values():
        r.conflicts.clear()
        r.conditional.clear()
        r.head_on.clear()
    for v in variants:
        if count[v.route.id] == 1:
            # the common case: a route without run-on; a partner with run-ons is sorted out below
            c = v.route.conflicts
            for (other, _), why in found.get(v.key, {}).items():
                if other != v.route.id and count[other] == 1 and other not in c:
                    c[other] = why
    pairs: dict[tuple[str, str], list[tuple[Condition, Condition, str]]] = defaultdict(list)
    for v in variants:
        for (other, when), why in found.get(v.key, {}).items():
            if other != v.route.id and (count[v.route.id] > 1 or count[other] > 1):
                pairs[(v.route.id, other)].append((v.when, when, why))
    for (a, b), combos in pairs.items():
        conds: list[tuple[Condition, str]] = []
        for wa, wb, why in combos:
            merged = dict(wa)
            if any(merged.get(t, p) is not p for t, p in wb):
                continue  # the two run-ons need a turnout both ways: they cannot both be set
            merged.update(dict(wb))
            conds.append((tuple(sorted(merged.items())), why))
        if len({(wa, wb) for wa, wb, _ in combos}) == count[a] * count[b]:
            routes[a].conflicts[b] = combos[0][2]
        elif conds:
            routes[a].conditional[b] = tuple(dict.fromkeys(conds))
    for (a, b), track in head_on.items():
        if b in routes[a].conflicts or b in routes[a].conditional:
            routes[a].head_on[b] = track
    trains: dict[Direction, set[str]] = {d: set() for d in Direction}
    for r in routes.values():
        if r.kind == "train":
            trains[r.direction].add(r.id)
    for r in routes.values():
        if r.kind != "train":
            continue
        against = trains[Direction.up if r.direction is Direction.down else Direction.down]
        r.opposing = tuple(sorted(o for o, why in r.conflicts.items() if o in against and why.startswith("section")))

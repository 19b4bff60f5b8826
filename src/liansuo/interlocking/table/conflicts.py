"""Enemy routes (敌对进路) of the interlocking table.

Two routes are enemies when they hold the same section (a fouling section only against a route that runs over it:
several routes may check one fouling section), need a turnout in opposite positions, run over the same diamond, or
lead head-on onto one station track as the rule set's ``enemy_onto_track`` classes say (a train route and an
opposing train or shunting route onto the same track). A receiving route's overlap is not an enemy of the route that
continues from its end signal in the same direction over the overlap: that is a through movement.

A shunting route that runs on past its end (:class:`~interlocking.route.RunOn`) has one variant per way the turnouts
beyond may lie; an enmity that holds for some variants only is conditional (``<2>D2-D4``: enemy with turnout 2
normal). Hubs have millions of conflicting pairs: routes without run-on are worked in bulk, route sets at a time;
only the variants of routes with a run-on are compared pair by pair.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Callable, Iterable
from dataclasses import dataclass

from liansuo.interlocking.table.route import Condition, Route
from liansuo.rules import RuleSet
from liansuo.stations.schema import TurnoutPosition


@dataclass(frozen=True)
class _Variant:
    route: Route
    when: Condition
    sections: frozenset[str]  # route, overlap and run-on sections
    fouling: frozenset[str]
    turnouts: tuple[tuple[str, TurnoutPosition], ...]
    diamonds: frozenset[str]
    leads_into: str | None


def _base(r: Route) -> _Variant:
    """The route on its own, without what it runs on over."""
    sections = frozenset(r.sections) | frozenset(r.overlap_sections)
    return _Variant(r, (), sections, frozenset(f.section for f in r.fouling) - sections,
                    tuple((t.id, t.position) for t in r.all_turnouts), frozenset(r.diamonds), r.leads_into)


def _variants(r: Route) -> list[_Variant]:
    """One per way the route may be set: itself, or itself and each way it may run on."""
    base = _base(r)
    if not r.run_on:
        return [base]
    return [_Variant(r, ro.when, base.sections | frozenset(ro.sections), base.fouling - frozenset(ro.sections),
                     base.turnouts + tuple((t.id, t.position) for t in ro.turnouts), base.diamonds, ro.leads_into)
            for ro in r.run_on]


def _flip(pos: TurnoutPosition) -> TurnoutPosition:
    return TurnoutPosition.reverse if pos is TurnoutPosition.normal else TurnoutPosition.normal


class _Enmity:
    """The elements of every variant, indexed, and the reason two variants are enemies."""

    def __init__(self, variants: list[_Variant], rules: RuleSet) -> None:
        self.v = variants
        self.enemies = {frozenset(pair) for pair in rules.enemy_onto_track}
        self.by_section: dict[str, set[int]] = defaultdict(set)
        self.by_fouling: dict[str, set[int]] = defaultdict(set)
        self.by_turnout: dict[tuple[str, TurnoutPosition], set[int]] = defaultdict(set)
        self.by_diamond: dict[str, set[int]] = defaultdict(set)
        self.onto: dict[str, set[int]] = defaultdict(set)  # track -> variants leading into it
        self.overlap_of: dict[str, set[str]] = defaultdict(set)  # section -> routes it is an overlap section of
        for i, x in enumerate(variants):
            for s in x.sections:
                self.by_section[s].add(i)
            for s in x.fouling:
                self.by_fouling[s].add(i)
            for t in x.turnouts:
                self.by_turnout[t].add(i)
            for d in x.diamonds:
                self.by_diamond[d].add(i)
            if x.leads_into is not None:
                self.onto[x.leads_into].add(i)
            for s in x.route.overlap_sections:
                if s not in x.route.sections:
                    self.overlap_of[s].add(x.route.id)

    def head_on(self, a: _Variant, b: _Variant) -> str | None:
        if a.route.direction is b.route.direction or frozenset({a.route.kind, b.route.kind}) not in self.enemies:
            return None
        for x, y in ((a, b), (b, a)):
            if x.leads_into is not None and (x.leads_into in y.sections or x.leads_into == y.leads_into):
                return x.leads_into
        return None


def derive_conflicts(routes: dict[str, Route], rules: RuleSet, is_track: Callable[[str], bool]) -> None:
    """Fill ``conflicts``, ``conditional``, ``head_on`` and ``opposing`` of every route; ``is_track``: whether a
    section is a station track (股道)."""
    for r in routes.values():
        r.conflicts.clear()
        r.conditional.clear()
        r.head_on.clear()
    # every route on its own first, in bulk: an enmity there holds whichever way a route runs on
    bases = _Enmity([_base(r) for r in routes.values()], rules)
    _bulk(routes, bases, list(range(len(bases.v))))
    en = bases
    if any(r.run_on for r in routes.values()):
        en = _Enmity([x for r in routes.values() for x in _variants(r)], rules)
        _with_run_on(routes, en)
    variants = en.v
    for x in variants:  # head-on enemies, for the engine (it asks whether the track is still held)
        if x.leads_into is None:
            continue
        for j in en.onto[x.leads_into] | en.by_section.get(x.leads_into, set()):
            y = variants[j]
            track = en.head_on(x, y)
            if track and (y.route.id in x.route.conflicts or y.route.id in x.route.conditional):
                x.route.head_on[y.route.id] = y.route.head_on[x.route.id] = track
    _opposing(routes, is_track)


def _opposing(routes: dict[str, Route], is_track: Callable[[str], bool]) -> None:
    """迎面进路: the enemies of the other direction that lead onto the same station track as the route, from the
    other end (the receiving route of the other throat, a shunting movement into the track from the far end)."""
    onto = {rid: _track_entered(r, is_track) for rid, r in routes.items()}
    for r in routes.values():
        track = onto[r.id]
        r.opposing = () if track is None else tuple(sorted(
            o for o in {*r.conflicts, *r.conditional}
            if o in routes and routes[o].direction is not r.direction and onto[o] == track))


def _track_entered(r: Route, is_track: Callable[[str], bool]) -> str | None:
    """The station track a route ends on (a receiving or transfer route, or a shunting movement into a track)."""
    if r.leads_into is not None:
        return r.leads_into if is_track(r.leads_into) else None
    if r.category == "departure" or not r.sections or not is_track(r.sections[-1]):
        return None
    return r.sections[-1]


def _bulk(routes: dict[str, Route], en: _Enmity, simple: list[int]) -> None:
    """Routes without run-on among themselves, element by element: the first reason found for a pair wins (sections,
    fouling sections, turnouts, diamonds, head-on), and a route's new partners are added all at once."""
    keep = set(simple)
    v = en.v

    def add(ids: Iterable[int], others: set[str], why: str) -> None:
        for i in ids:
            c = v[i].route.conflicts
            new = others - c.keys()
            if new:
                c.update(dict.fromkeys(new, why))

    # in a fixed order (by element name): the first reason found is the one the table prints, the same on every run
    for s, holders in sorted(en.by_section.items()):
        ids = holders & keep
        if not ids:
            continue
        if s in en.overlap_of:
            for i in ids:
                for j in ids:
                    a, b = v[i].route, v[j].route
                    if a is not b and not _continues(a, b, s) and not _continues(b, a, s):
                        a.conflicts.setdefault(b.id, f"section {s}")
        else:
            add(ids, {v[j].route.id for j in ids}, f"section {s}")
        fouled = en.by_fouling.get(s, set()) & keep
        if fouled:
            add(ids, {v[j].route.id for j in fouled}, f"fouling section {s}")
            add(fouled, {v[j].route.id for j in ids}, f"fouling section {s}")
    for (t, pos), holders in sorted(en.by_turnout.items(), key=lambda kv: (kv[0][0], kv[0][1].value)):
        ids = holders & keep
        opposite = en.by_turnout.get((t, _flip(pos)), set()) & keep
        if ids and opposite:
            add(ids, {v[j].route.id for j in opposite}, f"turnout {t} {pos.value}/{_flip(pos).value}")
    for d, holders in sorted(en.by_diamond.items()):
        ids = holders & keep
        add(ids, {v[j].route.id for j in ids}, f"diamond {d}")
    for track, leading in en.onto.items():
        for i in leading & keep:
            for j in (leading | en.by_section.get(track, set())) & keep:
                if en.head_on(v[i], v[j]):
                    why = f"both lead onto {track} from opposite ends"
                    v[i].route.conflicts.setdefault(v[j].route.id, why)
                    v[j].route.conflicts.setdefault(v[i].route.id, why)
    for r in routes.values():
        r.conflicts.pop(r.id, None)


def _with_run_on(routes: dict[str, Route], en: _Enmity) -> None:
    """Every pair with a route that runs on past its end and not already enemies on their own, variant by variant:
    an enemy under every combination of their variants is one always, under some only conditionally (under the
    turnout positions that choose them)."""
    v = en.v
    combos: dict[tuple[str, str], dict[tuple[int, int], str]] = defaultdict(dict)

    variants_of: dict[str, list[int]] = defaultdict(list)
    for i, x in enumerate(v):
        variants_of[x.route.id].append(i)

    def record(i: int, j: int, why: str) -> None:
        a, b = v[i].route, v[j].route
        key, pair = ((a.id, b.id), (i, j)) if a.id < b.id else ((b.id, a.id), (j, i))
        combos[key].setdefault(pair, why)

    for r in routes.values():
        if not r.run_on:
            continue
        # the variants of this route and of its enemies on their own need no more looking at
        skip = set(variants_of[r.id]).union(*(variants_of[o] for o in r.conflicts))
        base = _base(r)
        for i in variants_of[r.id]:
            x = v[i]
            # only what the run-on adds can make enemies the routes on their own are not
            secs = x.sections - base.sections
            turns = {t: pos for t, pos in x.turnouts[len(base.turnouts):]}
            cand = set().union(*(en.by_section[s] for s in secs), *(en.by_fouling.get(s, ()) for s in secs),
                               *(en.by_turnout.get((t, _flip(pos)), ()) for t, pos in turns.items())) - skip
            for j in cand:
                y = v[j]
                why = next((f"section {s}" for s in sorted(secs & y.sections)
                            if not _continues(r, y.route, s) and not _continues(y.route, r, s)), "")
                if not why and secs & y.fouling:
                    why = f"fouling section {min(secs & y.fouling)}"
                if not why:
                    theirs = dict(y.turnouts)
                    why = next((f"turnout {t} {pos.value}/{theirs[t].value}" for t, pos in turns.items()
                                if theirs.get(t, pos) is not pos), "")
                if why:
                    record(i, j, why)
            for track in {x.leads_into, *secs} - {None}:
                rivals = en.onto.get(track or "", set())
                if track == x.leads_into:
                    rivals = rivals | en.by_section.get(track or "", set())
                for j in rivals - skip:
                    over = en.head_on(x, v[j])
                    if over:
                        record(i, j, f"both lead onto {over} from opposite ends")
    sets = {r.id: {t.id: t.position for t in r.all_turnouts} for r in routes.values()}
    when = [dict(x.when) for x in v]

    def fits(i: int, other: str) -> bool:
        """The run-on of variant ``i`` can be chosen with route ``other`` set (``other`` keeps none of its
        turnouts the other way)."""
        keep = sets[other]
        return all(keep.get(t, p) is p for t, p in v[i].when)

    for (a, b), found in combos.items():
        # the ways each route may run on with the other set (it keeps none of their turnouts the other way)
        va = [i for i in variants_of[a] if fits(i, b)]
        vb = [j for j in variants_of[b] if fits(j, a)]
        if len(vb) == 1 or len(va) == 1:  # the common case: one of the two has a single way
            one_b = len(vb) == 1
            single, many = (vb[0], va) if one_b else (va[0], vb)
            hits = [(k, (k, single) if one_b else (single, k)) for k in many
                    if ((k, single) if one_b else (single, k)) in found]
            if hits and len(hits) == len(many):
                routes[a].conflicts[b] = routes[b].conflicts[a] = found[hits[0][1]]
            elif hits:
                routes[a].conditional[b] = routes[b].conditional[a] = tuple(
                    dict.fromkeys((v[k].when, found[pair]) for k, pair in hits))
            continue
        both = [(i, j) for i in va for j in vb if all(when[j].get(t, p) is p for t, p in v[i].when)]
        hit = [(i, j) for i, j in both if (i, j) in found]
        if not hit:
            continue
        if len(hit) == len(both):
            routes[a].conflicts[b] = routes[b].conflicts[a] = found[hit[0]]
            continue
        conds: list[tuple[Condition, str]] = []
        rows = {i for i in va if all((i, j) in found for i2, j in both if i2 == i)}
        cols = {j for j in vb if all((i, j) in found for i, j2 in both if j2 == j)}
        for i in sorted(rows):
            conds.append((v[i].when, found[next(p for p in hit if p[0] == i)]))
        for j in sorted(cols):
            conds.append((v[j].when, found[next(p for p in hit if p[1] == j)]))
        for i, j in hit:
            if i not in rows and j not in cols:
                conds.append((tuple(sorted({**when[i], **when[j]}.items())), found[(i, j)]))
        routes[a].conditional[b] = routes[b].conditional[a] = tuple(dict.fromkeys(conds))


def _continues(first: Route, then: Route, section: str) -> bool:
    """``then`` starts at ``first``'s end signal, in the same direction, over ``first``'s overlap section."""
    return (then.signal == first.end_signal and then.direction is first.direction
            and section in first.overlap_sections and section not in first.sections)

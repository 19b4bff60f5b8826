"""The oracle's judgment of routes on paper, for ``liansuo verify``: what a route's authority needs, and whether two
routes may be open together.

A route is given only as the turnout positions it sets (route, flank-protection, driven and overlap turnouts, as
any table lists them) and its signal; the oracle traces the authority from there over the geometry, exactly as it
does in the running simulation. A turnout the route leaves free but the authority runs over (beyond the route's end,
for a shunting movement that goes past a signal of the other direction) may lie either way: every way it may lie is
tried. Two routes may not be open together when, for some way the free turnouts lie, they need a turnout in
opposite positions (the partners of a crossover pair always lie alike), one's flank needs a turnout the other's path
turns the wrong way, they share a section or a diamond (other than an overlap the other continues over), or they
lead head-on onto one track as the rule set's enemy classes say.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass

from liansuo.proving.oracle.authority import Authority, Kind, Tracer, other
from liansuo.proving.oracle.flank import Demand, Flank, clearance_m
from liansuo.proving.oracle.meet import Extent, head_on, shared
from liansuo.rules import RuleSet
from liansuo.stations.station import Station


@dataclass(frozen=True)
class RouteSpec:
    """A route as the oracle sees it: its signal, kind and the positions it sets."""

    name: str
    signal: str
    kind: Kind
    positions: Mapping[str, str]


class PaperOracle:
    def __init__(self, station: Station, rules: RuleSet) -> None:
        self.st = station
        self.tracer = Tracer(station, rules=rules)
        self.flank = Flank(station, clearance_m(station, rules))
        self.enemies = [frozenset(pair) for pair in rules.enemy_onto_track]
        self.partners: dict[str, list[str]] = {}
        for members in station.pairs.values():
            for t in members:
                self.partners[t] = [m for m in members if m != t]

    # ---- positions ---------------------------------------------------------------------------------------------------
    def settle(self, *specs: RouteSpec) -> tuple[dict[str, str], str]:
        """The positions the routes set together (crossover partners alike), or why they cannot."""
        out: dict[str, str] = {}
        who: dict[str, str] = {}
        for spec in specs:
            for t, pos in spec.positions.items():
                for u in [t, *self.partners.get(t, ())]:
                    if out.get(u, pos) != pos:
                        return out, (f"turnout {u}: {who[u]} needs it {out[u]}, {spec.name} needs it {pos}"
                                     + (f" (crossover {self.st.turnouts[u].pair})" if u != t else ""))
                    out[u] = pos
                    who.setdefault(u, spec.name)
        return out, ""

    def configurations(self, fixed: dict[str, str], *specs: RouteSpec) -> Iterator[tuple[dict[str, str],
                                                                                          list[Authority]]]:
        """Every way the free turnouts the authorities run over may lie, with the authorities traced over it. A free
        facing turnout may lie either way; a free turnout a path runs through trailing is set the way the path
        needs (the interlocking brings it there); two paths that need a free turnout both ways cannot be set
        together, which shows as a turnout one path needs the other way round."""
        stack = [dict(fixed)]
        while stack:
            lies = stack.pop()
            auths = [self.tracer.trace(s.signal, s.kind, lies.get) for s in specs]
            free = next((a.broken_at for a in auths if a.end == "broken" and a.broken_at is not None), None)
            trailing = {t: a.turnouts[t] for a in auths for t in a.against if lies.get(t) is None}
            if free is None and trailing:  # the facing turnouts first: they lie as they lie; these follow
                nxt = dict(lies)
                for t, pos in trailing.items():
                    for u in [t, *self.partners.get(t, ())]:
                        nxt.setdefault(u, pos)
                stack.append(nxt)
                continue
            if free is None:
                yield lies, auths
                continue
            for pos in ("normal", "reverse"):
                nxt = dict(lies)
                for u in [free, *self.partners.get(free, ())]:
                    nxt[u] = pos
                stack.append(nxt)

    # ---- one route ---------------------------------------------------------------------------------------------------
    def demands(self, spec: RouteSpec) -> tuple[list[Authority], dict[str, Demand], list[str]]:
        """The route's authorities (one per way its free turnouts lie), the flank turnouts and the fouling sections
        their paths demand."""
        fixed, _ = self.settle(spec)
        auths: list[Authority] = []
        flank: dict[str, Demand] = {}
        fouling: list[str] = []
        for _, (a,) in self.configurations(fixed, spec):
            auths.append(a)
            d, f = self.flank.of(a.tracks, a.turnouts)
            for t, dem in d.items():
                flank.setdefault(t, dem)
            fouling += [s for s in f if s not in fouling]
        return auths, flank, fouling

    # ---- what a route can touch -------------------------------------------------------------------------------------
    def footprint(self, spec: RouteSpec) -> frozenset[str]:
        """Every element the route's judgement against another route can turn on, over every way its free turnouts
        lie: the turnouts it sets, runs over, needs for flank protection or lies against (with their crossover
        partners), its sections, fouling sections and diamonds, the track it leads onto. Two routes whose footprints
        are disjoint may be open together: :meth:`apart_when` finds a reason only in an element both touch (a
        turnout set or needed both ways, a section, diamond or fouling section both hold, a track both lead onto),
        and another route's turnouts change a route's authority only where that authority runs over them."""
        fixed, _ = self.settle(spec)
        turnouts = set(fixed)
        elements: set[str] = set()
        for _, (a,) in self.configurations(fixed, spec):
            demands, fouling = self.flank.of(a.tracks, a.turnouts)
            turnouts |= set(a.turnouts) | set(a.overlap_turnouts) | set(a.against) | set(demands)
            if a.broken_at:
                turnouts.add(a.broken_at)
            elements |= {f"section {s}" for s in (*a.all_sections, *fouling)}
            elements |= {f"diamond {d}" for d in a.diamonds}
            if a.leads_into:
                elements.add(f"section {a.leads_into}")  # head-on: its section, as the other's path names it
            for secs, over, _ in self.tracer.overlaps.get(a.end_signal or "", ()) if a.kind == "train" else ():
                elements |= {f"section {s}" for s in secs}  # every overlap: which one is taken turns on how
                turnouts |= set(over)  # its turnouts lie, and another route may set them
        for t in list(turnouts):
            turnouts.update(self.partners.get(t, ()))
        return frozenset(elements | {f"turnout {t}" for t in turnouts})

    # ---- two routes --------------------------------------------------------------------------------------------------
    def apart(self, x: RouteSpec, y: RouteSpec) -> str:
        """'' when ``x`` and ``y`` may be open together, else the first reason they may not."""
        return self.apart_when(x, y)[0]

    def apart_when(self, x: RouteSpec, y: RouteSpec) -> tuple[str, dict[str, str]]:
        """(why ``x`` and ``y`` may not be open together, the turnout positions under which they may not); ('', {})
        when they may."""
        fixed, why = self.settle(x, y)
        if why:
            return why, fixed
        for lies, (a, b) in self.configurations(fixed, x, y):
            for first, second in ((a, b), (b, a)):
                for t in first.against:
                    if t in second.turnouts and second.turnouts[t] != first.turnouts[t]:
                        return (f"turnout {t}: {first.signal}'s path needs it {first.turnouts[t]}, {second.signal}'s "
                                f"{second.turnouts[t]}" + self._when(lies, fixed)), lies
            fouling: list[set[str]] = []
            for first, second, spec in ((a, b, y), (b, a, x)):
                demands, foul = self.flank.of(first.tracks, first.turnouts)
                fouling.append(set(foul))
                for t, d in demands.items():
                    got = lies.get(t)
                    if got is not None and got != d.position and (t in spec.positions or t in second.turnouts):
                        return (f"{first.signal}'s flank needs turnout {t} {d.position} ({d.why}); "
                                f"{spec.name} needs it {other(d.position)}"), lies
            ea, eb = Extent.whole(a, x.name, fouling[0]), Extent.whole(b, y.name, fouling[1])
            elements = shared(ea, eb)
            if elements:
                return f"both hold {elements[0]}" + self._when(lies, fixed), lies
            track = head_on(ea, eb, self.enemies)
            if track is not None:
                return f"{x.kind} and {y.kind} movements lead head-on onto {track}" + self._when(lies, fixed), lies
        return "", {}

    @staticmethod
    def _when(lies: dict[str, str], fixed: dict[str, str]) -> str:
        free = {t: p for t, p in lies.items() if t not in fixed}
        return " (with " + ", ".join(f"turnout {t} {p}" for t, p in sorted(free.items())) + ")" if free else ""

"""The interlocking table (联锁表), derived from the topology.

One row per route: buttons, the signal it opens and the aspects it can give, turnouts with position and role
(``route``; ``protection`` for flank protection, 防护道岔; ``driven``, 带动道岔), track sections, conditional fouling
sections (侵限), the approach section, an overlap where the station file asks for one, and the conflicting and
opposing routes. Any two routes that share a section or need a turnout in opposite positions conflict, so the
conflict relation is symmetric by construction.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Iterable
from dataclasses import dataclass, field
from itertools import pairwise
from typing import Literal

from stations.schema import Button, Direction, SectionRole, SignalKind, TurnoutPosition
from stations.source import Diagnostic, StationError
from stations.station import Station
from stations.topology import Move, Path

Role = Literal["route", "protection", "driven"]
Kind = Literal["train", "shunt"]

_FLANK_SEARCH_M = 250.0  # how far from a route turnout's unused leg a protection turnout is looked for


@dataclass(frozen=True)
class RouteTurnout:
    id: str
    position: TurnoutPosition
    role: Role


@dataclass(frozen=True)
class FoulingSection:
    """A section beyond a joint laid inside a turnout's fouling point: it must be clear for the route."""

    section: str
    turnout: str
    position: TurnoutPosition


@dataclass
class Route:
    id: str
    kind: Kind
    category: str  # receiving, departure, transfer, shunting
    start: str
    end: str
    via: tuple[str, ...]
    signal: str
    direction: Direction
    path: Path
    turnouts: tuple[RouteTurnout, ...]
    sections: tuple[str, ...]
    fouling: tuple[FoulingSection, ...]
    approach: tuple[str, ...]
    end_node: str
    end_signal: str | None  # the same-direction signal at the end of the route (the next signal)
    beyond: str | None  # the section just past the end of the route
    exit_link: str | None = None  # block link the route departs into
    overlap_sections: tuple[str, ...] = ()
    overlap_turnouts: tuple[RouteTurnout, ...] = ()
    overlap_release_s: float = 0.0
    aspects: tuple[str, ...] = ()
    conflicts: dict[str, str] = field(default_factory=dict)  # route id -> why
    opposing: tuple[str, ...] = ()

    @property
    def all_sections(self) -> tuple[str, ...]:
        return self.sections + tuple(f.section for f in self.fouling) + self.overlap_sections

    @property
    def all_turnouts(self) -> tuple[RouteTurnout, ...]:
        return self.turnouts + self.overlap_turnouts

    def as_dict(self) -> dict[str, object]:
        return {
            "id": self.id,
            "kind": self.kind,
            "category": self.category,
            "start": self.start,
            "end": self.end,
            "via": list(self.via),
            "signal": self.signal,
            "direction": self.direction.value,
            "aspects": list(self.aspects),
            "turnouts": [{"id": t.id, "position": t.position.value, "role": t.role} for t in self.turnouts],
            "sections": list(self.sections),
            "fouling_sections": [{"section": f.section, "turnout": f.turnout, "position": f.position.value}
                                 for f in self.fouling],
            "approach": list(self.approach),
            "overlap": ({"sections": list(self.overlap_sections),
                         "turnouts": [{"id": t.id, "position": t.position.value} for t in self.overlap_turnouts],
                         "release_s": self.overlap_release_s} if self.overlap_sections else None),
            "length_m": round(self.path.length, 1),
            "conflicts": sorted(self.conflicts),
            "conflict_reasons": dict(sorted(self.conflicts.items())),
            "opposing": list(self.opposing),
        }


@dataclass
class InterlockingTable:
    station: Station
    routes: dict[str, Route]
    throats: dict[str, tuple[str, ...]]  # throat name (its home signals) -> turnouts
    unselectable: list[str] = field(default_factory=list)  # paths with no distinguishing via button

    _buttons: dict[tuple[str, str, str, tuple[str, ...]], Route] = field(default_factory=dict, init=False,
                                                                         repr=False, compare=False)

    def by_buttons(self, kind: Kind, start: str, end: str, via: Iterable[str] = ()) -> Route | None:
        key = (kind, start, end, tuple(via))
        r = self._buttons.get(key)
        if r is None or self.routes.get(r.id) is not r:  # first use, or the routes were edited: index again
            self._buttons.clear()
            for x in self.routes.values():
                self._buttons.setdefault((x.kind, x.start, x.end, x.via), x)
            r = self._buttons.get(key)
        return r

    def as_dict(self) -> dict[str, object]:
        return {"station": self.station.id, "routes": [r.as_dict() for r in self.routes.values()],
                "throats": {k: list(v) for k, v in self.throats.items()}}


# ---- building --------------------------------------------------------------------------------------------------
class _Builder:
    def __init__(self, station: Station) -> None:
        self.st = station
        self.topo = station.topology
        self.errors: list[Diagnostic] = []

    # end candidates at a node for a movement in direction d
    def _train_end(self, node: str, d: Direction) -> tuple[str, str] | None:
        """(end button, end kind) if a train route may end here; kind is 'signal' or 'exit'."""
        for s in self.st.signals_at(node):
            if s.direction is d and Button.train in s.buttons:
                return s.id, "signal"
        if self.st.model.line == "single":  # a single line is worked both ways: the opposite home signal is the exit
            for s in self.st.signals_at(node):
                if s.direction is not d and s.kind is SignalKind.home:
                    return s.id, "exit"
        for b in self.st.model.buttons:
            if b.at == node and b.kind == "exit" and (b.direction is None or b.direction is d):
                return b.id, "exit"
        return None

    def _walk_routes(self, signal: str, kind: Kind) -> list[tuple[str, Path, str | None]]:
        """(end button, path, end signal) for every route from ``signal``."""
        sig = self.st.signals[signal]
        d = sig.direction
        out: list[tuple[str, Path, str | None]] = []
        first: Move = self.topo.start_move(sig.at, d)
        # depth-first over moves; each stack item is the list of moves so far and their length
        stack: list[tuple[list[Move], float]] = [([first], self.st.track_length(first[0]))]
        while stack:
            moves, length = stack.pop()
            last = moves[-1]
            node = self.topo.far_node(last)
            stop = False
            if kind == "train":
                end = self._train_end(node, d)
                if end is not None:
                    button, end_kind = end
                    out.append((button, self._path(sig.at, d, moves), button if end_kind == "signal" else None))
                    stop = True
            else:
                for s in self.st.signals_at(node):
                    if Button.shunt in s.buttons:
                        out.append((s.id, self._path(sig.at, d, moves), s.id if s.direction is d else None))
                        if s.direction is d:
                            stop = True
                    elif s.direction is not d and s.kind is SignalKind.home:
                        stop = True  # do not shunt out past the home signal
                for b in self.st.model.buttons:
                    if b.at == node and b.kind == "end":
                        out.append((b.id, self._path(sig.at, d, moves), None))
            if stop or length > 5000:
                continue
            for nxt, _ in self.topo.next_moves(last):
                if any(m[0] == nxt[0] for m in moves):
                    continue
                if kind == "shunt" and self.st.is_station_track(self.st.tracks[nxt[0]].section) \
                        and self.st.is_station_track(self.st.tracks[last[0]].section) is False \
                        and self._has_shunt_end(node):
                    continue  # a shunting route ends where it enters a station track
                stack.append(([*moves, nxt], length + self.st.track_length(nxt[0])))
        return out

    def _has_shunt_end(self, node: str) -> bool:
        return any(Button.shunt in s.buttons for s in self.st.signals_at(node))

    def _path(self, start: str, d: Direction, moves: list[Move]) -> Path:
        turnouts: list[tuple[str, TurnoutPosition]] = []
        joints: list[str] = []
        for a, b in pairwise(moves):
            data = self.topo.graph.edges[a, b]
            if data["turnout"] is not None:
                turnouts.append((str(data["turnout"]), TurnoutPosition(str(data["position"]))))
            if data["node"] in self.st.joints:
                joints.append(str(data["node"]))
        length = sum(self.st.track_length(t) for t, _ in moves)
        return self.topo._path(start, d, moves, turnouts, joints, length, self.topo.far_node(moves[-1]))

    # ---- per-route details ---------------------------------------------------------------------------------
    def _flank(self, path: Path) -> tuple[list[RouteTurnout], list[FoulingSection]]:
        route_pos = dict(path.turnouts)
        protection: dict[str, TurnoutPosition] = {}
        fouling: list[FoulingSection] = []
        for t, pos in path.turnouts:
            # which leg did the path use, and which is free?
            used_leg = pos.value
            free_leg = "reverse" if used_leg == "normal" else "normal"
            track = self.st.leg_track(t, free_leg)
            node_from = t
            travelled = 0.0
            crossed_joint = False
            while True:
                a, b = self.st.track_ports[track]
                far = b if a.node == node_from else a
                travelled += self.st.track_length(track)
                if crossed_joint:
                    # a fouling point on the first track past the joint means the joint is inside the fouling limit
                    if any(fp.track == track for fp in self.st.model.fouling_points):
                        fouling.append(FoulingSection(self.st.tracks[track].section, t, pos))
                    break_after_fouling = True
                else:
                    break_after_fouling = False
                if self.st.is_station_track(self.st.tracks[track].section):
                    break
                if far.leg is not None:  # reached another turnout
                    u = far.node
                    if far.leg != "point" and u not in route_pos:
                        other = TurnoutPosition.reverse if far.leg == "normal" else TurnoutPosition.normal
                        # a protection position must lead away from the route, never into one of its sections
                        # (in a scissors crossover the other diagonal crosses the route at the diamond)
                        away = self.st.tracks[self.st.leg_track(u, other.value)].section
                        if away not in path.sections:
                            protection.setdefault(u, other)
                    break
                if far.node not in self.st.joints or travelled > _FLANK_SEARCH_M:
                    break
                lo, hi = self.st.joint_tracks(far.node)
                track = hi if lo == track else lo
                node_from = far.node
                crossed_joint = True
                if break_after_fouling:
                    break
        prot = [RouteTurnout(u, p, "protection") for u, p in protection.items()]
        return prot, fouling

    def build(self) -> InterlockingTable:
        routes: dict[str, Route] = {}
        unselectable: list[str] = []
        overlaps = {o.end_signal: o for o in self.st.model.overlaps}
        for sig in self.st.model.signals:
            for kind in ("train", "shunt"):
                button = Button.train if kind == "train" else Button.shunt
                if button not in sig.buttons:
                    continue
                if kind == "train" and sig.kind not in (SignalKind.home, SignalKind.starting, SignalKind.route):
                    continue
                grouped: dict[str, list[tuple[Path, str | None]]] = defaultdict(list)
                for end, path, end_signal in self._walk_routes(sig.id, kind):
                    grouped[end].append((path, end_signal))
                for end, paths in grouped.items():
                    paths.sort(key=lambda pe: (sum(p is TurnoutPosition.reverse for _, p in pe[0].turnouts),
                                               pe[0].length, pe[0].tracks))
                    basic = paths[0]
                    self._add(routes, sig.id, kind, end, (), basic[0], basic[1], overlaps)  # type: ignore[arg-type]
                    for path, end_signal in paths[1:]:
                        via = self._via(path, basic[0])
                        if via is None:
                            unselectable.append(f"{sig.id}-{end} via {'/'.join(t for t, _ in path.turnouts)}")
                            continue
                        self._add(routes, sig.id, kind, end, (via,), path, end_signal, overlaps)  # type: ignore[arg-type]
        self._apply_overrides(routes)
        if self.errors:
            raise StationError(self.errors)
        _conflicts(routes)
        from .aspects import possible_aspects

        for r in routes.values():
            r.aspects = possible_aspects(self.st, r)
        return InterlockingTable(self.st, routes, self._throats(), unselectable)

    def _via(self, path: Path, basic: Path) -> str | None:
        basic_nodes = set(basic.joints) | set(basic.tracks)
        for j in path.joints:
            if j in basic_nodes:
                continue
            for s in self.st.signals_at(j):
                return s.id
            for b in self.st.model.buttons:
                if b.at == j and b.kind == "variant":
                    return b.id
        for t in path.tracks:
            if t in basic_nodes:
                continue
            for b in self.st.model.buttons:
                if b.at == t and b.kind == "variant":
                    return b.id
        return None

    def _add(self, routes: dict[str, Route], start: str, kind: Kind, end: str, via: tuple[str, ...], path: Path,
             end_signal: str | None, overlaps: dict[str, object]) -> None:
        st = self.st
        rid = f"{start}-{end}" + (f"({','.join(via)})" if via else "")
        same = routes.get(rid)
        if kind == "shunt" and same is not None and same.kind == "train":
            rid = f"{rid}/D"
        turnouts = [RouteTurnout(t, p, "route") for t, p in path.turnouts]
        prot, fouling = self._flank(path)
        in_route = {t.id for t in turnouts}
        # crossover pairs: the partner of a route turnout moves with it
        for t in list(turnouts):
            pair = st.turnouts[t.id].pair
            if pair is None:
                continue
            for partner in st.pairs[pair]:
                if partner in in_route:
                    continue
                if any(p.id == partner for p in prot):
                    prot = [RouteTurnout(p.id, t.position, "protection") if p.id == partner else p for p in prot]
                else:
                    prot.append(RouteTurnout(partner, t.position, "driven"))
                in_route.add(partner)
        prot = [p for p in prot if p.id not in {t.id for t in turnouts}]
        sig = st.signals[start]
        end_node = path.end
        beyond = None
        if end_node in st.joints:
            beyond = st.tracks[st.entry_track(end_node, path.direction)].section
        exit_link = None
        if kind == "train" and end_signal is None:
            exit_link = self._link_beyond(end_node, path.direction)
        if kind == "train":
            category = "departure" if end_signal is None else (
                "receiving" if sig.kind is SignalKind.home else "transfer")
        else:
            category = "shunting"
        ov_sections: tuple[str, ...] = ()
        ov_turnouts: tuple[RouteTurnout, ...] = ()
        ov_release = 0.0
        ov = overlaps.get(end_signal or "") if kind == "train" and category == "receiving" else None
        if ov is not None:
            ov_sections = tuple(ov.sections)  # type: ignore[attr-defined]
            ov_turnouts = tuple(RouteTurnout(t.turnout, t.position, "route")
                                for t in ov.turnouts)  # type: ignore[attr-defined]
            ov_release = float(ov.release_s)  # type: ignore[attr-defined]
        routes[rid] = Route(
            id=rid, kind=kind, category=category, start=start, end=end, via=via, signal=start,
            direction=path.direction, path=path, turnouts=tuple(turnouts + prot), sections=path.sections,
            fouling=tuple(dict.fromkeys(f for f in fouling if f.section not in path.sections)),
            approach=tuple(st.approach_sections(start)), end_node=end_node, end_signal=end_signal, beyond=beyond,
            exit_link=exit_link, overlap_sections=ov_sections, overlap_turnouts=ov_turnouts,
            overlap_release_s=ov_release,
        )
        del sig

    def _link_beyond(self, node: str, d: Direction) -> str | None:
        """The block link reached by going on from ``node`` in direction ``d`` without passing a turnout."""
        track = self.st.entry_track(node, d) if node in self.st.joints else None
        seen = 0
        while track is not None and seen < 50:
            seen += 1
            far = self.topo.far_node((track, d))
            if far in self.st.ends:
                for lk in self.st.model.links:
                    if lk.end == far:
                        return lk.id
                return None
            if far not in self.st.joints:
                return None
            track = self.st.entry_track(far, d)
        return None

    def _apply_overrides(self, routes: dict[str, Route]) -> None:
        ov = self.st.model.overrides
        src = self.st.source
        for k, rid in enumerate(ov.forbid):
            if rid not in routes:
                self._err(("overrides", "forbid", k), f"override forbids route '{rid}', which the topology does not "
                          "give", f"routes are named START-END; see 'liansuo table {self.st.id}'")
            else:
                del routes[rid]
        for key, adding in (("protection", True), ("remove_protection", False)):
            for k, p in enumerate(getattr(ov, key)):
                r = routes.get(p.route)
                if r is None:
                    self._err(("overrides", key, k, "route"), f"override names route '{p.route}', which does not "
                              "exist", f"routes are named START-END; see 'liansuo table {self.st.id}'")
                    continue
                if adding:
                    if any(t.id == p.turnout and t.role == "route" for t in r.turnouts):
                        self._err(("overrides", key, k, "turnout"), f"turnout {p.turnout} is already in route "
                                  f"{r.id}; it cannot also protect it", "")
                        continue
                    rest = [t for t in r.turnouts if t.id != p.turnout]
                    r.turnouts = (*rest, RouteTurnout(p.turnout, p.position, "protection"))
                else:
                    if not any(t.id == p.turnout and t.role == "protection" for t in r.turnouts):
                        self._err(("overrides", key, k, "turnout"), f"turnout {p.turnout} does not protect route "
                                  f"{r.id}", "")
                        continue
                    r.turnouts = tuple(t for t in r.turnouts if not (t.id == p.turnout and t.role == "protection"))
        del src

    def _err(self, loc: tuple[str | int, ...], msg: str, hint: str) -> None:
        if self.st.source is not None:
            self.errors.append(self.st.source.diagnostic(loc, msg, hint))
        else:
            self.errors.append(Diagnostic("<station>", 1, 1, msg, hint))

    def _throats(self) -> dict[str, tuple[str, ...]]:
        """Turnouts of each throat, named by the home signals that lead into it."""
        import networkx as nx

        g = nx.Graph()
        inside = {t for t, tr in self.st.tracks.items()
                  if self.st.sections[tr.section].role not in (SectionRole.station_track, SectionRole.approach,
                                                                SectionRole.block, SectionRole.departure)}
        g.add_nodes_from(inside)
        for a, b in self.topo.undirected().edges():
            if a in inside and b in inside:
                g.add_edge(a, b)
        throats: dict[str, tuple[str, ...]] = {}
        for sig in self.st.model.signals:
            if sig.kind is not SignalKind.home:
                continue
            entry = self.st.signal_entry_track(sig.id)
            if entry not in inside:
                continue
            comp = nx.node_connected_component(g, entry)
            turnouts = sorted({p.node for t in comp for p in self.st.track_ports[t] if p.leg is not None},
                              key=_turnout_key)
            throats[sig.id] = tuple(turnouts)
        return throats


def _turnout_key(t: str) -> tuple[int, str]:
    head = t.split("/")[0]
    return (int(head), t) if head.isdigit() else (10**6, t)


def _conflicts(routes: dict[str, Route]) -> None:
    by_section: dict[str, set[str]] = defaultdict(set)
    by_turnout: dict[tuple[str, TurnoutPosition], set[str]] = defaultdict(set)
    for r in routes.values():
        for s in r.all_sections:
            by_section[s].add(r.id)
        for rt in r.all_turnouts:
            by_turnout[(rt.id, rt.position)].add(r.id)
    # The first reason found for a pair wins, as with setdefault; the new partners of each route are added in bulk
    # (a hub has millions of conflicting pairs, so no Python-level work per pair and shared section).
    for sec, ids in by_section.items():
        why = f"section {sec}"
        for a in ids:
            c = routes[a].conflicts
            new = ids - c.keys()
            if new:
                c.update(dict.fromkeys(new, why))
    for r in routes.values():
        r.conflicts.pop(r.id, None)  # added with its own sections above
    for (t, pos), ids in by_turnout.items():
        other = TurnoutPosition.reverse if pos is TurnoutPosition.normal else TurnoutPosition.normal
        opposite = by_turnout.get((t, other))
        if not opposite:
            continue
        why = f"turnout {t} {pos.value}/{other.value}"
        for a in ids:
            c = routes[a].conflicts
            new = opposite - c.keys()
            if new:
                c.update(dict.fromkeys(new, why))
    trains: dict[Direction, set[str]] = {d: set() for d in Direction}
    for r in routes.values():
        if r.kind == "train":
            trains[r.direction].add(r.id)
    for r in routes.values():
        if r.kind != "train":
            continue
        against = trains[Direction.up if r.direction is Direction.down else Direction.down]
        r.opposing = tuple(sorted(o for o, why in r.conflicts.items() if o in against and why.startswith("section")))


def build_table(station: Station) -> InterlockingTable:
    """Derive the interlocking table; station-file overrides that name unknown routes raise StationError."""
    return _Builder(station).build()

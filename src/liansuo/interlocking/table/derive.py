"""Deriving the interlocking table from the topology: the routes between buttons, and for each its turnouts (route,
flank protection, driven), sections, fouling sections, approach sections, overlap, diamonds, and where a shunting
route runs on past its end. Flank protection, driven turnouts and fouling sections are :mod:`.flank`'s work, the
run-on :mod:`.runon`'s, the approach sections :mod:`.approach`'s, the enemy routes :mod:`.conflicts`'.
"""

from __future__ import annotations

from collections import defaultdict
from collections.abc import Sequence
from dataclasses import dataclass, replace
from itertools import pairwise

import networkx as nx

from liansuo.interlocking.aspects import possible_aspects
from liansuo.interlocking.table import approach
from liansuo.interlocking.table.conflicts import derive_conflicts
from liansuo.interlocking.table.flank import Flank, driven_turnouts
from liansuo.interlocking.table.overlap import profile_overlap
from liansuo.interlocking.table.route import KINDS, FoulingSection, InterlockingTable, Kind, Route, RouteTurnout, RunOn
from liansuo.interlocking.table.runon import RunOns
from liansuo.kit.source import Diagnostic, StationError
from liansuo.rules import RuleSet
from liansuo.stations.schema import Button, Direction, SectionRole, SignalKind, TurnoutPosition
from liansuo.stations.station import Station
from liansuo.stations.topology import Move, Path


@dataclass(frozen=True)
class _Overlap:
    sections: tuple[str, ...]
    turnouts: tuple[RouteTurnout, ...]
    release_s: float
    end: str | None  # its end button, where the file names one
    safety_line: str | None = None  # no overlap: a safety line isolates the track, its turnout lying towards it


class _Builder:
    def __init__(self, station: Station, rules: RuleSet) -> None:
        self.st = station
        self.rules = rules
        self.topo = station.topology
        self.flank = Flank(station, rules)
        self.run_ons = RunOns(station, self.flank)
        self.errors: list[Diagnostic] = []
        self.warnings: list[Diagnostic] = []  # design warnings: routes left out of the table, and why
        self._warned: set[tuple[str, str, Direction]] = set()
        self._overlaps: dict[tuple[str, str], list[_Overlap]] = {}  # (home, end signal) -> from the profile
        self._own_overlaps: dict[str, list[_Overlap]] = {}  # end signal -> the station file's

    # ---- routes between buttons ------------------------------------------------------------------------------
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
        # depth-first over moves; each stack item is the list of moves so far, their length, and the station track
        # a train route has run on through (its section and the joint it left it by), where it has
        stack: list[tuple[list[Move], float, tuple[str, str] | None]] = [
            ([first], self.st.track_length(first[0]), None)]
        while stack:
            moves, length, through = stack.pop()
            last = moves[-1]
            node = self.topo.far_node(last)
            stop = False
            if kind == "train":
                end = self._train_end(node, d)
                if end is not None:
                    button, end_kind = end
                    if through is not None:
                        self._through_track(signal, button, *through, d)
                    else:
                        out.append((button, self._path(sig.at, d, moves), button if end_kind == "signal" else None))
                    stop = True
                elif through is None:
                    through = self._leaves_track(last, node)
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
                stack.append(([*moves, nxt], length + self.st.track_length(nxt[0]), through))
        return out

    def _leaves_track(self, last: Move, node: str) -> tuple[str, str] | None:
        """(station track, joint) where a train route runs on from a station track (股道) out into the throat past
        ``node``, no train signal of its direction standing there."""
        st = self.st
        track = st.tracks[last[0]].section
        if node not in st.joints or not st.is_station_track(track):
            return None
        beyond = st.tracks[st.entry_track(node, last[1])].section
        return None if st.is_station_track(beyond) else (track, node)  # a station track in two sections: on

    def _through_track(self, signal: str, end: str, track: str, joint: str, d: Direction) -> None:
        """A train route from ``signal`` to ``end`` that runs on through station track ``track`` past ``joint``,
        where no train signal of its direction stands: no such route exists in a real table (it would receive and
        depart in one, or run out onto a line against its direction), so it is left out, with a design warning."""
        key = (track, joint, d)
        if key in self._warned:
            return
        self._warned.add(key)
        st = self.st
        k = next(i for i, sec in enumerate(st.model.sections) if sec.id == track)
        self._warn(("sections", k, "id"), f"station track {track} has no {d.value} train signal at {joint}: the "
                   f"path from {signal} to {end} would run on through it as one train route (receiving and departing "
                   "in one); it is left out of the table",
                   f"add the {d.value} starting signal at {joint}, or leave it out on purpose")

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

    # ---- one row ----------------------------------------------------------------------------------------------
    def _add(self, routes: dict[str, Route], start: str, kind: Kind, end: str, via: tuple[str, ...], path: Path,
             end_signal: str | None) -> None:
        st = self.st
        rid = f"{start}-{end}" + (f"({','.join(via)})" if via else "")
        same = routes.get(rid)
        if kind == "shunt" and same is not None and same.kind == "train":
            rid = f"{rid}/D"
        turnouts = [RouteTurnout(t, p, "route") for t, p in path.turnouts]
        in_route = {t.id for t in turnouts}
        driven = driven_turnouts(self.st, [t.id for t in turnouts], dict(path.turnouts), set())
        prot, fouling = self.flank.of(path.tracks, path.turnouts, in_route | set(driven))
        extra = [RouteTurnout(t, p, "driven") for t, p in driven.items()]
        extra += [RouteTurnout(t, p, "protection") for t, p in prot.items()]
        sig = st.signals[start]
        end_node = path.end
        beyond = st.tracks[st.entry_track(end_node, path.direction)].section if end_node in st.joints else None
        exit_link = self._link_beyond(end_node, path.direction) if kind == "train" and end_signal is None else None
        line = self._line_beyond(end_node, path.direction) if kind == "train" and end_signal is None \
            and exit_link is None else ()
        if kind == "train":
            category = "departure" if end_signal is None else (
                "receiving" if sig.kind is SignalKind.home else "transfer")
        else:
            category = "shunting"
        overlaps = self._overlap(start, end_signal) if kind == "train" and category == "receiving" else (
            self._file_overlaps(end_signal) if kind == "train" else [])
        isolating = next((o for o in overlaps if o.safety_line), None)
        if isolating is not None:  # a safety line at the end of the track: its turnout lies towards it
            overlaps = []
            guard = {t.id: t for t in isolating.turnouts if t.id not in in_route and t.id not in driven}
            extra = [t for t in extra if t.id not in guard] + list(guard.values())
        basic = overlaps[0] if overlaps else _Overlap((), (), 0.0, None)
        leads_into: str | None = None
        run_on: tuple[RunOn, ...] = ()
        if kind == "shunt" and end_signal is None and end not in st.buttons:
            leads_into, run_on = self.run_ons.of(end_node, path.direction, path.tracks,
                                               in_route | set(driven) | set(prot))
        diamonds = tuple(sorted({d for t in path.tracks for d, _ in st.crossings.get(t, ())}))
        routes[rid] = Route(
            id=rid, kind=kind, category=category, start=start, end=end, via=via, signal=start,
            direction=path.direction, path=path, turnouts=tuple(turnouts + extra), sections=path.sections,
            fouling=tuple({f.section: f for f in reversed(fouling) if f.section not in path.sections}.values())[::-1],
            approach=approach.sections(st, self.rules, start), end_node=end_node, end_signal=end_signal, beyond=beyond,
            exit_link=exit_link, line_sections=line,
            overlap_sections=basic.sections, overlap_turnouts=basic.turnouts, overlap_release_s=basic.release_s,
            overlap_end=basic.end, diamonds=diamonds, leads_into=leads_into, run_on=run_on,
            safety_line=isolating.safety_line if isolating else None,
        )
        for alt in overlaps[1:]:  # alternative overlaps (变更延续进路): the same route, another overlap
            routes[f"{rid}+{alt.end}"] = replace(
                routes[rid], id=f"{rid}+{alt.end}", overlap_sections=alt.sections, overlap_turnouts=alt.turnouts,
                overlap_release_s=alt.release_s, overlap_end=alt.end, overlap_alternative=True,
                conflicts={}, conditional={}, head_on={}, added_enemies=set())

    def _overlap(self, home: str, end_signal: str | None) -> list[_Overlap]:
        """What a receiving route from ``home`` needs beyond ``end_signal``, the basic overlap first: the station
        file's own overlaps, else what the approach gradient outside the home signal calls for (an overlap, or the
        turnout of a safety line: :mod:`.overlap`), else nothing."""
        own = self._file_overlaps(end_signal)
        if own or end_signal is None:
            return own
        key = (home, end_signal)
        if key not in self._overlaps:
            found = profile_overlap(self.st, home, end_signal, self.rules)
            if found is None:
                self._overlaps[key] = []
            elif found.safety_line is not None:
                self._overlaps[key] = [_Overlap((), tuple(RouteTurnout(t, p, "protection") for t, p in found.turnouts),
                                                0.0, None, found.safety_line)]
            else:
                self._overlaps[key] = [_Overlap(found.sections, self._overlap_turnouts(found.turnouts),
                                                self.rules.overlap_release_s, None)]
        return self._overlaps[key]

    def _file_overlaps(self, end_signal: str | None) -> list[_Overlap]:
        """The station file's own overlaps beyond ``end_signal`` (alternatives after the basic one)."""
        if end_signal is None:
            return []
        if end_signal not in self._own_overlaps:
            self._own_overlaps[end_signal] = [
                _Overlap(tuple(o.sections), self._overlap_turnouts([(t.turnout, t.position) for t in o.turnouts]),
                         self.rules.overlap_release_s if o.release_s is None else o.release_s, o.end)
                for o in self.st.model.overlaps if o.end_signal == end_signal]
        return self._own_overlaps[end_signal]

    def _overlap_turnouts(self, turnouts: Sequence[tuple[str, TurnoutPosition]]) -> tuple[RouteTurnout, ...]:
        """An overlap's turnouts with the crossover partners and driven turnouts they take along."""
        lie = dict(turnouts)
        lie.update(driven_turnouts(self.st, [t for t, _ in turnouts], lie, set()))
        return tuple(RouteTurnout(t, p, "route") for t, p in lie.items())

    def _link_beyond(self, node: str, d: Direction) -> str | None:
        """The block link reached by going on from ``node`` in direction ``d`` without passing a turnout (or the
        link at ``node`` itself, where a route ends at the boundary)."""
        at_end = next((lk.id for lk in self.st.model.links if lk.end == node), None)
        if at_end is not None:
            return at_end
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

    def _line_beyond(self, node: str, d: Direction) -> tuple[str, ...]:
        """The sections a departure runs onto past ``node`` where the file describes no block: on to the end of the
        line, or to the next signal of its direction, without passing a turnout. The departure checks them clear,
        since nothing else does."""
        if node not in self.st.joints:
            return ()
        track: str | None = self.st.entry_track(node, d)
        out: list[str] = []
        while track is not None and len(out) < 50:
            sec = self.st.tracks[track].section
            if sec not in out:
                out.append(sec)
            far = self.topo.far_node((track, d))
            if far in self.st.ends or far not in self.st.joints:
                return tuple(out) if far in self.st.ends else ()
            if any(s.direction is d for s in self.st.signals_at(far)):
                break
            track = self.st.entry_track(far, d)
        return tuple(out)

    # ---- the whole table ------------------------------------------------------------------------------------
    def build(self) -> InterlockingTable:
        routes: dict[str, Route] = {}
        unselectable: list[str] = []
        for sig in self.st.model.signals:
            for kind in KINDS:
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
                    self._add(routes, sig.id, kind, end, (), basic[0], basic[1])
                    for path, end_signal in paths[1:]:
                        via = self._via(path, basic[0])
                        if via is None:
                            unselectable.append(f"{sig.id}-{end} via {'/'.join(t for t, _ in path.turnouts)}")
                            continue
                        self._add(routes, sig.id, kind, end, (via,), path, end_signal)
        self._apply_overrides(routes)
        self._add_fouling(routes)
        if self.errors:
            raise StationError(self.errors)
        derive_conflicts(routes, self.rules, self.st.is_station_track)
        self._add_enemies(routes)
        if self.errors:
            raise StationError(self.errors)
        onward: dict[str, list[Route]] = defaultdict(list)
        for r in routes.values():
            if r.kind == "train":
                onward[r.signal].append(r)
        listed: dict[str, tuple[str, ...]] = {}

        def aspects_of(r: Route, through: frozenset[str] = frozenset()) -> tuple[str, ...]:
            if r.id not in listed:
                if r.id in through:  # a ring of train routes (none in one direction, but never loop)
                    return ("L", "LU", "U")
                listed[r.id] = possible_aspects(self.st, r, self.rules, onward.get(r.end_signal or "", ()),
                                                lambda o: aspects_of(o, through | {r.id}))
            return listed[r.id]

        for r in routes.values():
            r.aspects = aspects_of(r)
        return InterlockingTable(self.st, routes, self._throats(), unselectable, self.warnings)

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

    def _apply_overrides(self, routes: dict[str, Route]) -> None:
        ov = self.st.model.overrides
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

    def _add_fouling(self, routes: dict[str, Route]) -> None:
        """The station file's added track conditions (``overrides.fouling``): sections a route must find clear."""
        for k, f in enumerate(self.st.model.overrides.fouling):
            r = routes.get(f.route)
            if r is None:
                self._err(("overrides", "fouling", k, "route"), f"override names route '{f.route}', which does not "
                          "exist", f"routes are named START-END; see 'liansuo table {self.st.id}'")
            elif f.section in r.sections or any(x.section == f.section for x in r.fouling):
                self._err(("overrides", "fouling", k, "section"), f"route {r.id} already checks section "
                          f"{f.section}", "remove this entry; the table derives it")
            else:
                r.fouling = (*r.fouling, FoulingSection(f.section))

    def _add_enemies(self, routes: dict[str, Route]) -> None:
        """The station file's added enemies (``overrides.enemies``), both ways, after the derived ones."""
        for k, e in enumerate(self.st.model.overrides.enemies):
            missing = [(key, rid) for key, rid in (("route", e.route), ("enemy", e.enemy)) if rid not in routes]
            for key, rid in missing:
                self._err(("overrides", "enemies", k, key), f"added enemy names route '{rid}', which does not exist",
                          f"routes are named START-END; see 'liansuo table {self.st.id}'")
            if missing:
                continue
            if e.route == e.enemy:
                self._err(("overrides", "enemies", k, "enemy"), f"route {e.route} is named as its own enemy",
                          "name two different routes")
                continue
            a, b = routes[e.route], routes[e.enemy]
            if b.id in a.conflicts:
                self._err(("overrides", "enemies", k, "enemy"), f"routes {a.id} and {b.id} are already enemies "
                          f"({a.conflicts[b.id]})", "remove this entry; the table derives it")
                continue
            why = f"added in the station file: {e.why}"
            a.conflicts[b.id] = b.conflicts[a.id] = why
            a.added_enemies.add(b.id)
            b.added_enemies.add(a.id)
            a.conditional.pop(b.id, None)
            b.conditional.pop(a.id, None)

    def _warn(self, loc: tuple[str | int, ...], msg: str, hint: str) -> None:
        if self.st.source is not None:
            d = self.st.source.diagnostic(loc, msg, hint)
            self.warnings.append(Diagnostic(d.file, d.line, d.column, msg, hint, "warning"))
        else:
            self.warnings.append(Diagnostic("<station>", 1, 1, msg, hint, "warning"))

    def _err(self, loc: tuple[str | int, ...], msg: str, hint: str) -> None:
        if self.st.source is not None:
            self.errors.append(self.st.source.diagnostic(loc, msg, hint))
        else:
            self.errors.append(Diagnostic("<station>", 1, 1, msg, hint))

    def _throats(self) -> dict[str, tuple[str, ...]]:
        """Turnouts of each throat, named by the home signals that lead into it."""
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


def derive_table(station: Station, rules: RuleSet) -> InterlockingTable:
    return _Builder(station, rules).build()

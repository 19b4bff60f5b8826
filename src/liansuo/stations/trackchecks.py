"""The cross-checks of a station file's tracks (:mod:`.checks` runs them first): unique ids, ports that resolve,
consistent geometry, sections bounded by joints or ends, turnout pairs, drives, fouling points, diamonds and scissors,
and a connected network. Each problem becomes a diagnostic at the offending key."""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterator, Sequence
from functools import cached_property
from itertools import pairwise

import networkx as nx

from liansuo.kit.fit import metres, number
from liansuo.kit.source import Diagnostic, Loc, Source
from liansuo.stations import limits
from liansuo.stations.crossovers import undeclared_crossings
from liansuo.stations.schema import (
    CircuitType,
    SectionRole,
    StationFile,
)
from liansuo.stations.station import LEGS, Port, Station, parse_port


class TrackChecks:
    """The checks of one station file's tracks; ``errors`` collects their diagnostics."""

    node_positions: dict[str, float]  # node id -> position, once the ids are known to be unique

    def __init__(self, model: StationFile, src: Source) -> None:
        self.m = model
        self.src = src
        self.errors: list[Diagnostic] = []

    def err(self, loc: Loc, message: str, hint: str = "") -> None:
        self.errors.append(self.src.diagnostic(loc, message, hint))

    def unique_ids(self) -> None:
        groups: list[tuple[str, Sequence[object], str]] = [
            ("ends", self.m.ends, "node"), ("joints", self.m.joints, "node"), ("turnouts", self.m.turnouts, "node"),
            ("tracks", self.m.tracks, "track"), ("sections", self.m.sections, "section"),
            ("signals", self.m.signals, "button"), ("buttons", self.m.buttons, "button"),
            ("fouling_points", self.m.fouling_points, "fouling"), ("platforms", self.m.platforms, "platform"),
            ("markers", self.m.markers, "marker"), ("diamonds", self.m.diamonds, "diamond"),
            ("links", self.m.links, "link"),
        ]
        seen: dict[tuple[str, str], str] = {}
        for key, items, space in groups:
            for i, item in enumerate(items):
                ident = item.id  # type: ignore[attr-defined]
                if (space, ident) in seen:
                    self.err((key, i, "id"), f"id '{ident}' is already used by {seen[(space, ident)]}",
                             "every end, joint and turnout needs its own id, and so does every signal and button")
                else:
                    seen[(space, ident)] = f"{key[:-1]} '{ident}'"

    def ports_resolve(self) -> None:
        turnouts = {t.id for t in self.m.turnouts}
        plain = {e.id for e in self.m.ends} | {j.id for j in self.m.joints}
        for i, t in enumerate(self.m.tracks):
            for key, ref in (("from", t.start), ("to", t.end)):
                p = parse_port(ref)
                if p.leg is not None and p.node in turnouts:
                    continue
                if p.leg is None and p.node in plain:
                    continue
                if p.node in turnouts or ref in turnouts:
                    self.err(("tracks", i, key), f"track '{t.id}' attaches to turnout '{p.node}' without naming a leg",
                             f"write '{p.node}.point', '{p.node}.normal' or '{p.node}.reverse'")
                else:
                    self.err(("tracks", i, key), f"track '{t.id}' {key} '{ref}' is not an end, joint or turnout leg",
                             "declare it under 'ends:', 'joints:' or 'turnouts:', or fix the spelling")
            if t.start == t.end:
                self.err(("tracks", i, "to"), f"track '{t.id}' starts and ends at the same place",
                         "a track runs between two different nodes; check 'from' and 'to'")

    def _track_ports(self) -> Iterator[tuple[int, str, Port, Port]]:
        for i, t in enumerate(self.m.tracks):
            yield i, t.id, parse_port(t.start), parse_port(t.end)

    def node_usage(self) -> None:
        use: dict[tuple[str, str | None], list[tuple[int, str]]] = {}
        for i, _, a, b in self._track_ports():
            use.setdefault((a.node, a.leg), []).append((i, "from"))
            use.setdefault((b.node, b.leg), []).append((i, "to"))
        for k, e in enumerate(self.m.ends):
            n = len(use.get((e.id, None), []))
            if n != 1:
                self.err(("ends", k, "id"), f"end '{e.id}' has {n} tracks attached; an end takes exactly one",
                         "connect exactly one track to a buffer stop or boundary")
        for k, j in enumerate(self.m.joints):
            n = len(use.get((j.id, None), []))
            if n != 2:
                self.err(("joints", k, "id"), f"joint '{j.id}' has {n} tracks attached; a joint joins exactly two",
                         "a joint sits between the last track of one section and the first of the next")
        for k, t in enumerate(self.m.turnouts):
            for leg in LEGS:
                n = len(use.get((t.id, leg), []))
                if n != 1:
                    self.err(("turnouts", k, "id"),
                             f"turnout {t.id}: its {leg} leg has {n} tracks attached; each leg takes exactly one",
                             f"connect one track 'from' or 'to' '{t.id}.{leg}'")

    def geometry(self) -> None:
        pos = self.node_positions
        for i, tid, a, b in self._track_ports():
            if pos[a.node] == pos[b.node]:
                self.err(("tracks", i), f"track '{tid}' has both ends at position {metres(pos[a.node])}",
                         "positions increase in the down direction; the two ends of a track must differ")
        if self.errors:
            return
        other: dict[tuple[str, str | None], float] = {}
        for _, _, a, b in self._track_ports():
            other[(a.node, a.leg)] = pos[b.node]
            other[(b.node, b.leg)] = pos[a.node]
        for k, t in enumerate(self.m.turnouts):
            side = {leg: other[(t.id, leg)] > t.at for leg in LEGS}
            if side["normal"] != side["reverse"]:
                self.err(("turnouts", k, "at"),
                         f"turnout {t.id}: its normal and reverse legs leave on opposite sides of {metres(t.at)}",
                         "both legs leave on the side away from the point; check the positions of their tracks")
            elif side["point"] == side["normal"]:
                self.err(("turnouts", k, "at"),
                         f"turnout {t.id}: the point leg leaves on the same side as the normal and reverse legs",
                         "the point leg goes one way from the turnout, the normal and reverse legs the other")
        far_ends: dict[str, list[float]] = {}  # node -> positions of the far ends of its tracks
        for _, _, a, b in self._track_ports():
            far_ends.setdefault(a.node, []).append(pos[b.node])
            if b.node != a.node:
                far_ends.setdefault(b.node, []).append(pos[a.node])
        for k, j in enumerate(self.m.joints):
            sides = {p > j.at for p in far_ends.get(j.id, [])}
            if len(sides) != 2:
                self.err(("joints", k, "at"), f"joint '{j.id}': both its tracks leave on the same side of "
                                              f"{metres(j.at)}",
                         "a joint lies between its two tracks; check the positions")
            if j.at2 is not None and abs(j.at2 - j.at) > limits.DEAD_ZONE.high:
                self.err(("joints", k, "at2"),
                         f"joint '{j.id}': the two rail joints are {metres(abs(j.at2 - j.at))} apart (at most "
                         f"{metres(limits.DEAD_ZONE.high)})",
                         "'at2' is the second rail's joint, normally within a few metres of 'at'")
        self.extent()

    def extent(self) -> None:
        """The station lies within :data:`limits.EXTENT`: the models solve each section as one line, and the console
        draws the whole station."""
        nodes = [("ends", k, e.at) for k, e in enumerate(self.m.ends)]
        nodes += [("joints", k, j.at) for k, j in enumerate(self.m.joints)]
        nodes += [("turnouts", k, t.at) for k, t in enumerate(self.m.turnouts)]
        low = min(nodes, key=lambda n: n[2])
        high = max(nodes, key=lambda n: n[2])
        if high[2] - low[2] > limits.EXTENT.high:
            name = getattr(self.m, high[0])[high[1]].id
            lowest = getattr(self.m, low[0])[low[1]].id
            self.err((high[0], high[1], "at"), f"the station spans {metres(high[2] - low[2])}, from '{lowest}' at "
                     f"{metres(low[2])} to '{name}' at {metres(high[2])}; {limits.EXTENT.what} is at most "
                     f"{metres(limits.EXTENT.high)}", "check the position: a kilometre post written as metres, or a "
                     "digit too many")

    def sections(self) -> None:
        known = {s.id for s in self.m.sections}
        used: Counter[str] = Counter()
        for i, t in enumerate(self.m.tracks):
            if t.section not in known:
                self.err(("tracks", i, "section"), f"track '{t.id}' is in section '{t.section}', which is not declared",
                         "add it under 'sections:' with its type (25hz, zpw2000a or axle_counter)")
            used[t.section] += 1
        for k, s in enumerate(self.m.sections):
            if used[s.id] == 0:
                self.err(("sections", k, "id"), f"section '{s.id}' has no tracks",
                         "give at least one track 'section: " + s.id + "', or remove the section")
            if s.type is CircuitType.zpw2000a and s.carrier is None:
                self.err(("sections", k, "type"), f"ZPW-2000A section '{s.id}' has no carrier",
                         "add e.g. 'carrier: 2300-1' (down line 1700/2300, up line 2000/2600)")
            if s.safety_line and s.role is not SectionRole.spur:
                self.err(("sections", k, "safety_line"), f"section '{s.id}' is a safety line but its role is "
                         f"{s.role.value}", "a safety line (安全线) is a spur: give it 'role: spur'")
            if s.type is not CircuitType.zpw2000a and s.carrier is not None:
                self.err(("sections", k, "carrier"), f"section '{s.id}' ({s.type.value}) cannot have a ZPW-2000A "
                         "carrier", "remove 'carrier', or make the section 'type: zpw2000a'")
            caps = s.capacitors
            if caps is not None and sum(x is not None for x in (caps.count, caps.positions, caps.rule)) != 1:
                self.err(("sections", k, "capacitors"), f"section '{s.id}': give exactly one of count, positions, rule",
                         "e.g. 'capacitors: {rule: standard}'")
            if s.line_class is not None and s.type is not CircuitType.zpw2000a:
                self.err(("sections", k, "line_class"),
                         f"section '{s.id}' ({s.type.value}): a line class belongs to ZPW-2000A sections",
                         "remove 'line_class', or make the section 'type: zpw2000a'")
            if caps is not None and s.type is not CircuitType.zpw2000a:
                self.err(("sections", k, "capacitors"),
                         f"section '{s.id}': compensation capacitors belong to ZPW-2000A sections",
                         "remove 'capacitors', or make the section 'type: zpw2000a'")
        if self.errors:
            return
        self.zpw_lengths()
        # sections are bounded by joints or ends: tracks meeting at a turnout share a section, tracks meeting at a
        # joint do not, and the tracks of a section are connected through turnouts.
        by_node: dict[str, list[tuple[int, str]]] = {}
        for i, _, a, b in self._track_ports():
            by_node.setdefault(a.node, []).append((i, "from"))
            by_node.setdefault(b.node, []).append((i, "to"))
        joints = {j.id for j in self.m.joints}
        turnouts = {t.id for t in self.m.turnouts}
        g = nx.Graph()
        for t in self.m.tracks:
            g.add_node(t.id)
        counted = {sec.id for sec in self.m.sections if sec.type is CircuitType.axle_counter}
        for k, j in enumerate(self.m.joints):
            beside = sorted({self.m.tracks[i].section for i, _ in by_node.get(j.id, ())} & counted)
            if beside and (j.at2 is not None or j.dead_zone_m):
                self.err(("joints", k, "at2" if j.at2 is not None else "dead_zone_m"),
                         f"joint '{j.id}' borders axle-counter section '{beside[0]}' but has a dead zone",
                         "an axle counter counts at a point and has no dead zone: remove 'at2' / 'dead_zone_m'")
        for node, items in by_node.items():
            secs = {self.m.tracks[i].section for i, _ in items}
            if node in joints and len(items) == 2 and len(secs) == 1:
                i, key = items[1]
                self.err(("tracks", i, key), f"joint '{node}' has section '{secs.pop()}' on both sides",
                         "a joint separates two sections; put the tracks in different sections or remove the joint")
            if node in turnouts:
                if len(secs) > 1:
                    i, key = items[0]
                    self.err(("tracks", i, key),
                             f"turnout {node} has tracks of different sections ({', '.join(sorted(secs))}) on its legs",
                             "a turnout lies inside one section: put its three leg tracks in the same section, "
                             "or place joints between them")
                for a_, b_ in pairwise(items):
                    g.add_edge(self.m.tracks[a_[0]].id, self.m.tracks[b_[0]].id)
        section_tracks: dict[str, list[str]] = {}
        for t in self.m.tracks:
            section_tracks.setdefault(t.section, []).append(t.id)
        # the two tracks of a diamond crossing may share one section: the crossing's track circuit covers both
        g.add_edges_from(d.tracks for d in self.m.diamonds if all(g.has_node(t) for t in d.tracks))
        for k, s in enumerate(self.m.sections):
            tracks = section_tracks.get(s.id, [])
            if len(tracks) > 1 and not nx.is_connected(g.subgraph(tracks)):
                self.err(("sections", k, "id"),
                         f"section '{s.id}' is in pieces: its tracks ({', '.join(tracks)}) are not joined through "
                         "turnouts or a diamond", "each section is one stretch bounded by joints or ends; split it "
                         "in two ids")

    def zpw_lengths(self) -> None:
        """A ZPW-2000A section is no longer than :data:`limits.ZPW_SECTION`, and its explicit capacitor positions lie
        within it: from its lower end to the nearer of its far end and the sum of its tracks' lengths (a track's own
        ``length`` may make that shorter; the models place the capacitors on whichever they solve)."""
        pos = self.node_positions
        span: dict[str, tuple[float, float]] = {}
        total: dict[str, float] = {}
        for i, _, a, b in self._track_ports():
            t = self.m.tracks[i]
            lo, hi = sorted((pos[a.node], pos[b.node]))
            was = span.get(t.section, (lo, hi))
            span[t.section] = (min(was[0], lo), max(was[1], hi))
            total[t.section] = total.get(t.section, 0.0) + (t.length if t.length is not None else hi - lo)
        for k, s in enumerate(self.m.sections):
            if s.type is not CircuitType.zpw2000a or s.id not in span:
                continue
            run = span[s.id][1] - span[s.id][0]
            longest = max(run, total[s.id])
            if longest > limits.ZPW_SECTION.high:
                self.err(("sections", k, "id"), f"ZPW-2000A section '{s.id}' is {metres(longest)} long; "
                         f"{limits.ZPW_SECTION.what} is at most {metres(limits.ZPW_SECTION.high)}",
                         "split it with electrical joints (tuning areas), as a real line is")
                continue
            reach = min(run, total[s.id])
            caps = s.capacitors
            for m, x in enumerate(caps.positions or [] if caps is not None else []):
                if x > reach:
                    self.err(("sections", k, "capacitors", "positions", m),
                             f"section '{s.id}': capacitor {m + 1} at {metres(x)} lies beyond the section, which "
                             f"runs {metres(reach)} from its lower end", "capacitor positions are metres from the "
                             "section's lower (X-end) end, within the section")

    def pairs(self) -> None:
        members: dict[str, list[int]] = {}
        for k, t in enumerate(self.m.turnouts):
            if t.pair:
                members.setdefault(t.pair, []).append(k)
        for pair, ks in members.items():
            if len(ks) != 2:
                self.err(("turnouts", ks[0], "pair"), f"crossover pair '{pair}' has {len(ks)} turnout(s), not 2",
                         "a pair ('1/3') is exactly two turnouts moved by one command")
                continue
            a, b = (self.m.turnouts[k].id for k in ks)
            if not self._reverse_legs_meet(a, b):
                self.err(("turnouts", ks[1], "pair"),
                         f"turnouts {a} and {b} form pair '{pair}' but their reverse legs are not joined",
                         "a crossover pair's reverse legs are connected by the crossover track (through joints only)")

    def drives(self) -> None:
        """A driven turnout (``drives``) is another declared turnout, not the crossover partner (that one moves
        anyway), named once per position of the turnout that drives it."""
        turnouts = {t.id: t for t in self.m.turnouts}
        for k, t in enumerate(self.m.turnouts):
            seen: set[tuple[str, str]] = set()
            for m, d in enumerate(t.drives):
                loc: Loc = ("turnouts", k, "drives", m, "turnout")
                other = turnouts.get(d.turnout)
                if other is None:
                    self.err(loc, f"turnout {t.id} drives unknown turnout '{d.turnout}'",
                             "name a turnout listed under 'turnouts:'")
                elif d.turnout == t.id:
                    self.err(loc, f"turnout {t.id} drives itself", "name another turnout")
                elif t.pair is not None and other.pair == t.pair:
                    self.err(loc, f"turnout {d.turnout} is the crossover partner of {t.id} ({t.pair}); it moves "
                             "with it anyway", "remove this entry: only a turnout outside the pair is driven")
                elif (d.turnout, d.when) in seen:
                    self.err(loc, f"turnout {t.id} drives {d.turnout} twice when {d.when}", "keep one entry")
                seen.add((d.turnout, d.when))

    def _reverse_legs_meet(self, a: str, b: str) -> bool:
        # walk from a.reverse through tracks and joints only
        ports, at_port = self._ports
        at = Port(a, "reverse")
        seen = set()
        while True:
            track = next((tid for tid in at_port.get(at, ()) if tid not in seen), None)
            if track is None:
                return False
            seen.add(track)
            p, q = ports[track]
            far = q if p == at else p
            if far == Port(b, "reverse"):
                return True
            if far.leg is not None or far.node not in self._joint_ids:
                return False
            at = far

    @cached_property
    def _ports(self) -> tuple[dict[str, tuple[Port, Port]], dict[Port, list[str]]]:
        """Each track's two ports, and the tracks at each port: looked up, not searched, so that the checks take
        time in proportion to the station's size."""
        ports = {t.id: (parse_port(t.start), parse_port(t.end)) for t in self.m.tracks}
        at_port: dict[Port, list[str]] = {}
        for tid, (p, q) in ports.items():
            at_port.setdefault(p, []).append(tid)
            if q != p:
                at_port.setdefault(q, []).append(tid)
        return ports, at_port

    @cached_property
    def _joint_ids(self) -> set[str]:
        return {j.id for j in self.m.joints}

    def fouling_points(self) -> None:
        tracks = {t.id: t for t in self.m.tracks}
        turnouts = {t.id for t in self.m.turnouts}
        station: Station | None = None
        for k, f in enumerate(self.m.fouling_points):
            short, tied = f.track is not None, f.turnout is not None or f.tracks is not None
            if short == tied:
                self.err(("fouling_points", k), f"fouling point {f.id} needs either 'turnout' and 'tracks' or the "
                         "short form 'track'" + (", not both" if short else ""),
                         "write {id: FP1, turnout: '1', tracks: [NORMAL_SIDE, REVERSE_SIDE], at: POSITION}")
                continue
            if tied and (f.turnout is None or f.tracks is None):
                missing = "tracks" if f.tracks is None else "turnout"
                self.err(("fouling_points", k), f"fouling point {f.id} names its "
                         f"{'turnout' if missing == 'tracks' else 'tracks'} but not its {missing}",
                         "a fouling point stands between two tracks that part at one turnout: give both")
                continue
            named = [f.track] if f.track is not None else list(f.tracks or [])
            unknown = [m for m, t in enumerate(named) if t not in tracks]
            for m in unknown:
                self.err(("fouling_points", k, "track") if short else ("fouling_points", k, "tracks", m),
                         f"fouling point {f.id} is on unknown track '{named[m]}'", "name a track id listed under "
                         "'tracks:'")
            if f.turnout is not None and f.turnout not in turnouts:
                self.err(("fouling_points", k, "turnout"), f"fouling point {f.id} names unknown turnout "
                         f"'{f.turnout}'", "name a turnout listed under 'turnouts:'")
                continue
            if unknown:
                continue
            for tid in named:
                t = tracks[tid]
                xa = self.node_positions[parse_port(t.start).node]
                xb = self.node_positions[parse_port(t.end).node]
                if not min(xa, xb) <= f.at <= max(xa, xb):
                    self.err(("fouling_points", k, "at"),
                             f"fouling point {f.id} at {metres(f.at)} is off track '{t.id}' "
                             f"({number(min(xa, xb))}-{metres(max(xa, xb))})",
                             "a fouling point lies beside its tracks, between each track's two ends")
                    break
            else:
                if tied:
                    station = station or Station(self.m)
                    for m, (leg, chain) in enumerate(station.fouling_legs(f).items()):
                        if not chain:
                            self.err(("fouling_points", k, "tracks", m),
                                     f"fouling point {f.id}: track '{named[m]}' is not reached from the {leg} leg of "
                                     f"turnout {f.turnout} (across joints only)",
                                     "list first the track on the normal side, then the one on the reverse side")

    def diamonds(self) -> None:
        tracks = {t.id: t for t in self.m.tracks}
        for k, d in enumerate(self.m.diamonds):
            bad = [m for m, tid in enumerate(d.tracks) if tid not in tracks]
            for m in bad:
                self.err(("diamonds", k, "tracks", m), f"diamond {d.id} names unknown track '{d.tracks[m]}'",
                         "name the two tracks that cross, as listed under 'tracks:'")
            if bad:
                continue
            a, b = (tracks[tid] for tid in d.tracks)
            if a.id == b.id:
                self.err(("diamonds", k, "tracks"), f"diamond {d.id} crosses track '{a.id}' with itself",
                         "a diamond is two different tracks crossing")
                continue
            nodes_a = {parse_port(a.start).node, parse_port(a.end).node}
            nodes_b = {parse_port(b.start).node, parse_port(b.end).node}
            if nodes_a & nodes_b:
                self.err(("diamonds", k, "tracks"), f"diamond {d.id}: tracks {a.id} and {b.id} meet at "
                         f"'{sorted(nodes_a & nodes_b)[0]}', so they do not cross",
                         "a diamond joins two tracks that cross without any node in common")
                continue
            spans = []
            for t in (a, b):
                xa = self.node_positions[parse_port(t.start).node]
                xb = self.node_positions[parse_port(t.end).node]
                spans.append((min(xa, xb), max(xa, xb)))
            lo, hi = max(spans[0][0], spans[1][0]), min(spans[0][1], spans[1][1])
            if lo > hi:
                self.err(("diamonds", k, "tracks"), f"diamond {d.id}: tracks {a.id} ({number(spans[0][0])}-"
                         f"{metres(spans[0][1])}) and {b.id} ({number(spans[1][0])}-{metres(spans[1][1])}) do not "
                         "overlap along the line, so they cannot cross", "name two tracks that pass the same point")
            elif d.at is not None and not lo <= d.at <= hi:
                self.err(("diamonds", k, "at"), f"diamond {d.id} at {metres(d.at)} is not on both tracks (they run "
                         f"side by side from {number(lo)} to {metres(hi)})", "give the point where the two tracks "
                         "cross")
        if not self.errors:
            self.scissors()

    def scissors(self) -> None:
        """Two crossover pairs whose diagonals cross (a scissors crossover, 交叉渡线) need their diamond declared:
        without it nothing would keep the other pair away from a route over one diagonal."""
        for c in undeclared_crossings(self.m):
            self.err(("turnouts", c.turnout_index, "pair"),
                     f"crossover pairs {c.pairs[0]} and {c.pairs[1]} cross each other (a scissors crossover, "
                     f"交叉渡线): their diagonals {c.tracks[0]} and {c.tracks[1]} meet near {metres(c.at)}, and no "
                     "diamond is declared there, so nothing would protect the crossing",
                     f"declare it: 'diamonds: [{{id: XD, tracks: [{c.tracks[0]}, {c.tracks[1]}], "
                     f"at: {number(c.at)}}}]'")

    def connected(self) -> None:
        g = nx.Graph()
        for _, tid, a, b in self._track_ports():
            g.add_edge(("n", a.node), ("t", tid))
            g.add_edge(("t", tid), ("n", b.node))
        if not nx.is_connected(g):
            parts = sorted(nx.connected_components(g), key=len, reverse=True)
            stray = sorted(x[1] for x in parts[1] if x[0] == "t")
            i = next(i for i, t in enumerate(self.m.tracks) if t.id == stray[0])
            self.err(("tracks", i), f"the network is in {len(parts)} pieces; tracks {', '.join(stray)} are cut off "
                     "from the rest", "connect them through a joint or turnout, or remove them")

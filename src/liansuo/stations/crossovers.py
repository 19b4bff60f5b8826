"""Crossovers that cross each other: the two diagonals of a scissors crossover (交叉渡线), found from the geometry.

A crossover pair (双动道岔) joins two lines by a diagonal from the reverse leg of one turnout to the reverse leg of
the other. Two diagonals between the same two lines whose spans along the line overlap, and which leave the lower
end from different lines, must cross: one runs from line A to line B, the other from B to A, over the same stretch.
Where they cross there is a diamond (菱形交叉), and a route over one diagonal must keep the other pair away from it;
a station file that leaves that diamond out would leave the crossing unprotected, so the cross-checks refuse it and
name the diamond to declare.

A line here is what the turnouts' point and normal legs join (through joints): the straight roads. Two lines that
themselves cross at a declared diamond (the straight roads of a double slip) are not parallel, and their slip roads
do not cross each other.
"""

from __future__ import annotations

from dataclasses import dataclass
from itertools import combinations

import networkx as nx

from liansuo.stations.schema import StationFile
from liansuo.stations.station import Port, parse_port


@dataclass(frozen=True)
class Crossing:
    """Two crossover pairs whose diagonals cross with no diamond declared: where, and over which tracks."""

    pairs: tuple[str, str]
    tracks: tuple[str, str]  # the track of each diagonal at the crossing point
    at: float
    turnout_index: int  # the entry (in ``turnouts:``) of the second pair's first turnout, for the diagnostic


def undeclared_crossings(model: StationFile) -> list[Crossing]:
    """The crossover pairs of ``model`` whose diagonals cross without a declared diamond between them. The model
    has passed the geometry and pair checks (every pair has two turnouts whose reverse legs are joined)."""
    pos: dict[str, float] = {e.id: e.at for e in model.ends}
    pos.update({j.id: j.at for j in model.joints})
    pos.update({t.id: t.at for t in model.turnouts})
    ports = {t.id: (parse_port(t.start), parse_port(t.end)) for t in model.tracks}
    at_port: dict[Port, list[str]] = {}
    for tid, (p, q) in ports.items():
        at_port.setdefault(p, []).append(tid)
        at_port.setdefault(q, []).append(tid)
    joints = {j.id for j in model.joints}
    line = _lines(ports, joints)
    members: dict[str, list[int]] = {}
    for k, t in enumerate(model.turnouts):
        if t.pair:
            members.setdefault(t.pair, []).append(k)
    diagonals: dict[str, tuple[list[str], int, int, float, float, int]] = {}
    for pair, ks in members.items():
        if len(ks) != 2:
            continue
        a, b = (model.turnouts[k] for k in ks)
        tracks = _diagonal(a.id, b.id, ports, at_port, joints)
        if not tracks:
            continue
        low, high = (a, b) if a.at <= b.at else (b, a)
        ta, tb = at_port[Port(a.id, "point")][0], at_port[Port(b.id, "point")][0]
        lines = {a.id: line[ta], b.id: line[tb]}
        diagonals[pair] = (tracks, lines[low.id], lines[high.id], low.at, high.at, min(ks))
    declared = [(d.tracks[0], d.tracks[1]) for d in model.diamonds]
    out: list[Crossing] = []
    for p1, p2 in combinations(sorted(diagonals), 2):
        t1, lo1, hi1, x1, y1, _ = diagonals[p1]
        t2, lo2, hi2, x2, y2, k2 = diagonals[p2]
        if lo1 in (hi1, lo2) or {lo1, hi1} != {lo2, hi2}:
            continue  # not between the same two lines, or leaving the lower end from the same line: parallel
        if max(x1, x2) >= min(y1, y2):
            continue  # their spans along the line do not overlap
        if any({line.get(u), line.get(v)} == {lo1, hi1} for u, v in declared):
            continue  # the two lines cross each other at a declared diamond (a double slip): not parallel lines
        if any((u in t1 and v in t2) or (u in t2 and v in t1) for u, v in declared):
            continue  # the diamond is declared
        w1, w2 = y1 - x1, y2 - x2
        at = (1.0 + x1 / w1 + x2 / w2) / (1.0 / w1 + 1.0 / w2)
        out.append(Crossing((p1, p2), (_track_at(t1, at, ports, pos), _track_at(t2, at, ports, pos)), round(at, 1),
                            k2))
    return out


def _lines(ports: dict[str, tuple[Port, Port]], joints: set[str]) -> dict[str, int]:
    """Track -> its line: the tracks joined through joints and through the point and normal legs of turnouts."""
    g = nx.Graph()
    g.add_nodes_from(ports)
    by_node: dict[str, list[tuple[str | None, str]]] = {}
    for tid, pq in ports.items():
        for p in pq:
            by_node.setdefault(p.node, []).append((p.leg, tid))
    for node, items in by_node.items():
        if node in joints:
            g.add_edges_from((a, b) for (_, a), (_, b) in combinations(items, 2))
        else:
            straight = [tid for leg, tid in items if leg in ("point", "normal")]
            g.add_edges_from(combinations(straight, 2))
    return {tid: n for n, comp in enumerate(nx.connected_components(g)) for tid in comp}


def _diagonal(a: str, b: str, ports: dict[str, tuple[Port, Port]], at_port: dict[Port, list[str]],
              joints: set[str]) -> list[str]:
    """The tracks of the crossover from ``a``'s reverse leg to ``b``'s, through joints; [] when they are not joined."""
    at, out = Port(a, "reverse"), []
    while True:
        track = next((t for t in at_port.get(at, ()) if t not in out), None)
        if track is None:
            return []
        out.append(track)
        p, q = ports[track]
        far = q if p == at else p
        if far == Port(b, "reverse"):
            return out
        if far.leg is not None or far.node not in joints:
            return []
        at = far


def _track_at(tracks: list[str], x: float, ports: dict[str, tuple[Port, Port]], pos: dict[str, float]) -> str:
    """The track of a diagonal that passes position ``x``."""
    for t in tracks:
        a, b = (pos[p.node] for p in ports[t])
        if min(a, b) <= x <= max(a, b):
            return t
    return tracks[0]

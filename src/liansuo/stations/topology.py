"""The track network as a directed graph (networkx) that respects turnout geometry.

A graph vertex is ``(track, direction)``: a movement along a track, down (towards increasing positions) or up.
Edges join a movement to the movements it can continue into at the far node. Through a turnout a movement runs
point -> normal, point -> reverse, normal -> point or reverse -> point, never normal -> reverse; each edge carries the
turnout and the position it needs. A direction never changes along a path because every node has its legs on
opposite sides, so "paths from a signal in its direction" are paths in this graph.

The graph is built from a :class:`Network`, the little of a station it needs; a
:class:`~stations.station.Station` is one and offers its graph as ``Station.topology``, so the station stands on
this module and not the other way round.
"""

from __future__ import annotations

from collections.abc import Iterator, Mapping
from dataclasses import dataclass, field
from typing import Protocol

import networkx as nx

from liansuo.stations.schema import Direction, Joint, Signal, Track, Turnout, TurnoutPosition

Move = tuple[str, Direction]


class TrackEnd(Protocol):
    @property
    def node(self) -> str: ...


class Network(Protocol):
    """The tracks, nodes and signals of a station: what the graph is built from and what its paths are told in."""

    @property
    def tracks(self) -> Mapping[str, Track]: ...
    @property
    def joints(self) -> Mapping[str, Joint]: ...
    @property
    def turnouts(self) -> Mapping[str, Turnout]: ...
    @property
    def signals(self) -> Mapping[str, Signal]: ...
    @property
    def node_tracks(self) -> Mapping[str, list[tuple[str | None, str]]]: ...
    def joint_tracks(self, joint: str) -> tuple[str, str]: ...
    def turnout_points_down(self, turnout: str) -> bool: ...
    def track_low_port(self, track: str) -> TrackEnd: ...
    def track_high_port(self, track: str) -> TrackEnd: ...
    def entry_track(self, node: str, direction: Direction) -> str: ...
    def track_length(self, track: str) -> float: ...


@dataclass(frozen=True)
class Path:
    """A path over the network: the tracks it runs, in order, and what it needs and passes."""

    direction: Direction
    tracks: tuple[str, ...]
    start: str  # node the path starts at
    end: str  # node the path ends at
    turnouts: tuple[tuple[str, TurnoutPosition], ...]
    joints: tuple[str, ...]  # joints passed strictly inside the path
    length: float
    sections: tuple[str, ...] = field(default=())

    def uses_turnout(self, turnout: str) -> TurnoutPosition | None:
        return dict(self.turnouts).get(turnout)


class Topology:
    """Answers path questions about one station."""

    def __init__(self, station: Network) -> None:
        self.station = station
        self.graph = nx.DiGraph()
        self._next: dict[Move, list[tuple[Move, dict[str, object]]]] = {}
        st = station
        for tid in st.tracks:
            for d in Direction:
                self.graph.add_node((tid, d))
        for node, attached in st.node_tracks.items():
            if node in st.joints:
                lo, hi = st.joint_tracks(node)
                self.graph.add_edge((lo, Direction.down), (hi, Direction.down), node=node, turnout=None, position=None)
                self.graph.add_edge((hi, Direction.up), (lo, Direction.up), node=node, turnout=None, position=None)
            elif node in st.turnouts:
                legs = dict(attached)
                point, normal, reverse = legs["point"], legs["normal"], legs["reverse"]
                facing = Direction.down if st.turnout_points_down(node) else Direction.up
                trailing = Direction.up if facing is Direction.down else Direction.down
                for leg_track, pos in ((normal, TurnoutPosition.normal), (reverse, TurnoutPosition.reverse)):
                    self.graph.add_edge((point, facing), (leg_track, facing), node=node, turnout=node, position=pos)
                    self.graph.add_edge((leg_track, trailing), (point, trailing), node=node, turnout=node,
                                        position=pos)

    # ---- basic moves -----------------------------------------------------------------------------------------
    def far_node(self, move: Move) -> str:
        track, d = move
        port = self.station.track_high_port(track) if d is Direction.down else self.station.track_low_port(track)
        return port.node

    def near_node(self, move: Move) -> str:
        track, d = move
        port = self.station.track_low_port(track) if d is Direction.down else self.station.track_high_port(track)
        return port.node

    def next_moves(self, move: Move) -> list[tuple[Move, dict[str, object]]]:
        """The moves that can follow ``move`` (the graph never changes: looked up once per move; read only)."""
        found = self._next.get(move)
        if found is None:
            found = self._next[move] = [(nxt, data) for _, nxt, data in self.graph.out_edges(move, data=True)]
        return found

    def start_move(self, node: str, direction: Direction) -> Move:
        return (self.station.entry_track(node, direction), direction)

    # ---- paths -------------------------------------------------------------------------------------------------
    def walk(self, node: str, direction: Direction, *, max_length: float = 10_000.0,
             stop_at: set[str] | None = None) -> Iterator[Path]:
        """Every path from ``node`` in ``direction`` to the first node in ``stop_at`` (or to an end of the network),
        shorter than ``max_length``."""
        stop_at = stop_at or set()
        first = self.start_move(node, direction)
        if self.near_node(first) != node:
            return  # e.g. from a boundary outwards: there is no track that way
        stack: list[tuple[list[Move], list[tuple[str, TurnoutPosition]], list[str], float]] = [
            ([first], [], [], self.station.track_length(first[0]))
        ]
        while stack:
            moves, turnouts, joints, length = stack.pop()
            last = moves[-1]
            far = self.far_node(last)
            nexts = self.next_moves(last)
            if far in stop_at or not nexts or length > max_length:
                if far in stop_at or not nexts:
                    yield self._path(node, direction, moves, turnouts, joints, length, far)
                continue
            for nxt, data in nexts:
                if any(m[0] == nxt[0] for m in moves):
                    continue
                t = list(turnouts)
                if data["turnout"] is not None:
                    t.append((str(data["turnout"]), TurnoutPosition(str(data["position"]))))
                j = [*joints, far] if far in self.station.joints else joints
                stack.append(([*moves, nxt], t, j, length + self.station.track_length(nxt[0])))

    def _path(self, start: str, d: Direction, moves: list[Move], turnouts: list[tuple[str, TurnoutPosition]],
              joints: list[str], length: float, end: str) -> Path:
        sections: list[str] = []
        for track, _ in moves:
            s = self.station.tracks[track].section
            if not sections or sections[-1] != s:
                sections.append(s)
        return Path(d, tuple(m[0] for m in moves), start, end, tuple(turnouts), tuple(joints), length, tuple(sections))

    def paths(self, start: str, direction: Direction, to: str, *, max_length: float = 10_000.0) -> list[Path]:
        """All paths from node ``start`` in ``direction`` that end at node ``to``."""
        return [p for p in self.walk(start, direction, max_length=max_length, stop_at={to}) if p.end == to]

    def paths_from_signal(self, signal: str, to: str, *, max_length: float = 10_000.0) -> list[Path]:
        """Paths from ``signal`` in its direction to a node, or to the joint of another signal."""
        sig = self.station.signals[signal]
        target = self.station.signals[to].at if to in self.station.signals else to
        return self.paths(sig.at, sig.direction, target, max_length=max_length)

    def shortest(self, signal: str, to: str) -> Path | None:
        found = self.paths_from_signal(signal, to)
        return min(found, key=lambda p: (p.length, len(p.turnouts))) if found else None

    def undirected(self) -> nx.Graph:
        """Tracks joined where they meet, for connectivity questions."""
        g = nx.Graph()
        for (a, _), (b, _) in self.graph.edges():
            g.add_edge(a, b)
        g.add_nodes_from(self.station.tracks)
        return g

"""How a train moves over the network: along the turnouts' actual positions, never through them otherwise.

A train is a path of moves ``(track, direction)`` from its rear to its front and the front's distance into the
front track. Advancing the front follows the topology: through a joint to the one track beyond; through a turnout
from the point leg to the leg its switch rails lie on (a facing move onto a turnout that is moving or lies in no
end position derails); from a normal or reverse leg to the point (a trailing move through a turnout lying the
other way squeezes it, 挤岔). At a buffer stop the train stops; past a boundary it leaves the model.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from liansuo.circuits.field import Field
from liansuo.circuits.machines import SwitchMachine
from liansuo.circuits.railgeometry import Axle, RailGeometry
from liansuo.stations.schema import Direction, EndKind
from liansuo.stations.station import Station
from liansuo.stations.topology import Move

OUTSIDE = "@outside"  # the line beyond a boundary: no track circuit, no limit
OUTSIDE_LENGTH = 1e9

Notify = Callable[[str, str], None]  # (kind, text)


@dataclass
class Position:
    """Where a train's front is, and the path of moves behind it (rear first)."""

    moves: list[Move]
    front_s: float  # metres of the front into the last move
    exits: list[str] = field(default_factory=list)  # boundary the front left through (for OUTSIDE moves)
    rails_ahead: RailsAhead | None = field(default=None, repr=False, compare=False)  # ``Track``'s, for the way ahead


class RailsAhead:
    """The front's move and the moves after it along the rails as they lay, worked out as far as asked, with each
    move's length and far node; ``Track`` keeps it on the train's position while the front stays on its move and
    every turnout it passes facing (``consulted``) has its switch rails where they were."""

    __slots__ = ("consulted", "ended", "lengths", "moves", "nodes", "track")

    def __init__(self, track: TrackGeometry, front: Move, length: float, node: str | None) -> None:
        self.track = track  # whose field's turnouts it follows
        self.moves = [front]
        self.lengths = [length]
        self.nodes = [node]  # None for the open line beyond a boundary
        self.consulted: list[tuple[SwitchMachine, str | None]] = []  # (machine, where its rails lay)
        self.ended = front[0] == OUTSIDE  # no move after the last one (a buffer stop, the open line, no position)

    def holds(self, track: TrackGeometry, front: Move) -> bool:
        if self.track is not track or self.moves[0] != front:
            return False
        return not self.consulted or all(machine.rails == rails for machine, rails in self.consulted)


def _track_geo(station: Station) -> dict[str, tuple[float, float, float]]:
    return {t: (*station.track_span(t), station.track_length(t)) for t in station.tracks}


class TrackGeometry:
    """Geometry queries shared by all trains of a station."""

    def __init__(self, station: Station, fld: Field) -> None:
        self.station = station
        self.topo = station.topology
        self.field = fld
        # per track: (position at its low end, at its high end, length), for the hot path of wheelset positions;
        # read only, shared by every simulation of the station
        self.geo = station.derived(_track_geo)

    def length(self, move: Move) -> float:
        return OUTSIDE_LENGTH if move[0] == OUTSIDE else self.station.track_length(move[0])

    def x_at(self, move: Move, s: float) -> float:
        """Position along the line of the point ``s`` metres into ``move``."""
        track, d = move
        lo, hi = self.station.track_span(track)
        frac = s / self.station.track_length(track)
        return lo + (hi - lo) * frac if d is Direction.down else hi - (hi - lo) * frac

    def place(self, section: str, direction: Direction, length: float, front_back_m: float = 5.0,
              front_x: float | None = None) -> Position | str:
        """A train of ``length`` standing in ``section`` (or on a track) facing ``direction``, its front
        ``front_back_m`` short of the far end (or at position ``front_x`` along the line); its rear may reach back
        into the sections behind, and beyond a boundary onto the open line. Returns the reason if it does not fit."""
        if section in self.station.tracks:
            front_track = section
        else:
            tracks = self.station.section_tracks.get(section)
            if not tracks:
                return f"there is no section or track '{section}'"
            # the section's track furthest in the direction of travel
            key = (lambda t: self.station.track_span(t)[1]) if direction is Direction.down else (
                lambda t: -self.station.track_span(t)[0])
            front_track = max(tracks, key=key)
        move: Move = (front_track, direction)
        if front_x is not None:
            s_x = self.s_of_x(move, front_x)
            if s_x is None:
                lo, hi = self.station.track_span(front_track)
                return f"front={front_x:g} is off track {front_track} ({lo:g}-{hi:g} m)"
            front_s = s_x
        elif front_back_m >= self.length(move):
            return f"{section} is only {self.length(move):.0f} m long where the train would stand; use a smaller back="
        else:
            front_s = self.length(move) - front_back_m
        moves = [move]
        need = length - front_s
        while need > 0:
            prev = self._previous(moves[0])
            if prev is None:
                return (f"a {length:g} m train does not fit: {section} and the track behind it end "
                        f"{length - need:.0f} m short")
            moves.insert(0, prev)
            need -= self.length(prev)
        return Position(moves, front_s)

    def _previous(self, move: Move) -> Move | None:
        """The move that leads into ``move`` (the rear's way back), following the turnouts' rails."""
        if move[0] == OUTSIDE:
            return None
        back = (move[0], Direction.up if move[1] is Direction.down else Direction.down)
        nxt = self._next(back, follow_rails=True)
        if nxt is None:
            return None
        return (nxt[0], move[1])  # OUTSIDE when the track behind runs out of the model onto the open line

    def _next(self, move: Move, *, follow_rails: bool,
              consulted: list[tuple[SwitchMachine, str | None]] | None = None) -> Move | None:
        """The move after ``move``: through a turnout faced, the leg its rails lie on (``follow_rails``: none if
        they lie on neither, else the first leg); each machine whose rails it looked at goes into ``consulted``."""
        options = self.topo.next_moves(move)
        if not options:
            far = self.topo.far_node(move)
            end = self.station.ends.get(far)
            if end is not None and end.kind is EndKind.boundary:
                return (OUTSIDE, move[1])
            return None
        if len(options) == 1:
            return options[0][0]
        for nxt, data in options:
            machine = self.field.machines[str(data["turnout"])]
            if consulted is not None:
                consulted.append((machine, machine.rails))
            if machine.rails == data["position"]:
                return nxt
        return options[0][0] if not follow_rails else None

    # ---- moving -----------------------------------------------------------------------------------------------
    def advance(self, name: str, pos: Position, ds: float, notify: Notify) -> tuple[float, str]:
        """Move the front ``ds`` metres; returns (metres moved, what stopped it: '', 'buffer', 'derailed')."""
        moved = 0.0
        geo = self.geo
        while ds > 1e-9:
            head = pos.moves[-1]
            g = geo.get(head[0])  # ``length``: a track's, or the open line's
            room = (OUTSIDE_LENGTH if g is None else g[2]) - pos.front_s
            if ds <= room:
                pos.front_s += ds
                return moved + ds, ""
            pos.front_s += room
            moved += room
            ds -= room
            nxt, stop = self._enter_next(name, head, notify)
            if nxt is None:
                return moved, stop
            pos.moves.append(nxt)
            pos.front_s = 0.0
        return moved, ""

    def _enter_next(self, name: str, head: Move, notify: Notify) -> tuple[Move | None, str]:
        far = self.topo.far_node(head)
        options = self.topo.next_moves(head)
        if not options:
            end = self.station.ends.get(far)
            if end is not None and end.kind is EndKind.boundary:
                notify("train", f"train {name} leaves the station at {far}")
                return (OUTSIDE, head[1]), ""
            notify("train", f"train {name} stopped at buffer stop {far}")
            return None, "buffer"
        if len(options) == 1:
            nxt, data = options[0]
            t = data["turnout"]
            if t is not None:  # trailing through a turnout
                m = self.field.machines[str(t)]
                if m.rails != data["position"]:
                    m.trail(str(data["position"]))
                    self.field.note_turnout(str(t))
                    notify("alarm", f"train {name} trailed through turnout {t} lying the other way: squeezed (挤岔)")
            return nxt, ""
        t = str(options[0][1]["turnout"])
        m = self.field.machines[t]
        if m.running or m.rails is None:
            notify("alarm", f"train {name} derailed at turnout {t}: it was moving or in no end position")
            return None, "derailed"
        for nxt, data in options:
            if data["position"] == m.rails:
                return nxt, ""
        return None, "derailed"  # pragma: no cover - rails always match one leg

    # ---- what the track circuits see ------------------------------------------------------------------------
    def axles(self, pos: Position, offsets: tuple[float, ...]) -> list[Axle]:
        """Where each wheelset stands (``offsets`` behind the front, front first); none on the open line."""
        out: list[Axle] = []
        moves = pos.moves
        idx = len(moves) - 1
        back_of_move = pos.front_s  # distance from the front to the start of move idx
        track, down = moves[idx][0], moves[idx][1] is Direction.down
        geo = self.geo.get(track)
        for off in offsets:
            while off > back_of_move and idx > 0:
                idx -= 1
                track, down = moves[idx][0], moves[idx][1] is Direction.down
                geo = self.geo.get(track)
                back_of_move += OUTSIDE_LENGTH if geo is None else geo[2]
            if geo is None or off > back_of_move:
                continue
            lo, hi, length = geo
            frac = (back_of_move - off) / length
            out.append(Axle(track, lo + (hi - lo) * frac if down else hi - (hi - lo) * frac))
        return out

    def shunts(self, pos: Position, offsets: tuple[float, ...], geometry: RailGeometry,
               ohm: float) -> dict[str, list[tuple[float, float]]]:
        """The shunts this train's wheelsets make, by section: ``axles`` and ``RailGeometry.shunts_of`` in one pass.
        Worked out only when the field asks (``wheelsets.TrainWheelsets``); ``wheelsets.sections_shunted`` finds
        the sections the same way without placing each wheelset."""
        out: dict[str, list[tuple[float, float]]] = {}
        moves = pos.moves
        idx = len(moves) - 1
        back_of_move = pos.front_s
        sections = self.station.tracks
        seg: tuple[float, float, float, bool, list[tuple[float, float]], float, float, list[tuple[float, float]]] | None
        seg = None

        def segment(i: int) -> tuple[float, float, float, bool, list[tuple[float, float]], float, float,
                                     list[tuple[float, float]]] | None:
            track, d = moves[i]
            geo = self.geo.get(track)
            if geo is None:
                return None
            sec = sections[track].section
            return (*geo, d is Direction.down, geometry.track_dead[track], geometry.section_low[sec],
                    geometry.section_length[sec], out.setdefault(sec, []))

        seg = segment(idx)
        for off in offsets:
            while off > back_of_move and idx > 0:
                idx -= 1
                seg = segment(idx)
                back_of_move += OUTSIDE_LENGTH if seg is None else seg[2]
            if seg is None or off > back_of_move:
                continue
            lo, hi, length, down, zones, sec_low, sec_len, bucket = seg
            frac = (back_of_move - off) / length
            x = lo + (hi - lo) * frac if down else hi - (hi - lo) * frac
            if zones and any(z0 <= x < z1 for z0, z1 in zones):
                continue  # in a dead zone: it shunts nothing
            d = x - sec_low
            bucket.append((0.0 if d < 0 else (sec_len if d > sec_len else d), ohm))
        return {s: v for s, v in out.items() if v}

    def trim(self, pos: Position, length: float) -> None:
        """Forget moves wholly behind the rear of the train."""
        behind = pos.front_s
        moves, geo = pos.moves, self.geo
        keep = len(moves) - 1
        while keep > 0 and behind < length:
            keep -= 1
            g = geo.get(moves[keep][0])  # ``length``: a track's, or the open line's
            behind += OUTSIDE_LENGTH if g is None else g[2]
        if keep:
            del moves[:keep]

    def reverse(self, pos: Position, length: float) -> Position:
        """The same train facing the other way: its rear becomes its front."""
        self.trim(pos, length)
        rear_s = sum(self.length(m) for m in pos.moves[:-1]) + pos.front_s - length  # rear's distance into moves[0]
        flipped = [(t, Direction.up if d is Direction.down else Direction.down) for t, d in reversed(pos.moves)]
        first = pos.moves[0]
        return Position(flipped, self.length(first) - max(rear_s, 0.0) if first[0] != OUTSIDE else 0.0)

    def moves_ahead(self, pos: Position, horizon: float) -> list[tuple[float, Move]]:
        """The front's move and those after it along the rails as they lie now, each with the distance from the
        front to the move's start (negative for the front's own move)."""
        out: list[tuple[float, Move]] = []
        way = self.rails_ahead(pos)
        k = 0
        move = way.moves[0]
        start = -pos.front_s
        while move[0] != OUTSIDE and start <= horizon:
            out.append((start, move))
            start += way.lengths[k]
            nxt = self.move_after(way, k)
            if nxt is None:
                break
            k += 1
            move = nxt
        return out

    def rails_ahead(self, pos: Position) -> RailsAhead:
        """The way ahead of the front as the rails lie now: the one kept on ``pos`` while it holds."""
        front = pos.moves[-1]
        way = pos.rails_ahead
        if way is None or not way.holds(self, front):
            way = pos.rails_ahead = RailsAhead(self, front, self.length(front),
                                               None if front[0] == OUTSIDE else self.topo.far_node(front))
        return way

    def move_after(self, way: RailsAhead, k: int) -> Move | None:
        """The move after ``way.moves[k]`` along the rails (worked out now if it has not been yet), or None."""
        if k + 1 < len(way.moves):
            return way.moves[k + 1]
        if way.ended:
            return None
        nxt = self._next(way.moves[k], follow_rails=True, consulted=way.consulted)
        if nxt is None:
            way.ended = True
            return None
        outside = nxt[0] == OUTSIDE
        way.moves.append(nxt)
        way.lengths.append(self.length(nxt))
        way.nodes.append(None if outside else self.topo.far_node(nxt))
        way.ended = outside
        return nxt

    def s_of_x(self, move: Move, x: float) -> float | None:
        """How far into ``move`` the position ``x`` lies, if it lies on the move's track."""
        lo, hi = self.station.track_span(move[0])
        if not lo - 1e-6 <= x <= hi + 1e-6:
            return None
        frac = (x - lo) / (hi - lo) if move[1] is Direction.down else (hi - x) / (hi - lo)
        return frac * self.station.track_length(move[0])

    def ahead(self, pos: Position, horizon: float) -> list[tuple[float, str, Move]]:
        """Nodes ahead of the front within ``horizon`` metres along the way the rails lie now: (distance, node,
        the move arriving at it)."""
        out: list[tuple[float, str, Move]] = []
        geo = self.geo.get(pos.moves[-1][0])
        if geo is not None and geo[2] - pos.front_s > horizon:
            return out  # no node before the horizon (the common case of a step's run)
        way = self.rails_ahead(pos)
        k = 0
        move = way.moves[0]
        dist = way.lengths[0] - pos.front_s
        while dist <= horizon and move[0] != OUTSIDE:
            node = way.nodes[k]
            assert node is not None
            out.append((dist, node, move))
            nxt = self.move_after(way, k)
            if nxt is None or nxt[0] == OUTSIDE:
                break
            k += 1
            move = nxt
            dist += way.lengths[k]
        return out

"""Drivers: what speed a train aims for.

- ``manual``: the speed commanded with ``drive``; it does not look at signals and can pass one at danger (the
  interlocking notices);
- ``signal``: stops short of a closed signal (a stop aspect or dark) and of buffer stops, and keeps to the speed of
  the last aspect passed (the rule set's ``driving.aspect_speed_kmh``);
- ``auto``: automatic shunting (Liu Jing et al. 2025, docs/references.md): moves only while the driving conditions hold,
  stops at a safe distance before closed or blue signals and at the station boundary, keeps to the depot limits.
"""

from __future__ import annotations

from collections.abc import Mapping
from math import sqrt

from liansuo.rules import RuleSet
from liansuo.simulation.trains.movement import OUTSIDE, Position, TrackGeometry
from liansuo.stations.schema import Direction, EndKind, Signal, SignalKind
from liansuo.stations.station import Station


def stopping_speed(distance_m: float, brake_ms2: float) -> float:
    """The highest speed (m/s) from which the train still stops within ``distance_m``."""
    return sqrt(2.0 * brake_ms2 * max(distance_m, 0.0))


class Lookout:
    """What drivers look out for at a station under a rule set, sorted out once: the signals at a node that a
    movement heeds (a train movement train signals only; a shunting movement shunting signals and signals with a
    shunting aspect), the aspects to stop at and the speed each other aspect allows."""

    def __init__(self, station: Station, rules: RuleSet) -> None:
        self.station = station
        self.names = rules.aspects
        self.closed = rules.aspects.closed
        self.speeds_kmh = rules.driving.aspect_speed_kmh
        self.buffer_margin_m = rules.driving.buffer_margin_m
        self._heeded: dict[tuple[Direction, bool], dict[str, list[Signal]]] = {}  # by movement, then node

    def heeded(self, node: str, direction: Direction, shunting: bool) -> list[Signal]:
        at = self.heeded_at(direction, shunting)
        found = at.get(node)
        if found is None:
            names = self.names
            found = at[node] = [
                sig for sig in self.station.signals_at(node) if sig.direction is direction
                and ((sig.kind is SignalKind.shunting) == shunting
                     or (shunting and names.can_show(names.shunt, [lp.value for lp in sig.lamps])))]
        return found

    def heeded_at(self, direction: Direction, shunting: bool) -> dict[str, list[Signal]]:
        """``heeded`` of the nodes asked so far for one kind of movement, by node (a node not in it yet: ask
        ``heeded``)."""
        key = (direction, shunting)
        at = self._heeded.get(key)
        if at is None:
            at = self._heeded[key] = {}
        return at


def aim(track: TrackGeometry, pos: Position, aspects: Mapping[str, str], lookout: Lookout, horizon: float,
        margin: float, shunting: bool, boundary_stops: bool, current_limit_ms: float, vmax_ms: float, brake_ms2: float,
        lead_m: float) -> tuple[float, str]:
    """The speed a driver aims for now: the lowest of line speed, the current aspect's limit, and what lets the train
    meet every limit ahead (signals, a buffer stop, the boundary when ``boundary_stops``) along the rails as they lie
    now, stopping ``margin`` before a closed signal; ``lead_m`` (the distance run in one step) keeps the discrete
    steps from overshooting. A train movement heeds train signals only; a shunting movement shunting signals and
    signals with a shunting aspect. Worked out in one pass: the fleet asks it of every train every cycle, so no list
    of what lies ahead is built, nor a text for a limit that does not bind; the walk ends at the first stop, which
    the rails ahead (``Track``'s, kept on ``pos``) answer the same however far they were worked out.
    tests/test_shortcuts_same.py compares every answer with the rule written plainly (the list of what lies ahead,
    then the limits one by one): the very same floats."""
    v = min(vmax_ms, current_limit_ms)
    why = ""
    front = pos.moves[-1]
    geo = track.geo.get(front[0])
    if geo is not None and geo[2] - pos.front_s > horizon:
        return v, why  # no node before the horizon
    way = track.rails_ahead(pos)
    moves, lengths, nodes = way.moves, way.lengths, way.nodes
    direction = front[1]
    closed, speeds_kmh, ends = lookout.closed, lookout.speeds_kmh, lookout.station.ends
    heeded = lookout.heeded_at(direction, shunting)
    k = 0
    move = moves[0]
    dist = lengths[0] - pos.front_s
    while dist <= horizon and move[0] != OUTSIDE:
        node = nodes[k]
        assert node is not None
        signals = heeded.get(node)
        if signals is None:
            signals = lookout.heeded(node, direction, shunting)
        for sig in signals:
            aspect = aspects.get(sig.id, "")
            if aspect in closed:
                allowed = _allowed(dist - margin, 0.0, brake_ms2, lead_m)
                if allowed < v:
                    v, why = allowed, f"signal {sig.id} at {aspect or 'dark'}"
                return v, why
            limit = speeds_kmh.get(aspect)
            if limit is not None:
                allowed = _allowed(dist, limit / 3.6, brake_ms2, lead_m)
                if allowed < v:
                    v, why = allowed, f"signal {sig.id} at {aspect}"
        end = ends.get(node)
        if end is not None and (end.kind is EndKind.buffer or boundary_stops):
            allowed = _allowed(dist - lookout.buffer_margin_m, 0.0, brake_ms2, lead_m)
            if allowed < v:
                v, why = allowed, f"{end.kind.value} {node}"
            return v, why
        nxt = moves[k + 1] if k + 1 < len(moves) else track.move_after(way, k)
        if nxt is None or nxt[0] == OUTSIDE:
            break
        k += 1
        move = nxt
        dist += lengths[k]
    return v, why


def _allowed(distance_m: float, speed_ms: float, brake_ms2: float, lead_m: float) -> float:
    """The highest speed now from which the train still meets ``speed_ms`` at ``distance_m`` ahead, braking at
    ``brake_ms2`` after a step's run ``lead_m``; 0 within half a metre of a stop."""
    allowed = sqrt(speed_ms ** 2 + 2.0 * brake_ms2 * max(distance_m - lead_m, 0.0))
    return 0.0 if speed_ms == 0.0 and distance_m <= 0.5 else allowed

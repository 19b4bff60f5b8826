"""Drivers: what speed a train aims for.

- ``manual``: the speed commanded with ``drive``; it does not look at signals and can pass one at danger (the
  interlocking notices);
- ``signal``: stops short of a closed signal (a stop aspect or dark) and of buffer stops, and keeps to the speed of
  the last aspect passed (the rule set's ``driving.aspect_speed_kmh``);
- ``auto``: automatic shunting (Liu Jing et al. 2025, docs/references.md): moves only while the driving conditions hold,
  stops at a safe distance before closed or blue signals and at the station boundary, keeps to the depot limits.
"""

from __future__ import annotations

from dataclasses import dataclass
from math import sqrt

from liansuo.rules import RuleSet, load_rules
from liansuo.stations.schema import Direction, EndKind, Signal, SignalKind
from liansuo.stations.station import Station

from .movement import Position, Track


def stopping_speed(distance_m: float, brake_ms2: float) -> float:
    """The highest speed (m/s) from which the train still stops within ``distance_m``."""
    return sqrt(2.0 * brake_ms2 * max(distance_m, 0.0))


@dataclass(frozen=True)
class Ahead:
    """The first thing ahead a driver must heed: the distance to it and the speed allowed there (0: stop)."""

    distance_m: float
    speed_ms: float
    what: str


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
        self._heeded: dict[tuple[str, Direction, bool], list[Signal]] = {}

    def heeded(self, node: str, direction: Direction, shunting: bool) -> list[Signal]:
        key = (node, direction, shunting)
        found = self._heeded.get(key)
        if found is None:
            names = self.names
            found = self._heeded[key] = [
                sig for sig in self.station.signals_at(node) if sig.direction is direction
                and ((sig.kind is SignalKind.shunting) == shunting
                     or (shunting and names.can_show(names.shunt, [lp.value for lp in sig.lamps])))]
        return found


def look_ahead(track: Track, pos: Position, station: Station, aspects: dict[str, str], horizon: float,
               margin: float, *, shunting: bool, boundary_stops: bool = False,
               rules: RuleSet | None = None, lookout: Lookout | None = None) -> list[Ahead]:
    """Signals, buffer stops and (optionally) the boundary ahead along the rails as they lie now. A train movement
    is governed by train signals only; a shunting movement by shunting signals and signals with a shunting aspect,
    and it stops before a shunting signal at stop. ``lookout``: the station sorted out for the rules (made here if
    not given)."""
    out: list[Ahead] = []
    lookout = lookout or Lookout(station, rules or load_rules())
    closed, speeds_kmh, ends = lookout.closed, lookout.speeds_kmh, station.ends
    direction = pos.moves[-1][1]
    for dist, node, _move in track.ahead(pos, horizon):
        for sig in lookout.heeded(node, direction, shunting):
            aspect = aspects.get(sig.id, "")
            if aspect in closed:
                out.append(Ahead(dist - margin, 0.0, f"signal {sig.id} at {aspect or 'dark'}"))
                return out
            limit = speeds_kmh.get(aspect)
            if limit is not None:
                out.append(Ahead(dist, limit / 3.6, f"signal {sig.id} at {aspect}"))
        end = ends.get(node)
        if end is not None and (end.kind is EndKind.buffer or boundary_stops):
            out.append(Ahead(dist - lookout.buffer_margin_m, 0.0, f"{end.kind.value} {node}"))
            return out
    return out


def target_speed(current_limit_ms: float, vmax_ms: float, ahead: list[Ahead], brake_ms2: float,
                 lead_m: float = 0.0) -> tuple[float, str]:
    """Speed to aim for now: the lowest of line speed, the current aspect's limit, and what lets the train meet
    every limit ahead. ``lead_m`` (the distance run in one step) keeps the discrete steps from overshooting."""
    v = min(vmax_ms, current_limit_ms)
    why = ""
    for a in ahead:
        allowed = sqrt(a.speed_ms ** 2 + 2.0 * brake_ms2 * max(a.distance_m - lead_m, 0.0))
        if a.speed_ms == 0.0 and a.distance_m <= 0.5:
            allowed = 0.0
        if allowed < v:
            v, why = allowed, a.what
    return v, why

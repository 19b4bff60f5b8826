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
from liansuo.stations.schema import EndKind, SignalKind
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


def look_ahead(track: Track, pos: Position, station: Station, aspects: dict[str, str], horizon: float,
               margin: float, *, shunting: bool, boundary_stops: bool = False,
               rules: RuleSet | None = None) -> list[Ahead]:
    """Signals, buffer stops and (optionally) the boundary ahead along the rails as they lie now. A train movement
    is governed by train signals only; a shunting movement by shunting signals and signals with a shunting aspect,
    and it stops before a shunting signal at stop."""
    out: list[Ahead] = []
    rules = rules or load_rules()
    names, driving = rules.aspects, rules.driving
    direction = pos.moves[-1][1]
    for dist, node, _move in track.ahead(pos, horizon):
        for sig in station.signals_at(node):
            if sig.direction is not direction:
                continue
            shunt_aspect = names.can_show(names.shunt, [lp.value for lp in sig.lamps])
            if (sig.kind is SignalKind.shunting) != shunting and not (shunting and shunt_aspect):
                continue  # not this movement's signal
            aspect = aspects.get(sig.id, "")
            if aspect in names.closed:
                out.append(Ahead(dist - margin, 0.0, f"signal {sig.id} at {aspect or 'dark'}"))
                return out
            limit = driving.aspect_speed_kmh.get(aspect)
            if limit is not None:
                out.append(Ahead(dist, limit / 3.6, f"signal {sig.id} at {aspect}"))
        end = station.ends.get(node)
        if end is not None and (end.kind is EndKind.buffer or boundary_stops):
            out.append(Ahead(dist - driving.buffer_margin_m, 0.0, f"{end.kind.value} {node}"))
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

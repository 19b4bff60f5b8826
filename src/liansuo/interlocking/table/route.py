"""The interlocking table's data (联锁表): one row per route, derived from the topology by :mod:`.derive` and
:mod:`.conflicts`.

A row holds the buttons, the signal and the aspects it can give, the turnouts with position and role (``route``;
``protection`` for flank protection, 防护道岔; ``driven``, 带动道岔), the track sections, conditional fouling
sections (侵限), the approach sections, an overlap where the station file asks for one, the track a shunting
route leads into at sight, the run-on of a shunting route past a signal of the other direction, and the
conflicting (敌对) and opposing routes.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field
from typing import Literal

from liansuo.kit.source import Diagnostic
from liansuo.stations.schema import Direction, TurnoutPosition
from liansuo.stations.station import Station
from liansuo.stations.topology import Path

Role = Literal["route", "protection", "driven"]
Kind = Literal["train", "shunt"]
KINDS: tuple[Kind, ...] = ("train", "shunt")
Condition = tuple[tuple[str, TurnoutPosition], ...]  # turnout positions under which a conflict holds


@dataclass(frozen=True)
class RouteTurnout:
    id: str
    position: TurnoutPosition
    role: Role


@dataclass(frozen=True)
class FoulingSection:
    """A section the route must find clear beside its path (侵限): beyond a joint laid inside the fouling point of
    ``turnout`` (lying ``position`` for the route), the section of a track that crosses the path at ``diamond`` (a
    vehicle standing there fouls the crossing), or one the station file adds (``overrides.fouling``)."""

    section: str
    turnout: str | None = None
    position: TurnoutPosition | None = None
    diamond: str | None = None


@dataclass(frozen=True)
class RunOn:
    """Where a shunting movement runs on past a signal of the other direction at the end of its route, for one way
    the turnouts beyond lie: it goes on to the next signal of its own direction, or into a station track or spur at
    sight. ``when`` are the facing turnouts beyond that choose this way; ``turnouts`` every turnout it needs (the
    trailing ones it runs through, and their flank protection)."""

    when: Condition
    sections: tuple[str, ...]
    turnouts: tuple[RouteTurnout, ...]
    leads_into: str | None
    end_node: str


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
    line_sections: tuple[str, ...] = ()  # a departure onto a line with no block described: its sections to the end
    overlap_sections: tuple[str, ...] = ()
    overlap_turnouts: tuple[RouteTurnout, ...] = ()
    overlap_release_s: float = 0.0
    overlap_end: str | None = None  # the overlap's end button, where the file names one
    overlap_alternative: bool = False  # set only by pressing ``overlap_end`` (变更延续进路): not the basic overlap
    safety_line: str | None = None  # the safety line (安全线) that isolates the receiving track, its turnout protecting
    diamonds: tuple[str, ...] = ()  # diamond crossings the path runs over
    leads_into: str | None = None  # station track or spur a shunting route enters at sight at its end
    run_on: tuple[RunOn, ...] = ()  # one per way the turnouts beyond may lie
    aspects: tuple[str, ...] = ()
    conflicts: dict[str, str] = field(default_factory=dict)  # route id -> why (always)
    conditional: dict[str, tuple[tuple[Condition, str], ...]] = field(default_factory=dict)  # only when ...
    head_on: dict[str, str] = field(default_factory=dict)  # enemy route -> the track both lead onto
    added_enemies: set[str] = field(default_factory=set)  # enemies the station file adds (overrides.enemies)
    opposing: tuple[str, ...] = ()

    @property
    def buttons(self) -> tuple[str, ...]:
        """The buttons that select the route, in the order pressed: start, variant buttons, end, and for an
        alternative overlap its end button."""
        return (self.start, *self.via, self.end) + ((self.overlap_end,) if self.overlap_alternative
                                                    and self.overlap_end else ())

    @property
    def all_sections(self) -> tuple[str, ...]:
        return self.sections + tuple(f.section for f in self.fouling) + self.overlap_sections

    @property
    def all_turnouts(self) -> tuple[RouteTurnout, ...]:
        return self.turnouts + self.overlap_turnouts

    def run_on_for(self, lies: dict[str, str | None]) -> RunOn | None:
        """The run-on for the way the turnouts beyond lie (``lies``: turnout -> position proven, or None)."""
        for ro in self.run_on:
            if all(lies.get(t) == p.value for t, p in ro.when):
                return ro
        return None

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
            "fouling_sections": [{"section": f.section, "turnout": f.turnout,
                                  "position": f.position.value if f.position else None, "diamond": f.diamond}
                                 for f in self.fouling],
            "approach": list(self.approach),
            "overlap": ({"sections": list(self.overlap_sections),
                         "turnouts": [{"id": t.id, "position": t.position.value} for t in self.overlap_turnouts],
                         "release_s": self.overlap_release_s, "end": self.overlap_end,
                         "alternative": self.overlap_alternative} if self.overlap_sections else None),
            "safety_line": self.safety_line,
            "diamonds": list(self.diamonds),
            "leads_into": self.leads_into,
            "run_on": [{"when": {t: p.value for t, p in ro.when}, "sections": list(ro.sections),
                        "turnouts": [{"id": t.id, "position": t.position.value, "role": t.role}
                                     for t in ro.turnouts],
                        "leads_into": ro.leads_into} for ro in self.run_on],
            "length_m": round(self.path.length, 1),
            "exit_link": self.exit_link,
            "line_sections": list(self.line_sections),
            "conflicts": sorted(self.conflicts),
            "conflict_reasons": dict(sorted(self.conflicts.items())),
            "conditional_conflicts": {rid: [{"when": {t: p.value for t, p in cond}, "why": why}
                                            for cond, why in alts]
                                      for rid, alts in sorted(self.conditional.items())},
            "opposing": list(self.opposing),
        }


@dataclass
class InterlockingTable:
    station: Station
    routes: dict[str, Route]
    throats: dict[str, tuple[str, ...]]  # throat name (its home signals) -> turnouts
    unselectable: list[str] = field(default_factory=list)  # paths with no distinguishing via button
    warnings: list[Diagnostic] = field(default_factory=list)  # design warnings: routes left out, and why

    _buttons: dict[tuple[str, str, str, tuple[str, ...], str | None], Route] = field(
        default_factory=dict, init=False, repr=False, compare=False)

    def by_buttons(self, kind: Kind, start: str, end: str, via: Iterable[str] = (),
                   overlap: str | None = None) -> Route | None:
        """The route the buttons select; ``overlap``: the overlap's end button pressed after the end button (none:
        the basic overlap)."""
        key = (kind, start, end, tuple(via), overlap)
        r = self._buttons.get(key)
        if r is None or self.routes.get(r.id) is not r:  # first use, or the routes were edited: index again
            self._buttons.clear()
            for x in self.routes.values():
                if not x.overlap_alternative:
                    self._buttons.setdefault((x.kind, x.start, x.end, x.via, None), x)
                if x.overlap_end is not None:
                    self._buttons.setdefault((x.kind, x.start, x.end, x.via, x.overlap_end), x)
            r = self._buttons.get(key)
        return r

    def as_dict(self) -> dict[str, object]:
        return {"station": self.station.id, "routes": [r.as_dict() for r in self.routes.values()],
                "throats": {k: list(v) for k, v in self.throats.items()}}

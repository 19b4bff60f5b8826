"""What the safety oracle reads of a station and a rule set (:class:`Tables`), worked out once per station and rule
set (``Station.derived``) for every oracle watching a simulation of it."""

from __future__ import annotations

from liansuo.proving.oracle.authority import Tracer
from liansuo.proving.oracle.ceiling import Ceiling
from liansuo.proving.oracle.flank import Flank, clearance_m
from liansuo.proving.oracle.lamps import LampReader
from liansuo.rules import RuleSet
from liansuo.stations.schema import Direction
from liansuo.stations.station import Station


class Tables:
    """What the oracle reads of a station and a rule set, worked out once per station and rule set for every oracle
    watching a simulation of it (verify starts thousands): the tracer, the ceiling, the lamp reader and the indices
    below never change once made (the reader's memo is a pure function of the lamps it was asked about). The flank
    is the one piece each oracle has of its own (``Flank.fresh``): its memo is keyed by a path's tracks alone."""

    def __init__(self, station: Station, rules: RuleSet) -> None:
        self.tracer = Tracer(station, overlap_release_s=rules.overlap_release_s, rules=rules)
        self.flank = Flank(station, clearance_m(station, rules))
        self.reader = LampReader(rules.aspects)
        self.ceiling = Ceiling(station, rules)
        self.onto_track = {frozenset(pair) for pair in rules.enemy_onto_track}
        self.kind = {s.id: s.kind for s in station.model.signals}
        self.lamps = {s.id: {lamp.value for lamp in s.lamps} for s in station.model.signals}
        self.rear: dict[str, str | None] = {}
        for s in station.model.signals:
            rear = station.signal_rear_track(s.id)
            self.rear[s.id] = station.tracks[rear].section if rear else None
        self.doors = {p.section for p in station.model.platforms if p.screen_doors}
        self.role = {s: sec.role for s, sec in station.sections.items()}
        self.section_of = {t: tr.section for t, tr in station.tracks.items()}
        self.turnout_section = dict(station.turnout_section)
        self.turnout_sections = sorted(set(self.turnout_section.values()))  # each once (a crossover's share one)
        self.turnout_tracks = {t: {tid for _, tid in station.node_tracks[t]} for t in station.turnouts}
        self.pair_of = {t.id: t.pair for t in station.model.turnouts if t.pair}
        # automatic lines: their sections, and the direction that leads out of the station onto them
        self.lines: dict[str, tuple[frozenset[str], Direction]] = {}
        for lk in station.model.links:
            if lk.kind.value == "automatic" and lk.sections:
                first = station.section_tracks[lk.sections[0]]
                inside = sum(station.node_at(p.node) for t in first for p in station.track_ports[t]) / (2 * len(first))
                out = Direction.down if station.node_at(lk.end) > inside else Direction.up
                self.lines[lk.id] = (frozenset(lk.sections), out)

"""A validated station: the file's model plus indices, and the topology graph built from it on first use."""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from functools import cached_property
from typing import TYPE_CHECKING, Any, TypeVar, overload

from liansuo.kit.printable import printable
from liansuo.kit.source import Diagnostic, Source
from liansuo.stations.schema import (
    Direction,
    End,
    FoulingPoint,
    Joint,
    Section,
    SectionRole,
    Signal,
    StandaloneButton,
    StationFile,
    Track,
    Turnout,
)

if TYPE_CHECKING:
    from liansuo.rules import DesignRules, RuleSet
    from liansuo.stations.topology import Topology

LEGS = ("point", "normal", "reverse")
T = TypeVar("T")


@dataclass(frozen=True)
class Port:
    """Where a track end attaches: a node (end, joint or turnout) and, for turnouts, the leg."""

    node: str
    leg: str | None = None

    def __str__(self) -> str:
        return f"{self.node}.{self.leg}" if self.leg else self.node


def parse_port(ref: str) -> Port:
    """``'1.normal'`` -> Port('1', 'normal'); ``'J3'`` -> Port('J3')."""
    head, dot, leg = ref.rpartition(".")
    if dot and leg in LEGS:
        return Port(head, leg)
    return Port(ref)


@dataclass(frozen=True)
class DeadZone:
    """The stretch between the staggered rail joints of one joint (死区段)."""

    joint: str
    start: float
    end: float

    @property
    def length(self) -> float:
        return self.end - self.start


class Station:
    """A station file that passed the schema and every cross-check."""

    def __init__(self, model: StationFile, source: Source | None = None) -> None:
        self.model = model
        self.source = source
        self.warnings: list[Diagnostic] = []
        self.id = model.id
        self.ends: dict[str, End] = {e.id: e for e in model.ends}
        self.joints: dict[str, Joint] = {j.id: j for j in model.joints}
        self.turnouts: dict[str, Turnout] = {t.id: t for t in model.turnouts}
        self.tracks: dict[str, Track] = {t.id: t for t in model.tracks}
        self.sections: dict[str, Section] = {s.id: s for s in model.sections}
        self.signals: dict[str, Signal] = {s.id: s for s in model.signals}
        self.buttons: dict[str, StandaloneButton] = {b.id: b for b in model.buttons}
        # track -> [(diamond, the track crossing it)]
        self.crossings: dict[str, list[tuple[str, str]]] = {}
        for d in model.diamonds:
            one, two = d.tracks
            self.crossings.setdefault(one, []).append((d.id, two))
            self.crossings.setdefault(two, []).append((d.id, one))
        # track ends
        self.track_ports: dict[str, tuple[Port, Port]] = {
            t.id: (parse_port(t.start), parse_port(t.end)) for t in model.tracks
        }
        # node -> {leg or track id: track id}
        self.node_tracks: dict[str, list[tuple[str | None, str]]] = {}
        for tid, ports in self.track_ports.items():
            for p in ports:
                self.node_tracks.setdefault(p.node, []).append((p.leg, tid))
        self.section_tracks: dict[str, list[str]] = {}
        for t in model.tracks:
            self.section_tracks.setdefault(t.section, []).append(t.id)
        self.turnout_section: dict[str, str] = {}
        for tid, (a, b) in self.track_ports.items():
            for p in (a, b):
                if p.leg is not None:
                    self.turnout_section[p.node] = self.tracks[tid].section
        self.pairs: dict[str, list[str]] = {}
        for turnout in model.turnouts:
            if turnout.pair:
                self.pairs.setdefault(turnout.pair, []).append(turnout.id)
        self._derived: dict[tuple[object, int], tuple[object, Any]] = {}  # see ``derived``

    # ---- what the layers above work out from the station once ------------------------------------------------
    @overload
    def derived(self, make: Callable[[Station], T]) -> T: ...

    @overload
    def derived(self, make: Callable[[Station, RuleSet], T], rules: RuleSet) -> T: ...

    def derived(self, make: Callable[..., T], rules: RuleSet | None = None) -> T:
        """``make(station)`` or ``make(station, rules)``, worked out at the first call and the same object after.

        A station never changes once loaded, and verify builds thousands of simulations of one: what a layer above
        derives from the station (and a rule set) alone, such as the track circuits' models, the interlocking's
        indices or the safety oracle's tables, is worked out for the first and read by the rest. The caller owns
        ``make`` (a module-level function: it is the key, with the rule set by identity) and must never change what
        it returns: whatever a simulation changes is built fresh for each. Kept on the station, it lives and dies
        with it (a cache keyed weakly by the station could not let go of a station its values refer back to), and it
        is not pickled: a copy in another process works it out again."""
        key = (make, id(rules))  # the entry keeps ``rules`` alive, so its id names no other rule set meanwhile
        hit = self._derived.get(key)
        if hit is None:
            hit = self._derived[key] = (rules, make(self) if rules is None else make(self, rules))
        return hit[1]

    def __getstate__(self) -> dict[str, object]:
        state = dict(self.__dict__)
        state["_derived"] = {}  # worked out again where it is unpickled (see ``derived``)
        return state

    # ---- geometry -------------------------------------------------------------------------------------------
    def node_at(self, node: str) -> float:
        if node in self.ends:
            return self.ends[node].at
        if node in self.joints:
            return self.joints[node].at
        return self.turnouts[node].at

    def track_span(self, track: str) -> tuple[float, float]:
        return self._spans[track]

    @cached_property
    def _spans(self) -> dict[str, tuple[float, float]]:
        """(low, high) position of every track, asked for on every cycle and by every simulation of the station."""
        out = {}
        for tid, (a, b) in self.track_ports.items():
            xa, xb = self.node_at(a.node), self.node_at(b.node)
            out[tid] = (xa, xb) if xa <= xb else (xb, xa)
        return out

    def track_length(self, track: str) -> float:
        return self._track_lengths[track]

    @cached_property
    def _track_lengths(self) -> dict[str, float]:
        out = {}
        for tid, t in self.tracks.items():
            if t.length is not None:
                out[tid] = t.length
            else:
                lo, hi = self.track_span(tid)
                out[tid] = hi - lo
        return out

    def track_low_port(self, track: str) -> Port:
        """The port of ``track`` at its lower position (towards the X end)."""
        a, b = self.track_ports[track]
        return a if self.node_at(a.node) <= self.node_at(b.node) else b

    def track_high_port(self, track: str) -> Port:
        a, b = self.track_ports[track]
        return b if self.node_at(a.node) <= self.node_at(b.node) else a

    def section_length(self, section: str) -> float:
        """All the track of a section: a turnout section counts its main line and its branches."""
        return sum(self.track_length(t) for t in self.section_tracks[section])

    def section_run(self, section: str) -> float:
        """The length of a track circuit's main run: the longest way through the section from one of its ends to
        another, over the tracks' lengths. A plain section is all its track; a turnout section's branches lie beside
        its run (受电分支, 无受电分支), not after it, so they are not added to it."""
        return self.derived(_section_runs)[section]

    def section_span(self, section: str) -> float:
        """How far a section reaches along the line, from its lowest to its highest point: the length of a track
        circuit's main run (a turnout section's branches lie beside it, not after it)."""
        spans = [self.track_span(t) for t in self.section_tracks[section]]
        return max(hi for _, hi in spans) - min(lo for lo, _ in spans)

    def far_end(self, track: str, node_from: str) -> Port:
        """The port of ``track`` at its other end, walking along it from ``node_from``."""
        a, b = self.track_ports[track]
        return b if a.node == node_from else a

    def across(self, joint: str, track: str) -> str:
        """The track on the other side of ``joint`` from ``track``."""
        lo, hi = self.joint_tracks(joint)
        return hi if lo == track else lo

    def joint_tracks(self, joint: str) -> tuple[str, str]:
        """(track on the low side, track on the high side) of a joint."""
        found = self._joint_tracks.get(joint)
        if found is None:
            tracks = [tid for _, tid in self.node_tracks[joint]]
            low = [t for t in tracks if self.track_high_port(t).node == joint]
            high = [t for t in tracks if self.track_low_port(t).node == joint]
            found = self._joint_tracks[joint] = (low[0], high[0])
        return found

    @cached_property
    def _joint_tracks(self) -> dict[str, tuple[str, str]]:
        return {}  # filled as asked (a joint's two tracks never change)

    def joint_sections(self, joint: str) -> tuple[str, str]:
        lo, hi = self.joint_tracks(joint)
        return self.tracks[lo].section, self.tracks[hi].section

    def leg_track(self, turnout: str, leg: str) -> str:
        for lg, tid in self.node_tracks[turnout]:
            if lg == leg:
                return tid
        raise KeyError(f"{turnout}.{leg}")

    def leg_chain(self, turnout: str, leg: str, reach: float = 250.0) -> list[tuple[str, str]]:
        """The tracks from a turnout's ``leg`` away from it across joints only, each as (track, node at its far
        end), up to another turnout, an end, or the first node more than ``reach`` metres from the turnout."""
        out: list[tuple[str, str]] = []
        track, near, at = self.leg_track(turnout, leg), turnout, self.turnouts[turnout].at
        for _ in range(100):
            a, b = self.track_ports[track]
            far = b.node if a.node == near else a.node
            out.append((track, far))
            if far not in self.joints or abs(self.node_at(far) - at) > reach:
                break
            lo, hi = self.joint_tracks(far)
            track, near = (hi if lo == track else lo), far
        return out

    def fouling_legs(self, fp: FoulingPoint) -> dict[str, list[tuple[str, str]]]:
        """A fouling point tied to its turnout: for each leg (normal, reverse), the chain of tracks from that leg up to
        the track the fouling point stands beside (:meth:`leg_chain`); {} for the short form (a bare track)."""
        if fp.turnout is None or fp.tracks is None:
            return {}
        out: dict[str, list[tuple[str, str]]] = {}
        for leg, track in zip(("normal", "reverse"), fp.tracks, strict=True):
            chain = self.leg_chain(fp.turnout, leg)
            ids = [t for t, _ in chain]
            out[leg] = chain[:ids.index(track) + 1] if track in ids else []
        return out

    def diverging_speed_kmh(self, turnout: str, design: DesignRules) -> float:
        """The speed a turnout allows over its diverging track: the file's own figure, else the rule set's typical
        one for its number."""
        t = self.turnouts[turnout]
        return t.diverging_speed_kmh if t.diverging_speed_kmh is not None else design.turnout_speed_kmh(t.number)

    def turnout_points_down(self, turnout: str) -> bool:
        """True when a down movement runs point -> normal/reverse (facing for down trains)."""
        track = self.leg_track(turnout, "point")
        return self.track_high_port(track).node == turnout

    @cached_property
    def dead_zones(self) -> list[DeadZone]:
        out = []
        for j in self.model.joints:
            if j.at2 is not None and j.at2 != j.at:
                out.append(DeadZone(j.id, min(j.at, j.at2), max(j.at, j.at2)))
            elif j.dead_zone_m:
                out.append(DeadZone(j.id, j.at - j.dead_zone_m / 2, j.at + j.dead_zone_m / 2))
        return out

    # ---- signals -------------------------------------------------------------------------------------------
    def signal_entry_track(self, signal: str) -> str:
        """The first track a movement passing ``signal`` enters."""
        sig = self.signals[signal]
        return self.entry_track(sig.at, sig.direction)

    def entry_track(self, node: str, direction: Direction) -> str:
        if node in self.joints:
            lo, hi = self.joint_tracks(node)
            return hi if direction is Direction.down else lo
        # an end: its single track
        return self.node_tracks[node][0][1]

    def signal_rear_track(self, signal: str) -> str | None:
        """The track a movement stands on in rear of ``signal`` (its approach side), if inside the model."""
        sig = self.signals[signal]
        if sig.at in self.joints:
            lo, hi = self.joint_tracks(sig.at)
            return lo if sig.direction is Direction.down else hi
        return None

    def approach_sections(self, signal: str) -> list[str]:
        sig = self.signals[signal]
        if sig.approach:
            return list(sig.approach)
        rear = self.signal_rear_track(signal)
        return [self.tracks[rear].section] if rear else []

    def signals_at(self, node: str) -> list[Signal]:
        return list(self._signals_by_node.get(node, ()))

    @cached_property
    def _signals_by_node(self) -> dict[str, list[Signal]]:
        out: dict[str, list[Signal]] = {}
        for s in self.model.signals:
            out.setdefault(s.at, []).append(s)
        return out

    def link_running(self, link: str) -> str | None:
        """The running direction of an automatic block line: 'inbound' (towards the station, over approach
        sections) or 'outbound' (departure sections); None for a line worked both ways by its block machines (64D)
        or one whose sections do not say."""
        lk = next(x for x in self.model.links if x.id == link)
        if lk.kind.value != "automatic":
            return None
        roles = {self.sections[s].role for s in lk.sections if s in self.sections}
        if SectionRole.approach in roles:
            return "inbound"
        if SectionRole.departure in roles:
            return "outbound"
        return None

    def is_station_track(self, section: str) -> bool:
        return self.sections[section].role is SectionRole.station_track

    def display_name(self) -> str:
        """The name for a heading, control characters written out (:func:`~liansuo.kit.printable.printable`)."""
        return printable(f"{self.model.name.zh} ({self.model.name.en})")

    @cached_property
    def topology(self) -> Topology:
        from liansuo.stations.topology import Topology  # networkx loads on first use: checking a file needs no graph

        return Topology(self)


def _section_runs(station: Station) -> dict[str, float]:
    """Every section's main run (:meth:`Station.section_run`): over the graph of its tracks (nodes the track ends,
    edges weighted by length), the largest of the shortest distances between two of its nodes."""
    import networkx as nx

    out: dict[str, float] = {}
    for section, tracks in station.section_tracks.items():
        g = nx.Graph()
        for t in tracks:
            a, b = station.track_ports[t]
            g.add_edge(a.node, b.node, weight=station.track_length(t))
        out[section] = max((d for _, lengths in nx.all_pairs_dijkstra_path_length(g) for d in lengths.values()),
                           default=0.0)
    return out

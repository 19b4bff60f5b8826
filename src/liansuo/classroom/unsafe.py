"""The rules that judge a trainee's action unsafe (docs/exercises.md, "Unsafe actions").

They are decided from what the exercise put into the world (its setup and fault lines, read here again) and the
station file's geometry (its tracks, turnouts, joints and signals through ``Station.topology``), never from the
interlocking's own functions or its table: a check must not share the code it checks. Only accepted commands are
judged; a refused one changed nothing and is counted as refused.

1. **Guide without cause** (``guide SIGNAL``, 引导). A guide aspect is with cause when something the exercise put in
   stops the signal's normal opening: within the signal's *reach* (every section and turnout from the signal, in its
   direction, up to the next home, starting, route or block signal facing the same way, or the station's boundary;
   narrowed to the sections of the route the guide was given over, when there is one, and the turnouts in them)
   there is a section fault that drops a track relay (``broken-rail``, ``low-ballast``, ``axle-miscount``,
   ``capacitor mode=short``, ``insulation`` at a joint of such a section or at a turnout in it), a turnout fault
   (``no-indication``, ``obstruction``, ``high-resistance``, ``squeezed``, ``insulation``), a section shown occupied
   by the instructor (``occupy``, a train, wheelsets that shunt); or a lamp of the signal itself is dark (``filament``
   with ``which=both``). Otherwise the guide is without cause: the route could have been set and its signal opened
   normally, and a guide aspect passes a train past a red without the interlocking's checks.
2. **Section fault release without cause** (``fault-release SECTION``, 区故解). With cause when a fault the exercise
   injected touches the section (any section fault on it, an insulation fault at one of its joints or turnouts, a
   turnout fault on a turnout standing in it), when the instructor occupied it, or when the section or one meeting it
   at an insulated joint was seen occupied since the exercise began (a train passed over or by it and it was left
   locked: a section a train skipped, as poor shunting or a dead zone lets it, is the textbook case). Otherwise
   without cause: a locked section no train has come near was freed under a route the interlocking still held.
3. **Over a hidden vehicle** (``fault-release``, ``route``, ``shunt``, ``throw``). A vehicle the exercise stood where
   the interlocking cannot see it (wheelsets in a dead zone, or wheelsets or a train on a section with a
   ``poor-shunt`` fault) makes its section unsafe to use: releasing that section, setting a route whose sections
   include it, or throwing a turnout standing in it is unsafe whatever the interlocking allowed (分路不良区段 and the
   dead-zone case of docs/faults.md: the operator confirms clearance on site first).
"""

from __future__ import annotations

import shlex
from collections.abc import Iterable
from dataclasses import dataclass, field

from liansuo.circuits.faults import Fault, parse_fault
from liansuo.stations.schema import SignalKind
from liansuo.stations.station import Station

RED_BAND = frozenset({"broken-rail", "low-ballast", "axle-miscount"})  # section faults that drop the track relay
TURNOUT_FAULTS = frozenset({"no-indication", "obstruction", "high-resistance", "squeezed"})
ROUTE_ENDS = frozenset({SignalKind.home, SignalKind.starting, SignalKind.route, SignalKind.block})


@dataclass
class Planted:
    """What an exercise's lines put into the world: faults, sections the instructor occupied, hidden vehicles."""

    faults: list[Fault] = field(default_factory=list)
    occupied: set[str] = field(default_factory=set)  # sections shown occupied by occupy, trains, shunting wheelsets
    hidden: dict[str, str] = field(default_factory=dict)  # section -> why a vehicle there is unseen


def _words(line: str) -> list[str]:
    text = line.split("#", 1)[0].strip()
    try:
        return shlex.split(text)
    except ValueError:
        return text.split()


def _in_dead_zone(station: Station, track: str, x: float) -> bool:
    return any(z.start <= x <= z.end and track in station.joint_tracks(z.joint) for z in station.dead_zones)


def planted(station: Station, lines: Iterable[str]) -> Planted:
    """Read the exercise's setup and fault lines (as sent, in order) for what they put in."""
    out = Planted()
    axles: list[tuple[str, float]] = []
    trains: list[str] = []
    for line in lines:
        words = _words(line)
        if len(words) >= 3 and words[0] == "fault":
            fault = parse_fault(station, words[1], words[2], words[3:])
            if isinstance(fault, Fault):
                out.faults.append(fault)
        elif len(words) == 2 and words[0] == "occupy" and words[1] in station.sections:
            out.occupied.add(words[1])
        elif len(words) >= 4 and words[0] == "train" and words[2] == "at" and words[3] in station.sections:
            trains.append(words[3])
        elif len(words) >= 3 and words[0] == "axles":
            track = ""
            for w in words[2:]:
                if w in station.tracks:
                    track = w
                    continue
                try:
                    axles.append((track, float(w)))
                except ValueError:
                    continue
    poor = {f.target for f in out.faults if f.kind == "poor-shunt"}
    for track, x in axles:
        if track not in station.tracks:
            continue
        section = station.tracks[track].section
        if _in_dead_zone(station, track, x):
            out.hidden[section] = f"wheelsets stand in the dead zone at {x:g} m on {track}"
        elif section in poor:
            out.hidden[section] = f"wheelsets stand on {section}, which shunts poorly (分路不良)"
        else:
            out.occupied.add(section)
    for section in trains:
        if section in poor:
            out.hidden[section] = f"a train stands on {section}, which shunts poorly (分路不良)"
        else:
            out.occupied.add(section)
    return out


def turnout_sections(station: Station, turnout: str) -> set[str]:
    """The sections of the tracks meeting at a turnout (both members of a crossover pair)."""
    ids = station.pairs.get(turnout, [turnout])
    return {station.tracks[track].section for t in ids for _, track in station.node_tracks.get(t, [])}


def reach(station: Station, signal: str) -> tuple[set[str], set[str]]:
    """The sections and turnouts from ``signal`` in its direction up to the next home, starting, route or block
    signal facing the same way (or the boundary): where a fault stops the signal's normal opening."""
    sig = station.signals[signal]
    stops = {s.at for s in station.signals.values()
             if s.direction is sig.direction and s.id != signal and s.kind in ROUTE_ENDS}
    sections: set[str] = set()
    turnouts: set[str] = set()
    for path in station.topology.walk(sig.at, sig.direction, stop_at=stops, max_length=5000.0):
        sections |= set(path.sections)
        turnouts |= {t for t, _ in path.turnouts}
    return sections, turnouts


def _touches(station: Station, fault: Fault, sections: set[str], turnouts: set[str]) -> bool:
    """The fault stops a track relay or a turnout's indication within these sections and turnouts."""
    if fault.kind in RED_BAND or (fault.kind == "capacitor" and fault.get("mode") == "short"):
        return fault.target in sections
    if fault.kind in TURNOUT_FAULTS:
        return fault.target in turnouts
    if fault.kind == "insulation":
        if fault.target in station.turnouts:
            return fault.target in turnouts or bool(turnout_sections(station, fault.target) & sections)
        return bool(set(station.joint_sections(fault.target)) & sections)
    return False


def guide_cause(station: Station, plant: Planted, signal: str, route: Iterable[str] | None = None) -> str:
    """Why a guide aspect on ``signal`` is justified, or '' when it is without cause (rule 1). ``route``: the
    sections of the route the guide was given over; the reach is narrowed to them (and the turnouts standing in
    them), so a fault on another branch is no cause. Without a route (guide total lock) the whole reach counts."""
    if signal not in station.signals:
        return ""
    sections, turnouts = reach(station, signal)
    if route is not None:
        sections &= set(route)
        turnouts = {t for t in turnouts if turnout_sections(station, t) & sections}
    for fault in plant.faults:
        if fault.kind == "filament" and fault.target == signal and fault.get("which") == "both":
            return f"the {fault.get('lamp')} lamp of {signal} is dark ({fault.describe()})"
        if _touches(station, fault, sections, turnouts):
            return f"{fault.describe()} stops {signal}'s normal opening"
    shown = sorted(plant.occupied & sections)
    return f"{', '.join(shown)} shown occupied beyond {signal}" if shown else ""


def fault_release_cause(station: Station, plant: Planted, section: str, seen_occupied: set[str]) -> str:
    """Why a section fault release of ``section`` is justified, or '' when it is without cause (rule 2)."""
    for fault in plant.faults:
        if fault.target == section and fault.kind not in TURNOUT_FAULTS and fault.kind != "insulation":
            return f"{fault.describe()} is in it"
        in_section = {section}
        turnouts = {t for t in station.turnouts if section in turnout_sections(station, t)}
        if fault.kind in TURNOUT_FAULTS | {"insulation"} and _touches(station, fault, in_section, turnouts):
            return f"{fault.describe()} touches it"
    if section in plant.occupied:
        return "the instructor showed it occupied"
    if section in seen_occupied:
        return "a train passed and it was left locked"
    passed = sorted(neighbours(station, section) & seen_occupied)
    if passed:
        return f"a train passed by it ({', '.join(passed)} occupied) and it was left locked"
    return ""


def neighbours(station: Station, section: str) -> set[str]:
    """The sections that meet ``section`` at an insulated joint."""
    out: set[str] = set()
    for joint in station.joints:
        pair = set(station.joint_sections(joint))
        if section in pair:
            out |= pair - {section}
    return out


def hidden_vehicle(station: Station, plant: Planted, sections: Iterable[str]) -> str:
    """Rule 3: why using these sections is unsafe ('' when no hidden vehicle stands in them)."""
    for s in sections:
        if s in plant.hidden:
            return f"{plant.hidden[s]}: the interlocking cannot see it"
    return ""

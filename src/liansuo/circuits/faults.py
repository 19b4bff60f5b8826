"""Fault kinds an instructor can inject (``fault KIND TARGET [key=value ...]`` / ``repair KIND TARGET``).

Each kind names what it is applied to and which parameters it takes, with their defaults. ``docs/faults.md`` gives
each fault's real-world cause, what the equipment does, what the interlocking and the console show, and how a
maintainer finds it.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from liansuo.circuits.physical import ballast_problem
from liansuo.stations import limits
from liansuo.stations.limits import Limit
from liansuo.stations.station import Station

TargetKind = str  # "section", "joint-or-turnout", "signal", "turnout", "platform"


@dataclass(frozen=True)
class FaultKind:
    name: str
    target: TargetKind
    params: dict[str, str | float]  # name -> default
    summary: str
    choices: dict[str, tuple[str, ...]] = field(default_factory=dict)


KINDS: dict[str, FaultKind] = {k.name: k for k in [
    FaultKind("broken-rail", "section", {"at": -1.0}, "a broken rail (断轨): the track relay drops, red band"),
    FaultKind("poor-shunt", "section", {"ohm": 1.0},
              "poor shunting (分路不良): wheelsets shunt through this resistance"),
    FaultKind("low-ballast", "section", {"ohm_km": 0.3}, "low ballast resistance (道床漏泄): the track relay may drop"),
    FaultKind("insulation", "joint-or-turnout", {}, "failed insulation at an insulated joint or at a switch machine"),
    FaultKind("capacitor", "section", {"n": 1.0, "mode": "open"}, "a ZPW-2000A compensation capacitor fails",
              {"mode": ("open", "half", "short")}),
    FaultKind("axle-miscount", "section", {},
              "an axle counter miscounts (计轴故障): the section shows occupied until the count is reset (计轴复零)"),
    FaultKind("filament", "signal", {"lamp": "", "which": "both"}, "lamp filament broken (灯丝断丝)",
              {"which": ("main", "backup", "both")}),
    FaultKind("flasher", "signal", {"mode": "bad-contact"}, "USU flasher fault: bad SNJ contact",
              {"mode": ("bad-contact",)}),
    FaultKind("no-indication", "turnout", {}, "turnout indication circuit broken: DBJ and FBJ down"),
    FaultKind("obstruction", "turnout", {"mm": 4.0}, "an obstruction between switch rail and stock rail"),
    FaultKind("high-resistance", "turnout", {"N": 4000.0}, "switching resistance above the rated force: clutch slips"),
    FaultKind("squeezed", "turnout", {}, "turnout trailed through in the wrong position (挤岔)"),
    FaultKind("psd-stuck", "platform", {}, "a screen door stuck open: doors not closed and locked"),
    FaultKind("psd-no-close", "platform", {}, "close relay GMJ failed: doors do not close"),
    FaultKind("psd-no-open", "platform", {}, "platform occupancy (ZCKJ) disturbed: doors do not open"),
    FaultKind("psd-bypass", "platform", {}, "interlock bypass switch on (PDQCJ): the signal ignores the doors"),
]}


@dataclass(frozen=True)
class Fault:
    kind: str
    target: str
    params: tuple[tuple[str, str | float], ...] = ()

    def get(self, name: str) -> str | float:
        return dict(self.params)[name]

    def describe(self) -> str:
        extra = " ".join(f"{k}={v:g}" if isinstance(v, float) else f"{k}={v}" for k, v in self.params)
        return f"{self.kind} {self.target}" + (f" {extra}" if extra else "")


def _target_error(kind: FaultKind, target: str, station: Station) -> str:
    t = kind.target
    if t == "section" and target not in station.sections:
        return f"there is no section '{target}'"
    if t == "turnout" and target not in station.turnouts:
        return f"there is no turnout '{target}'"
    if t == "joint-or-turnout" and target not in station.joints and target not in station.turnouts:
        return f"'{target}' is neither an insulated joint nor a turnout"
    if t == "signal" and target not in station.signals:
        return f"there is no signal '{target}'"
    if t == "platform":
        pid, _, side = target.partition(":")
        p = next((p for p in station.model.platforms if p.id == pid), None)
        if p is None or not p.screen_doors:
            return f"there is no platform with screen doors '{pid}'"
        if side and side not in {d.side.value for d in p.screen_doors}:
            return f"platform {pid} has no screen doors on the {side} side"
    return ""


# the range of each numeric parameter (stations/limits.py says why); a broken rail's place is within its section
PARAM_LIMITS: dict[str, Limit] = {
    "ohm": limits.POOR_SHUNT,
    "ohm_km": limits.BALLAST,
    "n": limits.CAPACITOR_NUMBER,
    "mm": limits.OBSTRUCTION,
    "N": limits.SWITCH_FORCE,
}


def _param_limit(kind: str, key: str, target: str, station: Station) -> Limit:
    if kind == "broken-rail" and key == "at":  # metres from the section's lower end
        return Limit("a place in the section", "m", 0.0, station.section_span(target),
                     f"section {target} runs that far from its lower end")
    if kind == "capacitor" and key == "n":
        count = _capacitors(station, target)
        return Limit("a capacitor's number", "", 1.0, float(count), f"section {target} has {count}", whole=True)
    return PARAM_LIMITS[key]


def _capacitors(station: Station, section: str) -> int:
    """How many compensation capacitors the live circuit of a ZPW-2000A section has (built on its span:
    circuits/trackcircuits.py)."""
    from liansuo.circuits.zpw.model import capacitor_positions  # numpy: only for a capacitor fault

    return len(capacitor_positions(station, section, length_m=max(station.section_span(section), 1.0)))


def parse_fault(station: Station, kind_name: str, target: str, args: list[str]) -> Fault | str:
    """A :class:`Fault`, or the reason it cannot be injected."""
    kind = KINDS.get(kind_name)
    if kind is None:
        return f"unknown fault kind '{kind_name}'; kinds: {', '.join(KINDS)}"
    why = _target_error(kind, target, station)
    if why:
        return f"fault {kind_name}: {why}"
    if kind_name == "capacitor" and station.sections[target].type.value != "zpw2000a":
        return f"fault capacitor: section {target} is not a ZPW-2000A section"
    if kind_name == "capacitor" and not _capacitors(station, target):
        return f"fault capacitor: section {target} has no compensation capacitors"
    params: dict[str, str | float] = dict(kind.params)
    for arg in args:
        key, eq, value = arg.partition("=")
        if not eq or key not in kind.params:
            keys = ", ".join(kind.params) or "none"
            return f"fault {kind_name}: unknown parameter '{arg}' (parameters: {keys})"
        default = kind.params[key]
        if isinstance(default, float):
            try:
                number = float(value)
            except ValueError:
                return f"fault {kind_name}: {key} must be a number, not '{value}'"
            if not math.isfinite(number):
                return f"fault {kind_name}: {key} must be a finite number, not '{value}'"
            if key == "ohm_km" and (why := ballast_problem(number, infinite_ok=False)):
                return (f"fault {kind_name}: ohm_km {why}, not '{value}' (wet or dirty ballast is a few tenths of "
                        "an ohm*km, e.g. ohm_km=0.3)")
            why = _param_limit(kind_name, key, target, station).problem(key, number, value)
            if why:
                return f"fault {kind_name}: {why}"
            params[key] = number
        else:
            if key in kind.choices and value not in kind.choices[key]:
                return f"fault {kind_name}: {key} must be one of {', '.join(kind.choices[key])}"
            params[key] = value
    if kind_name == "filament":
        lamps = [lamp.value for lamp in station.signals[target].lamps]
        if params["lamp"] not in lamps:
            return f"fault filament: name the lamp with lamp=..., one of {', '.join(lamps)}"
    if kind_name == "flasher" and not station.signals[target].usu:
        return f"fault flasher: signal {target} has no USU flasher"
    if kind_name == "axle-miscount" and station.sections[target].type.value != "axle_counter":
        return f"fault axle-miscount: section {target} is a track circuit, not counted by axle counters"
    return Fault(kind_name, target, tuple(sorted(params.items())))

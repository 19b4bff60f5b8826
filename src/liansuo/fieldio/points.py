"""The point map of a station's field I/O: which Modbus coil, discrete input or register is which relay
(docs/field-mode.md).

One YAML file per station, validated like every file liansuo reads (``FILE:LINE:COLUMN`` errors, ``liansuo schema
points``) and then checked against the station (:func:`check`): every point names an element the station has and a
relay that element has, no address is used twice, and every element is mapped whole (a turnout's two indications
and two drives, every lamp of a signal with its proving). The elements in the map are under field control after
the change-over; every other element stays simulated. ``liansuo field-map STATION`` writes the whole station's map,
a start to edit.

Tables, as the Modbus data model has them:

- discrete inputs (read by the interlocking): GJ per section, DBJ and FBJ per turnout, DJ per signal lamp, SNJ
  (flash check) per signal with a flasher, DSBJ (filament alarm) per signal, PDKJ and PDQCJ per platform door side;
- coils (driven by the interlocking): ``lamp`` per signal lamp, ``flasher`` per signal with a flasher, DCJ and FCJ
  (drive to normal, to reverse) per turnout, ZCKJ, KMJ and GMJ per platform door side, ``reset`` (计轴复零) per
  axle-counter section;
- holding registers: the interlocking's heartbeat, and the low-frequency code of each coded section (``codes``,
  with ``code_values``);
- input registers: the echo, the heartbeat the field last acted on.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Mapping
from dataclasses import dataclass
from pathlib import Path
from typing import Literal

import yaml
from pydantic import BaseModel, ConfigDict, Field

from liansuo.circuits.field import field_plan
from liansuo.kit.source import Diagnostic, Source, StationError, read_text, read_yaml
from liansuo.rules import RuleSet
from liansuo.simulation.fieldlink import Elements
from liansuo.stations.station import Station
from liansuo.stations.validation import validate

InputRelay = Literal["GJ", "DBJ", "FBJ", "DJ", "SNJ", "DSBJ", "PDKJ", "PDQCJ"]
OutputRelay = Literal["lamp", "flasher", "DCJ", "FCJ", "ZCKJ", "KMJ", "GMJ", "reset"]
Address = Field(ge=0, le=65535, description="the address in its table, from 0")

# what each relay belongs to
_KIND = {"GJ": "section", "reset": "section", "DBJ": "turnout", "FBJ": "turnout", "DCJ": "turnout",
         "FCJ": "turnout", "DJ": "signal", "lamp": "signal", "SNJ": "signal", "flasher": "signal",
         "DSBJ": "signal", "PDKJ": "doors", "PDQCJ": "doors", "ZCKJ": "doors", "KMJ": "doors", "GMJ": "doors"}
MAX_BITS = 2000  # discrete inputs read in one request (the Modbus limit)
MAX_COILS = 1968  # coils written in one request
MAX_REGISTERS = 123  # registers written in one request


class _Point(BaseModel):
    """Where a relay of an element is wired: its address in its table; the relay itself is the table's own."""

    model_config = ConfigDict(extra="forbid")
    at: int = Address
    element: str = Field(min_length=1, description="the section, turnout, signal or platform:side")


class InputPoint(_Point):
    """A discrete input: a relay contact the interlocking reads."""

    relay: InputRelay
    lamp: str | None = Field(None, description="DJ only: the lamp it proves (H, L, U, U2, B, A, L2)")


class OutputPoint(_Point):
    """A coil: a relay the interlocking drives."""

    relay: OutputRelay
    lamp: str | None = Field(None, description="lamp only: the lamp it lights")


class CodePoint(BaseModel):
    """A holding register: the low-frequency cab code sent on a coded section (0: none)."""

    model_config = ConfigDict(extra="forbid")
    at: int = Address
    section: str = Field(min_length=1)


class PointMapFile(BaseModel):
    """A station's field I/O point map (docs/field-mode.md)."""

    model_config = ConfigDict(extra="forbid")
    station: str = Field(min_length=1, description="the id of the station it wires")
    unit: int = Field(1, ge=0, le=247, description="the Modbus unit (device) id")
    heartbeat: int = Field(0, ge=0, le=65535, description="the holding register the interlocking counts each cycle")
    echo: int = Field(0, ge=0, le=65535, description="the input register where the field echoes the heartbeat it "
                                                     "last acted on")
    inputs: list[InputPoint] = Field(description="discrete inputs")
    outputs: list[OutputPoint] = Field(description="coils")
    codes: list[CodePoint] = Field(default_factory=list, description="holding registers of the cab codes")
    code_values: dict[str, int] = Field(default_factory=dict,
                                        description="each low-frequency code's register value (0 is no code)")


def point_name(element: str, relay: str, lamp: str | None = None) -> str:
    """'1DG GJ', 'X DJ U': a point as an alarm names it."""
    return f"{element} {relay}" + (f" {lamp}" if lamp else "")


@dataclass(frozen=True)
class PointMap:
    """A checked point map, with its tables' extents."""

    file: PointMapFile
    elements: Elements

    @property
    def coil_count(self) -> int:
        return max((p.at for p in self.file.outputs), default=-1) + 1

    @property
    def input_count(self) -> int:
        return max((p.at for p in self.file.inputs), default=-1) + 1

    @property
    def register_span(self) -> tuple[int, int]:
        """(first, count) of the holding registers the codes take, (0, 0) without codes."""
        if not self.file.codes:
            return 0, 0
        lo = min(p.at for p in self.file.codes)
        return lo, max(p.at for p in self.file.codes) - lo + 1

    def input_names(self, elements: Elements) -> list[str]:
        """The input points of ``elements``, named, in address order."""
        keys = elements.tracks | elements.turnouts | elements.signals | elements.doors
        return [point_name(p.element, p.relay, p.lamp) for p in sorted(self.file.inputs, key=lambda p: p.at)
                if p.element in keys]


# ---- a station's whole map ---------------------------------------------------------------------------------------
def generate(station: Station, rules: RuleSet) -> PointMapFile:
    """Every element of ``station`` mapped, in the station's order, the addresses counted from 0 in each table."""
    plan = field_plan(station, rules)
    flashers = {sig for sig, _ in plan.flashers}
    counters = [s for s, spec in plan.circuits.items() if spec.model is None]
    inputs: list[tuple[str, str, str | None]] = []
    outputs: list[tuple[str, str, str | None]] = []
    inputs += [(s, "GJ", None) for s in station.sections]
    for t in station.turnouts:
        inputs += [(t, "DBJ", None), (t, "FBJ", None)]
        outputs += [(t, "DCJ", None), (t, "FCJ", None)]
    for sig, lamps in plan.lamps.items():
        inputs += [(sig, "DJ", lamp) for lamp in lamps]
        outputs += [(sig, "lamp", lamp) for lamp in lamps]
        if sig in flashers:
            inputs.append((sig, "SNJ", None))
            outputs.append((sig, "flasher", None))
        inputs.append((sig, "DSBJ", None))
    for key in plan.doors:
        inputs += [(key, "PDKJ", None), (key, "PDQCJ", None)]
        outputs += [(key, "ZCKJ", None), (key, "KMJ", None), (key, "GMJ", None)]
    outputs += [(s, "reset", None) for s in counters]
    coded = [s.id for s in station.model.sections if s.coded]
    return PointMapFile(
        station=station.id,
        inputs=[InputPoint(at=i, element=e, relay=r, lamp=lamp) for i, (e, r, lamp) in enumerate(inputs)],
        outputs=[OutputPoint(at=i, element=e, relay=r, lamp=lamp) for i, (e, r, lamp) in enumerate(outputs)],
        codes=[CodePoint(at=1 + i, section=s) for i, s in enumerate(coded)],
        code_values={code: i + 1 for i, code in enumerate(_codes(rules))} if coded else {})


def _codes(rules: RuleSet) -> list[str]:
    """The low-frequency codes the rules send, in a stable order."""
    return sorted({c for c in rules.aspects.cab_codes.values() if c})


def dump(pm: PointMapFile, schema: str = "") -> str:
    """The map as YAML, one point to a line; ``schema``: the path of the JSON Schema for an editor's modeline."""
    def row(p: BaseModel) -> str:
        fields = p.model_dump(exclude_none=True)
        return "  - {" + ", ".join(f"{k}: {_scalar(v)}" for k, v in fields.items()) + "}"

    lines = [f"# yaml-language-server: $schema={schema}"] if schema else []
    lines += [f"# liansuo field I/O point map of station {pm.station} (docs/field-mode.md; liansuo schema points)",
             f"station: {_scalar(pm.station)}", f"unit: {pm.unit}",
             f"heartbeat: {pm.heartbeat}  # holding register: the interlocking's cycle count",
             f"echo: {pm.echo}  # input register: the count the field last acted on",
             "inputs:  # discrete inputs, read by the interlocking", *[row(p) for p in pm.inputs],
             "outputs:  # coils, driven by the interlocking", *[row(p) for p in pm.outputs]]
    if pm.codes:
        lines += ["codes:  # holding registers: each coded section's low-frequency code",
                  *[row(p) for p in pm.codes],
                  "code_values: {" + ", ".join(f"{_scalar(k)}: {v}" for k, v in pm.code_values.items()) + "}"]
    else:
        lines.append("codes: []")
    return "\n".join(lines) + "\n"


def _scalar(value: object) -> str:
    """A value as YAML writes it on one line (quoted where a plain word would read as something else)."""
    text = yaml.safe_dump(value, default_flow_style=True, width=10_000).strip()
    return text.removesuffix("\n...").strip()


# ---- reading and checking ------------------------------------------------------------------------------------------
def read(path: Path) -> tuple[PointMapFile, Source]:
    """The point map in ``path`` as its schema has it, with the places of its values; :class:`StationError` for a
    file that cannot be read or does not follow the schema."""
    text = read_text(path, "give the path of a point map ('liansuo field-map STATION' writes one)")
    src = read_yaml(text, str(path))
    errors: list[Diagnostic] = []
    pm = validate(src, PointMapFile, errors, "points", "'liansuo docs field-mode'")
    if pm is None:
        raise StationError(errors)
    return pm, src


def load(path: Path, station: Station, rules: RuleSet) -> PointMap:
    """The point map in ``path``, checked against ``station``; :class:`StationError` with every problem."""
    pm, src = read(path)
    problems = check(pm, src, station, rules)
    if any(d.severity == "error" for d in problems):
        raise StationError(problems)
    return PointMap(pm, elements_of(pm))


def from_station(station: Station, rules: RuleSet) -> PointMap:
    """The whole station's map, as ``liansuo field-map`` writes it."""
    pm = generate(station, rules)
    return PointMap(pm, elements_of(pm))


def elements_of(pm: PointMapFile) -> Elements:
    points = [(p.element, p.relay) for p in pm.inputs]
    return Elements(frozenset(e for e, r in points if _KIND[r] == "section"),
                    frozenset(e for e, r in points if _KIND[r] == "turnout"),
                    frozenset(e for e, r in points if _KIND[r] == "signal"),
                    frozenset(e for e, r in points if _KIND[r] == "doors"))


def check(pm: PointMapFile, src: Source, station: Station, rules: RuleSet) -> list[Diagnostic]:
    """Every problem of ``pm`` against ``station``, at its place in the file."""
    out: list[Diagnostic] = []
    plan = field_plan(station, rules)
    doors, flashers = set(plan.doors), {sig for sig, _ in plan.flashers}
    counters = {s for s, spec in plan.circuits.items() if spec.model is None}
    if pm.station != station.id:
        out.append(src.diagnostic(("station",), f"the map is for station '{pm.station}', not '{station.id}'",
                                  "give the map written for this station"))
    have = {"section": set(station.sections), "turnout": set(station.turnouts), "signal": set(station.signals),
            "doors": doors}
    tables: list[tuple[str, Iterable[InputPoint | OutputPoint]]] = [("inputs", pm.inputs), ("outputs", pm.outputs)]
    seen: dict[tuple[str, str, str | None], tuple[str, int]] = {}
    for table, points in tables:
        used: dict[int, int] = {}
        for i, p in enumerate(points):
            loc = (table, i)
            kind = _KIND[p.relay]
            name = point_name(p.element, p.relay, p.lamp)
            if p.at in used:
                out.append(src.diagnostic((*loc, "at"), f"{table} address {p.at} is used twice ({name}, and "
                                                        f"the point on line {src.mark((table, used[p.at])).line})",
                                          "give every point its own address"))
            used.setdefault(p.at, i)
            if p.element not in have[kind]:
                what = "platform door side (platform:side)" if kind == "doors" else kind
                out.append(src.diagnostic((*loc, "element"), f"{p.relay} is the relay of a {what}, and "
                                                             f"{station.id} has no {what} '{p.element}'",
                                          "check the element's id against the station file"))
                continue
            why = _relay_problem(p, kind, plan.lamps, flashers, counters)
            if why:
                out.append(src.diagnostic(loc, why, "'liansuo docs field-mode' lists each element's relays"))
                continue
            key = (p.element, p.relay, p.lamp)
            if key in seen:
                out.append(src.diagnostic(loc, f"{name} is mapped twice (also on line {src.mark(seen[key]).line})",
                                          "keep one"))
            seen[key] = (table, i)
    out += _whole(pm, src, station, plan.lamps, flashers, counters, set(seen))
    out += _codes_problems(pm, src, station, rules)
    return sorted(out, key=lambda d: (d.line, d.column))


def _relay_problem(p: InputPoint | OutputPoint, kind: str, lamps: Mapping[str, tuple[str, ...]],
                   flashers: set[str], counters: set[str]) -> str:
    if p.relay in ("DJ", "lamp"):
        own = lamps[p.element]
        if p.lamp is None:
            return f"{point_name(p.element, p.relay)} names no lamp: add 'lamp:' (one of {', '.join(own)})"
        if p.lamp not in own:
            return f"signal {p.element} has no lamp {p.lamp} (its lamps: {', '.join(own)})"
        return ""
    if p.lamp is not None:
        return f"only DJ and lamp points name a lamp; {p.relay} does not"
    if p.relay in ("SNJ", "flasher") and p.element not in flashers:
        return f"signal {p.element} has no flasher (it never shows the flashing aspect)"
    if p.relay == "reset" and p.element not in counters:
        return f"section {p.element} has no axle counter to reset"
    return ""


def _needed(kind: str, element: str, lamps: Mapping[str, tuple[str, ...]], flashers: set[str],
            counters: set[str]) -> list[tuple[str, str, str | None]]:
    """Every point an element needs to be under field control."""
    plain: tuple[str, ...]
    lit: list[tuple[str, str, str | None]] = []
    if kind == "section":
        plain = ("GJ", "reset") if element in counters else ("GJ",)
    elif kind == "turnout":
        plain = ("DBJ", "FBJ", "DCJ", "FCJ")
    elif kind == "signal":
        plain = ("DSBJ", "SNJ", "flasher") if element in flashers else ("DSBJ",)
        lit = [(element, r, lamp) for lamp in lamps[element] for r in ("DJ", "lamp")]
    else:
        plain = ("PDKJ", "PDQCJ", "ZCKJ", "KMJ", "GMJ")
    return lit + [(element, r, None) for r in plain]


def _whole(pm: PointMapFile, src: Source, station: Station, lamps: Mapping[str, tuple[str, ...]],
           flashers: set[str], counters: set[str], seen: set[tuple[str, str, str | None]]) -> list[Diagnostic]:
    """An element mapped in part: each missing point, at the element's first point."""
    out: list[Diagnostic] = []
    first: dict[str, tuple[str, int]] = {}
    for i, p in enumerate(pm.inputs):
        first.setdefault(p.element, ("inputs", i))
    for i, o in enumerate(pm.outputs):
        first.setdefault(o.element, ("outputs", i))
    mapped = {(e, _KIND[r]) for e, r, _ in seen}
    for element, kind in sorted(mapped):
        missing = [k for k in _needed(kind, element, lamps, flashers, counters) if k not in seen]
        if missing:
            names = ", ".join(point_name(*k) for k in missing)
            out.append(src.diagnostic(first[element], f"{kind} {element} is mapped in part: {names} missing",
                                      "map all of an element's points, or none of them to keep it simulated"))
    return out


def _codes_problems(pm: PointMapFile, src: Source, station: Station, rules: RuleSet) -> list[Diagnostic]:
    out: list[Diagnostic] = []
    coded = {s.id for s in station.model.sections if s.coded}
    tracks = {p.element for p in pm.inputs if p.relay == "GJ"}
    used: dict[int, int] = {}
    for i, p in enumerate(pm.codes):
        if p.section not in coded:
            out.append(src.diagnostic(("codes", i, "section"), f"section {p.section} is not a coded section",
                                      "only sections with 'coded: true' carry cab codes"))
        elif p.section not in tracks:
            out.append(src.diagnostic(("codes", i, "section"), f"section {p.section} has a code register but no "
                                                               "GJ input", "map its GJ too, or drop its code"))
        if p.at in used or p.at == pm.heartbeat:
            out.append(src.diagnostic(("codes", i, "at"), f"holding register {p.at} is used twice",
                                      "the heartbeat and every code need a register of their own"))
        used.setdefault(p.at, i)
    for s in sorted(coded & tracks - {p.section for p in pm.codes}):
        out.append(src.diagnostic(("codes",), f"coded section {s} is under field control but has no code register",
                                  "add it to 'codes', or its trains read no cab code", severity="warning"))
    if pm.codes:
        values = pm.code_values
        for code in _codes(rules):
            if code not in values:
                out.append(src.diagnostic(("code_values",), f"code {code} has no register value",
                                          "give every code of the rules a value from 1 up"))
        counts = Counter(values.values())
        for code, v in values.items():
            if v == 0 or counts[v] > 1 or not 0 < v < 65536:
                out.append(src.diagnostic(("code_values", code), f"code {code}'s value {v} is 0, used twice or "
                                                                 "past 65535", "give each code its own value "
                                                                               "from 1 to 65535"))
    return out

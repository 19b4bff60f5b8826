"""Station files: the bundled ones and the documented example load; every class of broken file is refused with
``FILE:LINE:COLUMN``, what is wrong and a hint; design-rule warnings state the measured figure and the limit; random
damage to a file never escapes as anything but :class:`StationError`."""

from __future__ import annotations

import copy
import re
from dataclasses import dataclass
from pathlib import Path
from typing import Any

import pytest
import yaml
from conftest import edit, position
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from pydantic import BaseModel

from liansuo.kit.source import Diagnostic, StationError
from liansuo.stations import schema
from liansuo.stations import values as value_types
from liansuo.stations.library import bundled
from liansuo.stations.loader import load, load_text
from liansuo.stations.rules import design_rules, min_coded_length
from liansuo.stations.station import Station

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
MINIMAL = PKG / "examples" / "stations" / "minimal.yaml"
DOC = ROOT / "docs" / "station-format.md"
GLOSSARY = ROOT / "docs" / "glossary.md"
BASE = MINIMAL.read_text(encoding="utf-8")
JIAOPEI = (PKG / "stations" / "library" / "jiaopei.yaml").read_text(encoding="utf-8")


# ---- helpers (edit, position: conftest.py) ------------------------------------------------------------------
def refuse(tmp_path: Path, text: str, name: str = "broken.yaml") -> tuple[StationError, Path]:
    path = tmp_path / name
    path.write_text(text, encoding="utf-8")
    with pytest.raises(StationError) as info:
        load(path)
    return info.value, path


def find(exc: StationError, fragment: str) -> Diagnostic:
    found = [d for d in exc.diagnostics if fragment in d.message]
    assert found, f"no diagnostic mentions {fragment!r}; got:\n{exc}"
    return found[0]


def warnings_of(text: str) -> list[Diagnostic]:
    station = load_text(text, "w.yaml")
    assert all(w.severity == "warning" for w in station.warnings)
    return station.warnings


# ---- the files that must load ----------------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(bundled()))
def test_bundled_station_loads(name: str) -> None:
    station = load(name)
    assert isinstance(station, Station)
    assert station.id == name
    for w in station.warnings:  # some stations keep a known defect on purpose (e.g. long crossover dead zones)
        assert w.severity == "warning" and w.file == str(bundled()[name]) and w.line >= 1 and w.hint


def test_jiaopei_is_bundled() -> None:
    assert "jiaopei" in bundled()
    station = load("jiaopei")
    assert len(station.model.turnouts) == 7
    assert sorted(station.pairs) == ["1/3", "2/4"]
    assert station.warnings == []


def test_minimal_example_loads() -> None:
    station = load(MINIMAL)
    assert station.id == "minimal"
    assert station.warnings == []
    assert len(station.model.turnouts) == 1
    assert sorted(station.signals) == ["X", "XI"]
    assert station.section_length("IG") == 600
    assert [dz.joint for dz in station.dead_zones] == ["J-X"]


def test_kilometre_posts_are_metres() -> None:
    station = load_text(edit(BASE, ("{id: B-3, kind: buffer, at: 600}", "{id: B-3, kind: buffer, at: K0+600.0}")))
    assert station.ends["B-3"].at == 600.0
    assert value_types.parse_km("K12+345.6") == pytest.approx(12345.6)


def test_integer_ids_are_taken_as_text() -> None:
    station = load_text(edit(BASE, ('{id: "1", at: 250', "{id: 1, at: 250")))
    assert "1" in station.turnouts


# ---- every class of error ----------------------------------------------------------------------------------------
S3 = "  - {id: 3G, type: 25hz, role: spur}\n"
T3G = "  - {id: t-3G, from: J-13, to: B-3, section: 3G, row: 1}\n"
JP_T5 = '{id: "5", at: 540, number: 9, machine: ZD6}'
JP_T7 = '{id: "7", at: 330, number: 9, machine: ZD6}'


@dataclass(frozen=True)
class Broken:
    """A broken station file; the diagnostic mentioning ``what`` must stand where ``at`` starts in the text."""

    name: str
    text: str
    what: str  # a fragment of the expected message
    at: str | None  # text whose first character is where the error is reported; None: line 1 column 1
    also: tuple[str, ...] = ()  # more fragments of the message or its hint


BROKEN = [
    # --- YAML itself
    Broken("yaml syntax: unclosed flow mapping", edit(BASE, ("at: 0}\n", "at: 0\n")), "YAML syntax error",
           "{id: SB, kind", ("did not find expected", "line 16")),
    Broken("yaml syntax: colon in a value", edit(BASE, ("line: double\n", "line: double: single\n")),
           "YAML syntax error", "double^: single", ("mapping values are not allowed",)),
    Broken("yaml syntax: tab indentation", edit(BASE, ("  - {id: IAG", "\t- {id: IAG")), "YAML syntax error",
           "\t- {id: IAG", ("tab", "spaces")),
    Broken("yaml syntax: unclosed quote", edit(BASE, ("{zh: 最小站", '{zh: "最小站')), "YAML syntax error",
           '"^1", at: 250', ("flow mapping at line 10",)),
    Broken("empty file", "", "the file is empty", None, ("id:",)),
    Broken("file of comments only", "# nothing here\n", "the file is empty", None),
    Broken("not a mapping", "- a\n- b\n", "a station file is a mapping", None),
    Broken("duplicate key", edit(BASE, ("{id: IAG, type: 25hz,", "{id: IAG, type: 25hz, type: zpw2000a,")),
           "key 'type' appears twice", "type: zpw2000a", ("remove or rename",)),
    Broken("key that is not a name", edit(BASE, ("line: double\n", "line: double\n[a, b]: 1\n")),
           "a key must be a name", "[a, b]: 1"),
    # --- schema (pydantic)
    Broken("unknown key", edit(BASE, ('{id: "1", at: 250,', '{id: "1", at: 250, colour: red,')),
           "unknown key 'colour'", "colour: red", ("spelling",)),
    Broken("unknown top-level key", edit(BASE, ("line_speed_kmh: 80", "line_speed: 80")),
           "unknown key 'line_speed'", "line_speed: 80"),
    Broken("unknown key given as a number", edit(BASE, ("{id: IAG, type: 25hz,", "{id: IAG, type: 25hz, 12: x,")),
           "unknown key '12'", "12: x"),
    Broken("missing key", edit(BASE, ("number: 12, machine: ZD6}", "number: 12}")), "missing key 'machine'",
           '{id: "1", at: 250, number: 12}', ("add this key",)),
    Broken("missing track end", edit(BASE, ("{id: t-IG, from: J-1I, to: J-XI,", "{id: t-IG, from: J-1I,")),
           "missing key 'to'", "{id: t-IG, from: J-1I,"),
    Broken("wrong type: text for a whole number", edit(BASE, ("number: 12", "number: twelve")),
           "valid integer", "twelve", ("turnouts.0.number", "'twelve'", "whole number")),
    Broken("wrong type: fraction for a whole number", edit(BASE, ("number: 12", "number: 12.5")),
           "integer", "12.5", ("whole number",)),
    Broken("wrong type: text for a list", edit(BASE, ("buttons: [train]}", "buttons: train}")),
           "valid array", "train}", ("signals.0.buttons", "write a list")),
    Broken("wrong type: text for a mapping", edit(BASE, ("name: {zh: 最小站, en: Minimal station}", "name: Minimal")),
           "name", "Minimal", ("mapping",)),
    Broken("wrong type: true for a position", edit(BASE, ("{id: FP1, track: t-1b, at: 290}",
                                                          "{id: FP1, track: t-1b, at: true}")),
           "not true/false", "t-1b, at: ^true}"),
    Broken("zero length", edit(BASE, ("to: 1.point, section: 1DG}", "to: 1.point, section: 1DG, length: 0}")),
           "greater than 0", "1DG, length: ^0}", ("tracks.1.length",)),
    Broken("not a finite number", edit(BASE, ("{id: J-13, at: 310}", "{id: J-13, at: .nan}")),
           "finite number", ".nan}", ("not .nan",)),
    Broken("bad enum value", edit(BASE, ("machine: ZD6", "machine: ZD7")), "'ZD6', 'ZDJ9' or 'S700K'", "ZD7",
           ("'ZD7'", "one of the values")),
    Broken("bad enum value: direction", edit(BASE, ("at: J-X, direction: down", "at: J-X, direction: sideways")),
           "'down' or 'up'", "sideways"),
    Broken("bad id", edit(BASE, ("{id: J-13, at: 310}", "{id: 'J 13', at: 310}")), "is not a valid id",
           "'J 13'", ("letters, digits",)),
    Broken("bad km position", edit(BASE, ("{id: B-3, kind: buffer, at: 600}", "{id: B-3, kind: buffer, at: K0+6x0}")),
           "is not a position", "K0+6x0", ("K12+345.6",)),
    Broken("bad carrier", edit(BASE, ("{id: 1DG, type: 25hz}", "{id: 1DG, type: zpw2000a, carrier: 2400-1}")),
           "not a ZPW-2000A carrier", "2400-1", ("1700, 2000, 2300 or 2600",)),
    # --- cross-checks
    Broken("duplicate id", edit(BASE, ("{id: J-13, at: 310}", "{id: J-1I, at: 310}")),
           "id 'J-1I' is already used by joint 'J-1I'", "J-1I, at: 310", ("own id",)),
    Broken("unresolved track end", edit(BASE, ("to: J-13, section: 1DG", "to: J-99, section: 1DG")),
           "'J-99' is not an end, joint or turnout leg", "J-99", ("declare it",)),
    Broken("turnout leg not named", edit(BASE, ("from: J-X, to: 1.point", "from: J-X, to: '1'")),
           "attaches to turnout '1' without naming a leg", "'1', section", ("1.point", "1.reverse")),
    Broken("end with two tracks", edit(BASE, (T3G, T3G.replace("B-3", "SB"))),
           "end 'SB' has 2 tracks attached", "SB, kind: boundary", ("exactly one",)),
    Broken("end with no track", edit(BASE, (T3G, T3G.replace("B-3", "SB"))),
           "end 'B-3' has 0 tracks attached", "B-3, kind"),
    Broken("joint with one track", edit(BASE, (T3G, ""), (S3, ""), ("  - {id: B-3, kind: buffer, at: 600}\n", "")),
           "joint 'J-13' has 1 tracks attached", "J-13, at", ("exactly two",)),
    Broken("turnout leg missing", edit(BASE, ("from: 1.reverse", "from: 1.normal")),
           "turnout 1: its reverse leg has 0 tracks attached", '"1", at', ("1.reverse",)),
    Broken("turnout leg used twice", edit(BASE, ("from: 1.reverse", "from: 1.normal")),
           "turnout 1: its normal leg has 2 tracks attached", '"1", at'),
    Broken("track with zero length", edit(BASE, ("{id: J-13, at: 310}", "{id: J-13, at: 250}")),
           "track 't-1c' has both ends at position 250 m", "{id: t-1c", ("must differ",)),
    Broken("turnout legs on opposite sides", edit(BASE, ("{id: J-13, at: 310}", "{id: J-13, at: 240}")),
           "turnout 1: its normal and reverse legs leave on opposite sides of 250 m", "250, number"),
    Broken("turnout point leg on the legs' side", edit(BASE, ("{id: J-X, at: 200, at2: 200.5}",
                                                              "{id: J-X, at: 260, at2: 260.5}")),
           "the point leg leaves on the same side", "250, number"),
    Broken("joint with both tracks on one side", edit(BASE, ("{id: J-13, at: 310}", "{id: J-13, at: 240}")),
           "joint 'J-13': both its tracks leave on the same side of 240 m", "240}"),
    Broken("joint with the same section on both sides",
           edit(BASE, ("to: B-3, section: 3G", "to: B-3, section: 1DG"), (S3, "")),
           "joint 'J-13' has section '1DG' on both sides", "J-13, to: B-3", ("separates two sections",)),
    Broken("turnout with tracks of different sections",
           edit(BASE, ("{id: t-1c, from: 1.reverse, to: J-13, section: 1DG", "{id: t-1c, from: 1.reverse, to: J-13, "
                                                                             "section: 3G")),
           "turnout 1 has tracks of different sections (1DG, 3G)", "1.point", ("inside one section",)),
    Broken("section in pieces", edit(BASE, ("to: B-3, section: 3G", "to: B-3, section: IG"), (S3, "")),
           "section 'IG' is in pieces", "IG, type", ("t-IG, t-3G", "split it")),
    Broken("undeclared section", edit(BASE, ("to: J-XI, section: IG}", "to: J-XI, section: 5G}")),
           "track 't-IG' is in section '5G', which is not declared", "5G}", ("sections:",)),
    Broken("section without tracks", edit(BASE, (S3, S3 + "  - {id: 5G, type: 25hz}\n")),
           "section '5G' has no tracks", "5G, type", ("section: 5G",)),
    Broken("zpw2000a without carrier", edit(BASE, ("{id: 1DG, type: 25hz}", "{id: 1DG, type: zpw2000a}")),
           "ZPW-2000A section '1DG' has no carrier", "zpw2000a}", ("carrier: 2300-1",)),
    Broken("25hz with carrier", edit(BASE, ("{id: 1DG, type: 25hz}", "{id: 1DG, type: 25hz, carrier: 2300-1}")),
           "section '1DG' (25hz) cannot have a ZPW-2000A carrier", "2300-1}", ("remove 'carrier'",)),
    Broken("capacitors on a 25hz section", edit(BASE, ("{id: 1DG, type: 25hz}",
                                                       "{id: 1DG, type: 25hz, capacitors: {count: 2}}")),
           "capacitors belong to ZPW-2000A sections", "{count: 2}"),
    Broken("crossover pair with one member", edit(BASE, ("machine: ZD6}", "machine: ZD6, pair: 1/3}")),
           "crossover pair '1/3' has 1 turnout(s), not 2", "1/3}", ("exactly two turnouts",)),
    Broken("crossover pair with three members", edit(JIAOPEI, (JP_T5, JP_T5[:-1] + ", pair: 1/3}")),
           "crossover pair '1/3' has 3 turnout(s), not 2", '1/3}\n  - {id: "3"'),
    Broken("crossover pair not joined",
           edit(JIAOPEI, (JP_T5, JP_T5[:-1] + ", pair: 5/7}"), (JP_T7, JP_T7[:-1] + ", pair: 5/7}")),
           "form pair '5/7' but their reverse legs are not joined", '5/7}\n  - {id: "4"', ("crossover track",)),
    Broken("signal not at a joint", edit(BASE, ("at: J-XI, direction: down", "at: t-IG, direction: down")),
           "signal XI stands at 't-IG', which is not a joint", "t-IG, direction", ("joints:",)),
    Broken("signal at a buffer stop", edit(BASE, ("at: J-XI, direction: down", "at: B-3, direction: down")),
           "signal XI stands at buffer stop 'B-3'", "B-3, direction"),
    Broken("signal at a boundary facing out", edit(BASE, ("at: J-X, direction: down", "at: XB, direction: up")),
           "signal X at boundary 'XB' faces up, out of the station", "up, lamps: [U", ("into the station",)),
    Broken("missing red lamp", edit(BASE, ("lamps: [L, U, H, B]", "lamps: [L, U, B]")),
           "starting signal XI has no red H lamp", "[L, U, B]", ("add H",)),
    Broken("usu without U2",
           edit(BASE, ("lamps: [U, L, H, U2, B], buttons", "lamps: [U, L, H, B], usu: true, buttons")),
           "signal X may show USU but lacks a U or U2 lamp", "true, buttons", ("second yellow",)),
    Broken("usu on a starting signal", edit(BASE, ("lamps: [L, U, H, B], buttons",
                                                    "lamps: [L, H, U, U2], usu: true, buttons")),
           "only home and route signals show USU", "true, buttons", ("usu: true",)),
    Broken("train button on a shunting signal",
           edit(BASE, ("kind: starting, at: J-XI, direction: down, lamps: [L, U, H, B]",
                       "kind: shunting, at: J-XI, direction: down, lamps: [A, B]")),
           "shunting signal XI cannot have a train button", "[train, shunt]}", ("buttons: [shunt]",)),
    Broken("shunting signal without a blue lamp",
           edit(BASE, ("kind: starting, at: J-XI, direction: down, lamps: [L, U, H, B], buttons: [train, shunt]",
                       "kind: shunting, at: J-XI, direction: down, lamps: [B], buttons: [shunt]")),
           "shunting signal XI needs a moon-white B and a blue A", "[B], buttons"),
    Broken("unknown approach section", edit(BASE, ("buttons: [train]}", "buttons: [train], approach: [IBG]}")),
           "approach section 'IBG' not declared", "IBG]", ("sections:",)),
    Broken("button at an unknown place", edit(BASE, ("{id: SBA, at: SB,", "{id: SBA, at: B-9,")),
           "button SBA (exit) is at 'B-9', which is not a joint or an end", "B-9"),
    Broken("fouling point off its track", edit(BASE, ("{id: FP1, track: t-1b, at: 290}",
                                                      "{id: FP1, track: t-1b, at: 390}")),
           "fouling point FP1 at 390 m is off track 't-1b' (250-300 m)", "390}", ("between each track's two ends",)),
    Broken("fouling point on an unknown track", edit(BASE, ("track: t-1b", "track: t-9")),
           "fouling point FP1 is on unknown track 't-9'", "t-9", ("tracks:",)),
    Broken("platform on a non-station track", edit(BASE, ("{id: P1, section: IG", "{id: P1, section: 3G")),
           "platform P1 is at section '3G', which is not a station track", "3G, screen", ("station_track",)),
    Broken("platform on an unknown section", edit(BASE, ("{id: P1, section: IG", "{id: P1, section: 9G")),
           "platform P1 is at unknown section '9G'", "9G, screen"),
    Broken("platform side twice", edit(BASE, ("[{side: left, doors: 8}]", "[{side: left}, {side: left}]")),
           "platform P1 lists a side twice", "[{side: left}, {side: left}]"),
    Broken("link from a non-boundary end", edit(BASE, ("end: SB,", "end: B-3,")),
           "link SL leaves from 'B-3', which is not a boundary end", "B-3, neighbour", ("kind: boundary",)),
    Broken("link over an unknown section", edit(BASE, ("sections: [1LQG]}", "sections: [1LQG, 2LQG]}")),
           "link SL: section '2LQG' is not declared", "2LQG]"),
    Broken("overlap at an unknown signal", BASE + "\noverlaps:\n  - {end_signal: SX, sections: [IG]}\n",
           "overlap at unknown signal 'SX'", "SX,", ("signals:",)),
    Broken("overlap over an unknown section", BASE + "\noverlaps:\n  - {end_signal: XI, sections: [1LQG, 9G]}\n",
           "overlap section '9G' is not declared", "9G]"),
    Broken("overlap with an unknown turnout",
           BASE + "\noverlaps:\n  - end_signal: XI\n    sections: [1LQG]\n"
                  "    turnouts: [{turnout: '9', position: normal}]\n",
           "overlap turnout '9' is not declared", "{turnout: '9'"),
    Broken("override with an unknown turnout",
           BASE + "\noverrides:\n  protection:\n    - {route: X-XI, turnout: '7', position: reverse}\n",
           "override names unknown turnout '7'", "'7', position", ("turnouts:",)),
    Broken("disconnected network",
           edit(BASE, ("  - {id: B-3, kind: buffer, at: 600}\n",
                       "  - {id: B-3, kind: buffer, at: 600}\n  - {id: B-Y1, kind: buffer, at: 1000}\n"
                       "  - {id: B-Y2, kind: buffer, at: 1100}\n"),
                (T3G, T3G + "  - {id: t-Y, from: B-Y1, to: B-Y2, section: YG}\n"),
                (S3, S3 + "  - {id: YG, type: 25hz, role: spur}\n")),
           "the network is in 2 pieces; tracks t-Y are cut off", "{id: t-Y", ("connect them",)),
]


@pytest.mark.parametrize("case", BROKEN, ids=[b.name for b in BROKEN])
def test_broken_file_is_refused_at_the_right_place(tmp_path: Path, case: Broken) -> None:
    exc, path = refuse(tmp_path, case.text)
    d = find(exc, case.what)
    line, column = position(case.text, case.at) if case.at is not None else (1, 1)
    assert d.file == str(path)
    assert d.line == line, f"reported at line {d.line}, expected {line}:\n{exc}"
    assert d.column == column, f"reported at column {d.column}, expected {column}:\n{exc}"
    assert d.severity == "error"
    assert d.hint, f"no hint for: {d}"
    text = str(exc)
    assert f"{path}:{line}:{column}: error: " in text
    for fragment in case.also:
        assert fragment in d.message or fragment in d.hint, f"{fragment!r} missing from: {d}"
    # every other problem found alongside is well-formed too
    for other in exc.diagnostics:
        assert other.file == str(path) and other.line >= 1 and other.column >= 1 and other.message and other.hint


def test_every_problem_is_reported_at_once(tmp_path: Path) -> None:
    text = edit(BASE, ("to: J-13, section: 1DG", "to: J-98, section: 1DG"),
                ("to: J-XI, section: IG", "to: J-99, section: IG"))
    exc, _ = refuse(tmp_path, text)
    assert [d.line for d in exc.diagnostics] == [position(text, "J-98")[0], position(text, "J-99")[0]]


def test_missing_file_is_a_station_error(tmp_path: Path) -> None:
    with pytest.raises(StationError) as info:
        load(tmp_path / "nowhere.yaml")
    d = info.value.diagnostics[0]
    assert (d.line, d.column) == (1, 1)
    assert "no such file" in d.message and "liansuo stations" in d.message


def test_file_that_is_not_utf8_is_a_station_error(tmp_path: Path) -> None:
    path = tmp_path / "latin1.yaml"
    path.write_bytes("id: caf\xe9\n".encode("latin-1"))
    with pytest.raises(StationError) as info:
        load(path)
    assert "UTF-8" in info.value.diagnostics[0].hint


def test_recursive_alias_is_a_station_error() -> None:
    with pytest.raises(StationError) as info:
        load_text("a: &a [*a]\n", "alias.yaml")
    assert info.value.diagnostics[0].file == "alias.yaml"


# ---- design-rule warnings ----------------------------------------------------------------------------------------
R = design_rules()


@dataclass(frozen=True)
class Warned:
    name: str
    text: str
    fragments: tuple[str, ...]  # measured figure, limit, ...
    at: str  # where the warning points


WARNED = [
    Warned("joint stagger too large", edit(BASE, ("at2: 200.5", "at2: 206")),
           ("joint 'J-X'", "staggered 6 m", f"limit {R.joint_stagger_max_turnout_m:g} m"), "206}"),
    Warned("dead zones too close",
           edit(BASE, ("{id: J-X, at: 200, at2: 200.5}", "{id: J-X, at: 240, at2: 241}"),
                ("{id: J-13, at: 310}", "{id: J-13, at: 255, at2: 256}")),
           ("'J-X' and 'J-13'", "only 14 m apart", f">= {R.dead_zone_spacing_min_m:g} m",
            f">= {R.dead_zone_spacing_relaxed_m:g} m", f"under {R.dead_zone_short_m:g} m"), "255, at2"),
    Warned("coded section too short", edit(BASE, ("{id: J-XI, at: 900}", "{id: J-XI, at: 340}")),
           ("coded section 'IG'", "40 m long", "at 80 km/h (line speed on the main line)",
            f">= {min_coded_length(80):.2f} m", "75.56 m"), "{id: IG, type"),
    Warned("coded siding too short at the rule set's speed",
           edit(BASE, ("{id: 3G, type: 25hz, role: spur}", "{id: 3G, type: 25hz, role: spur, coded: true}"),
                ("{id: B-3, kind: buffer, at: 600}", "{id: B-3, kind: buffer, at: 350}")),
           ("coded section '3G'", "40 m long", f"at {R.turnout_speed_kmh(12):g} km/h (side line, over turnout 1)",
            f">= {min_coded_length(R.turnout_speed_kmh(12)):.2f} m", "51.25 m"), "{id: 3G, type"),
    Warned("same carrier on both sides of a joint",
           edit(BASE, ("{id: IAG, type: 25hz, role: approach}",
                       "{id: IAG, type: zpw2000a, carrier: 2300-1, role: approach}"),
                ("{id: 1DG, type: 25hz}", "{id: 1DG, type: zpw2000a, carrier: 2300-2}")),
           ("'IAG' and '1DG'", "joint 'J-X'", "same carrier frequency (2300-1, 2300-2)"), "{id: J-X, at"),
    Warned("fouling point too close to a starting signal's joint",
           edit(BASE, ("track: t-1b, at: 290}", "track: t-LQ, at: 902}")),
           ("fouling point FP1", "2 m ahead", "starting signal XI", f"need >= {R.fouling_clearance_m:g} m"), "902}"),
    Warned("fouling point too close where EMUs call",
           edit(BASE, ("track: t-1b, at: 290}", "track: t-LQ, at: 904}"),
                ("line_speed_kmh: 80\n", "line_speed_kmh: 80\nemu: true\n")),
           ("4 m ahead", f"need >= {R.fouling_clearance_emu_m:g} m"), "904}"),
    Warned("long ZPW-2000A section without capacitors", edit(BASE, ("{id: IG, type: 25hz,",
                                                                  "{id: IG, type: zpw2000a, carrier: 1700-1,")),
           ("ZPW-2000A section 'IG'", "600 m long", "no compensation capacitors",
            f"over {R.capacitor_min_section_m:g} m"), "{id: IG, type"),
    Warned("long 25 Hz section", edit(BASE, ("{id: J-XI, at: 900}", "{id: J-XI, at: 1900}"),
                                      ("{id: SB, kind: boundary, at: 1200}", "{id: SB, kind: boundary, at: 2200}")),
           ("25 Hz section 'IG'", "1600 m long", f"limit about {R.phase25hz_max_length_m:g} m"), "{id: IG, type"),
    Warned("tuning-area dead zone too long",
           edit(BASE, ("{id: J-1I, at: 300}", "{id: J-1I, at: 300, kind: electrical, dead_zone_m: 6}")),
           ("tuning area 'J-1I'", "6 m", f"exceeds {R.tuning_dead_zone_max_m:g} m"), "{id: J-1I"),
    Warned("tuning area of a non-standard length",
           edit(BASE, ("{id: J-1I, at: 300}", "{id: J-1I, at: 300, kind: electrical, tuning_area_m: 20}")),
           ("tuning area of joint 'J-1I' is 20 m", f"standard {R.tuning_area_m:g} m"), "20}"),
]


@pytest.mark.parametrize("case", WARNED, ids=[w.name for w in WARNED])
def test_design_rule_warning_states_figure_and_limit(case: Warned) -> None:
    warnings = warnings_of(case.text)
    assert len(warnings) == 1, "\n".join(str(w) for w in warnings)
    w = warnings[0]
    for fragment in case.fragments:
        assert fragment in w.message, f"{fragment!r} missing from: {w}"
    assert (w.line, w.column) == position(case.text, case.at), str(w)
    assert w.hint
    assert str(w).startswith(f"w.yaml:{w.line}:{w.column}: warning: ")


def test_no_warning_within_the_limits() -> None:
    ok = [
        edit(BASE, ("at2: 200.5", f"at2: {200 + R.joint_stagger_max_m:g}")),  # 2.5 m: within the rule
        edit(BASE, ("track: t-1b, at: 290}", f"track: t-LQ, at: {900 + R.fouling_clearance_m:g}}}")),
        edit(BASE, ("{id: IG, type: 25hz,", "{id: IG, type: zpw2000a, carrier: 1700-1, capacitors: {rule: standard},")),
        edit(BASE, ("{id: IAG, type: 25hz, role: approach}",
                    "{id: IAG, type: zpw2000a, carrier: 2300-1, role: approach}"),
             ("{id: 1DG, type: 25hz}", "{id: 1DG, type: zpw2000a, carrier: 1700-2}")),
        # a fouling point on another track at the kilometre of the starting signal's joint: the siding 3G runs on
        # beside IG past XI, but no movement from XI reaches it (once a false positive, compared by kilometre only)
        edit(BASE, ("{id: B-3, kind: buffer, at: 600}", "{id: B-3, kind: buffer, at: 1000}"),
             ("track: t-1b, at: 290}", "track: t-3G, at: 902}")),
        # a ZPW-2000A turnout section whose legs add up to 330 m but whose main run is 280 m: no capacitors needed
        edit(BASE, ("{id: J-13, at: 310}", "{id: J-13, at: 480}"),
             ("{id: 1DG, type: 25hz}", "{id: 1DG, type: zpw2000a, carrier: 1700-2}")),
    ]
    for text in ok:
        assert warnings_of(text) == [], "\n".join(str(w) for w in warnings_of(text))


# ---- random damage never escapes as anything but StationError ---------------------------------------------------
def _check_outcome(text: str, file: str) -> None:
    try:
        station = load_text(text, file)
    except StationError as exc:
        assert exc.diagnostics
        lines = text.count("\n") + 2
        for d in exc.diagnostics:
            assert d.file == file
            assert 1 <= d.line <= lines, str(d)
            assert d.column >= 1, str(d)
            assert d.message.strip(), str(d)
            assert d.severity == "error"
        return
    assert isinstance(station, Station)
    for w in station.warnings:
        assert w.line >= 1 and w.column >= 1 and w.message


JIAOPEI_DATA = yaml.safe_load(JIAOPEI)


def _leaves(node: Any) -> list[Any]:
    if isinstance(node, dict):
        return [x for v in node.values() for x in _leaves(v)]
    if isinstance(node, list):
        return [x for v in node for x in _leaves(v)]
    return [node]


# the file's own values (ids, positions, kinds) keep many mutants past the schema and into the cross-checks
scalars = st.one_of(
    st.sampled_from(sorted({repr(x): x for x in _leaves(JIAOPEI_DATA)}.values(), key=repr)),
    st.integers(0, 1600),
    st.none(), st.booleans(), st.integers(-10**6, 10**6), st.floats(allow_nan=True, allow_infinity=True),
    st.text(max_size=12),
    st.sampled_from(["1.normal", "1.reverse", "J-X", "XB", "IG", "1DG", "K0+300", "25hz", "zpw2000a", "down", "H",
                     "train", "2300-1", "", "1/3", "boundary"]),
)
values = st.recursive(scalars, lambda inner: st.one_of(st.lists(inner, max_size=3),
                                                       st.dictionaries(st.text(max_size=8), inner, max_size=3)),
                      max_leaves=6)


def _slots(node: Any, path: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Paths to every value inside ``node`` (dict keys and list indices)."""
    out = []
    if isinstance(node, dict):
        for k, v in node.items():
            out.append((*path, k))
            out += _slots(v, (*path, k))
    elif isinstance(node, list):
        for i, v in enumerate(node):
            out.append((*path, i))
            out += _slots(v, (*path, i))
    return out


def _parent(data: Any, path: tuple[Any, ...]) -> Any:
    for p in path[:-1]:
        data = data[p]
    return data


@st.composite
def structural_mutants(draw: st.DrawFn) -> str:
    data = copy.deepcopy(JIAOPEI_DATA)
    for _ in range(draw(st.integers(1, 3))):
        slots = _slots(data)
        path = draw(st.sampled_from(slots))
        parent, key = _parent(data, path), path[-1]
        op = draw(st.sampled_from(["delete", "replace", "duplicate", "swap_ids", "copy_id"]))
        if op == "delete":
            del parent[key]
        elif op == "replace":
            parent[key] = draw(values)
        elif op == "duplicate" and isinstance(parent, list):
            parent.insert(key, copy.deepcopy(parent[key]))
        else:
            with_ids = [p for p in slots if isinstance(_parent(data, p), dict) and p[-1] == "id"]
            if len(with_ids) >= 2:
                a, b = draw(st.sampled_from(with_ids)), draw(st.sampled_from(with_ids))
                try:
                    pa, pb = _parent(data, a), _parent(data, b)
                except (KeyError, IndexError, TypeError):  # an earlier mutation moved things
                    continue
                if op == "swap_ids":
                    pa["id"], pb["id"] = pb["id"], pa["id"]
                else:
                    pa["id"] = pb["id"]
    return yaml.safe_dump(data, allow_unicode=True, sort_keys=draw(st.booleans()),
                          default_flow_style=draw(st.sampled_from([None, False])))


@st.composite
def textual_mutants(draw: st.DrawFn) -> str:
    text = JIAOPEI
    for _ in range(draw(st.integers(1, 4))):
        i = draw(st.integers(0, len(text)))
        op = draw(st.sampled_from(["delete", "insert", "replace"]))
        piece = draw(st.one_of(st.text(alphabet=" \t\n:-,{}[]'\"#&*!|>%@`.0123456789KXabz", max_size=4),
                               st.text(max_size=3)))
        n = draw(st.integers(1, 20))
        if op == "delete":
            text = text[:i] + text[i + n:]
        elif op == "insert":
            text = text[:i] + piece + text[i:]
        else:
            text = text[:i] + piece + text[i + len(piece):]
    return text


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(structural_mutants())
def test_structural_damage_gives_station_or_station_error(text: str) -> None:
    _check_outcome(text, "mutant.yaml")


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(textual_mutants())
def test_textual_damage_gives_station_or_station_error(text: str) -> None:
    _check_outcome(text, "mutant.yaml")


@settings(max_examples=30, deadline=None, suppress_health_check=[HealthCheck.too_slow,
                                                                 HealthCheck.function_scoped_fixture])
@given(st.one_of(textual_mutants(), structural_mutants()))
def test_damaged_file_on_disk_gives_station_or_station_error(tmp_path: Path, text: str) -> None:
    path = tmp_path / "mutant.yaml"
    path.write_text(text, encoding="utf-8")
    try:
        load(path)
    except StationError as exc:
        assert all(d.file == str(path) and d.line >= 1 and d.column >= 1 and d.message for d in exc.diagnostics)


# ---- the documentation cannot rot ---------------------------------------------------------------------------------
def _models() -> list[type[BaseModel]]:
    return [v for v in vars(schema).values()
            if isinstance(v, type) and issubclass(v, BaseModel) and v not in (BaseModel, schema.Strict)]


def test_format_doc_explains_every_key() -> None:
    doc = DOC.read_text(encoding="utf-8")
    missing = []
    for model in _models():
        for name, field in model.model_fields.items():
            key = field.alias or name
            if f"`{key}`" not in doc:
                missing.append(f"{model.__name__}.{key}")
    assert not missing, f"docs/station-format.md does not explain: {', '.join(missing)}"


def test_format_doc_lists_every_design_rule_and_enum_value() -> None:
    doc = DOC.read_text(encoding="utf-8")
    rules = PKG / "rules" / "china" / "design.yaml"
    for key, value in yaml.safe_load(rules.read_text(encoding="utf-8")).items():
        assert f"`{key}`" in doc, key
        for number, figure in (value.items() if isinstance(value, dict) else [("", value)]):
            assert f"{number}: {figure:g}" in doc if number else f"{figure:g}" in doc, (key, number, figure)
    for enum in (schema.EndKind, schema.JointKind, schema.Machine, schema.CircuitType, schema.SectionRole,
                 schema.SignalKind, schema.Lamp, schema.Button, schema.LinkKind, schema.Side, schema.Direction):
        for member in enum:
            assert f"`{member.value}`" in doc, f"{enum.__name__}.{member.value}"


def test_format_doc_includes_the_minimal_example_verbatim() -> None:
    doc = DOC.read_text(encoding="utf-8")
    assert BASE.strip() in doc


def test_format_doc_yaml_snippets_parse() -> None:
    doc = DOC.read_text(encoding="utf-8")
    blocks = re.findall(r"```yaml\n(.*?)```", doc, flags=re.S)
    assert len(blocks) >= 10
    for block in blocks:
        yaml.safe_load(block)


GLOSSARY_TERMS = [
    "联锁", "站场图", "进路", "列车进路", "调车进路", "变通进路", "接车", "发车", "进站", "出站", "调车", "通过",
    "道岔", "双动道岔", "定位", "反位", "防护道岔", "带动道岔", "轨道电路", "25 Hz 相敏轨道电路", "ZPW-2000A",
    "绝缘节", "电气绝缘节", "调谐区", "死区段", "警冲标", "补偿电容", "电码化", "分路不良", "红光带", "股道",
    "咽喉区", "接近区段", "离去区段", "闭塞分区", "半自动闭塞", "64D", "自动闭塞", "站台门", "屏蔽门", "总取消",
    "总人解", "区故解", "引导", "引导总锁闭", "单操", "单锁", "单封", "重复开放", "三点检查", "接近锁闭", "预先锁闭",
    "延续进路", "冒进", "挤岔", "敌对进路", "迎面进路", "联锁表", "联锁试验", "牵出线", "安全线", "尽头线", "车挡",
    "下行", "上行", "GJ", "DBJ", "FBJ", "DJ", "SNJ", "SNJJ", "ZCKJ", "KMJ", "GMJ", "PDKJ", "PDQCJ",
]


def test_glossary_has_every_term() -> None:
    glossary = GLOSSARY.read_text(encoding="utf-8")
    rows = [line for line in glossary.splitlines() if line.startswith("|")]
    first_cells = " ".join(row.split("|")[1] for row in rows)
    missing = [t for t in GLOSSARY_TERMS if t not in first_cells]
    assert not missing, f"docs/glossary.md lacks: {', '.join(missing)}"

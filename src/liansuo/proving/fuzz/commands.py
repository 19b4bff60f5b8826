"""Fuzzing the command language (``liansuo fuzz commands``, docs/robustness.md): command lines, random and mutated
from the bundled scripts and scenarios, sent to a simulation of a bundled station as an operator would.

A sample is a :class:`Session`: a bundled station, a prefix of a real script's steps that brings it into an
interesting state (a route set, a train running, a fault injected), then one to three lines under test, each
followed by a few cycles. What must hold: no exception ever (a command that crashes, or a cycle after it), and a
refused command changes nothing the query API shows (:class:`RefusalChangedState` otherwise).

The generators are hypothesis strategies, imported only when asked for (hypothesis is a test dependency): numbers
at and past every limit (NaN, infinities, 0, -1, 2**31, 1e308, 1e-300, Unicode digits), durations, every id of the
station, the language's keywords, long words and control characters, each put in place of a word of a real line,
added to it or left out of it, and lines made from the grammar alone.
"""

from __future__ import annotations

import json
import shlex
from dataclasses import dataclass
from functools import cache
from importlib.resources import files
from pathlib import Path
from typing import TYPE_CHECKING, Any

from liansuo.circuits.faults import KINDS
from liansuo.interlocking.table.build import InterlockingTable, build_table
from liansuo.kit.source import StationError, read_text, read_yaml
from liansuo.rules import load_rules
from liansuo.simulation.recording.recorder import snapshot
from liansuo.simulation.sim import LANGUAGE, Simulation
from liansuo.stations.loader import load
from liansuo.stations.station import Station

if TYPE_CHECKING:
    from hypothesis.strategies import DrawFn, SearchStrategy

NAME = "commands"

CYCLES = 4  # cycles run after each line under test: a command that breaks a later cycle shows there
# where the bundled scripts and scenarios are (a checkout; an installed wheel has none: the grammar alone serves)
EXAMPLES = Path(str(files("liansuo"))) / "examples"  # installed with the package
# lines for a station when no example names it (and for every station: commands the examples never send)
BASIC = ("route X XI", "shunt D1 D3", "throw 1 reverse", "train T1 at 1DG", "drive T1 10", "fault broken-rail 1DG",
         "occupy 1DG", "run 5s", "axles W t-1a 390")

NUMBERS = ("nan", "NaN", "-nan", "inf", "-inf", "Infinity", "1e308", "-1e308", "1e309", "1e-300", "5e-324",
           "2147483648", "-2147483649", "9" * 40, "-1", "-0", "0", "0.0", "0.5", "1", "2", "3", "7", "30", "100",
           "1e9", "1e-9", "0.001", "0.01", "1e-100", "1_000", "0x10", "１２", "٣", "1e", ".", "-", "+5", " 5")
DURATIONS = ("0", "0s", "250ms", "30s", "3min", "1h", "3600s", "3601s", "168h", "9999999h", "-5s", "1e5", "59.5s",
             "0.0001ms", "9" * 30 + "h", "5 s", "5m", "1.5min", "nan", "inf")
KEYWORDS = ("normal", "reverse", "request", "accept", "cancel", "restore", "accident", "depart", "block", "out", "in",
            "open", "close", "remove", "at", "clear", "locked", "free", "occupied", "released", "setting", "signal",
            "route", "turnout", "section", "refused", "accepted", "alarm", "no-alarm", "block-line", "code", "cab",
            "odometry", "within", "team", "cab", "remote", "system", "on", "off", "ok", "fault", "none", "lost",
            "wrong-carrier", "left", "right", "main", "backup", "both",
            "open", "half", "short", "bad-contact", "freight", "emu", "shunter", "trolley", "manual", "auto",
            "down", "up", "train", "shunt", *KINDS,
            *load_rules().aspects.lamps)  # the aspect codes, from the rule set (only it names them)
PARAMETERS = ("kind", "length", "axles", "vmax", "mode", "dir", "movement", "back", "front", "stop", "plan",
              "onboard", "centre", "loco", "perception", "by", *{p for k in KINDS.values() for p in k.params})
ODD = ("", "''", '"', "'", "#", "# comment", "\\", "=", "==", "a=b=c", "X" * 5000, "\x1b[2J", "\x1b]0;title\x07",
       "\x00", "\t", "\u202e", "联锁", "ＸＩ", "X\nroute", ";", "$(x)", "*", "..", "/")


class RefusalChangedState(AssertionError):
    """A refused command changed what the query API shows (a defect: a refusal must change nothing)."""


@dataclass(frozen=True)
class Session:
    """One sample: on a simulation of ``station``, the ``setup`` lines (a real script's, their answers not
    checked), then the ``lines`` under test, each followed by :data:`CYCLES` cycles."""

    station: str
    setup: tuple[str, ...]
    lines: tuple[str, ...]

    def __str__(self) -> str:
        """The sample as a test script's steps (``liansuo test`` runs it again)."""
        steps = [*self.setup, *self.lines]
        return f"station: {self.station}\ntests:\n  - name: fuzz\n    steps:\n" + "".join(
            f"      - {json.dumps(s, ensure_ascii=False)}\n" for s in steps)


# ---- the product, as a user drives it ------------------------------------------------------------------------------
@cache
def _station(name: str) -> tuple[Station, InterlockingTable]:
    """A bundled station and its table, loaded once per process (every sample builds a fresh simulation of it)."""
    station = load(name)
    return station, build_table(station)


def _state(sim: Simulation) -> dict[str, Any]:
    """Everything the query API shows that a command could change."""
    return {"t": sim.t, "relays": snapshot(sim), "routes": sim.view.routes(), "trains": sim.train_views(),
            "faults": sorted(sim.field.faults), "parked": {k: list(v) for k, v in sim.parked.items()},
            "alarms": sim.alarm_texts()}


def attempt(sample: Session) -> str:
    """Run ``sample``; 'refused' if a line under test was refused (or an ``expect`` line did not hold), else
    'accepted'. An exception escaping is a defect; so is a refusal that changed the state."""
    station, table = _station(sample.station)
    sim = Simulation(station, table=table)
    try:
        for line in sample.setup:
            sim.command(line)
        answer = "accepted"
        for line in sample.lines:
            before = _state(sim)
            result = sim.command(line)
            if not result.ok:
                answer = "refused"
                after = _state(sim)
                if after != before:
                    changed = sorted(k for k in before if before[k] != after[k])
                    raise RefusalChangedState(f"{line!r} was refused ({result.message}) but changed "
                                              f"{', '.join(changed)}")
            sim.run(CYCLES * sim.cycle_s)
        return answer
    finally:
        sim.close()


# ---- the generators --------------------------------------------------------------------------------------------
def corpus() -> list[tuple[str, tuple[str, ...]]]:
    """(station, steps) of every test of the bundled scripts and every scenario, plus :data:`BASIC` on jiaopei; a
    file that does not read is left out (the fuzzer is about commands, not files)."""
    out: list[tuple[str, tuple[str, ...]]] = [("jiaopei", BASIC)]
    for path in sorted(EXAMPLES.glob("scripts/*.yaml")) + sorted(EXAMPLES.glob("scenarios/*.yaml")):
        try:
            data = read_yaml(read_text(path), str(path)).data
        except StationError:
            continue
        if not isinstance(data, dict) or not isinstance(data.get("station"), str):
            continue
        groups = [t.get("steps") for t in data.get("tests", []) if isinstance(t, dict)] or [data.get("steps")]
        for steps in groups:
            if isinstance(steps, list):
                lines = tuple(s for s in steps if isinstance(s, str))
                if lines:
                    out.append((data["station"], lines))
    return out


@cache
def _slots(station: str) -> dict[str, tuple[str, ...]]:
    """The station's ids by what a command's argument names (signals, sections, turnouts, ...), for the templates;
    every kind also gets a name the station does not have."""
    st, table = _station(station)
    m = st.model
    doors = tuple(f"{p.id}:{d.side.value}" for p in m.platforms for d in p.screen_doors)
    out = {"SIG": (*st.signals, *st.buttons), "SEC": tuple(st.sections), "TO": (*st.turnouts, *st.pairs),
           "TRACK": tuple(st.tracks), "JOINT": tuple(st.joints), "PLAT": (*(p.id for p in m.platforms), *doors),
           "LINK": tuple(lk.id for lk in m.links), "ROUTE": tuple(list(table.routes)[:60]), "NAME": ("T1", "T2", "T9"),
           "BUTTONS": tuple(" ".join(r.buttons) for r in list(table.routes.values())[:60])}
    return {k: (*v, "NOPE") for k, v in out.items()}


def _ids(station: str) -> tuple[str, ...]:
    return tuple(sorted({x for v in _slots(station).values() for x in v}))


# lines of every command with typed slots ({SIG}, {NUM} ...), filled from the station and the lists above
TEMPLATES = (
    "route {BUTTONS}", "shunt {BUTTONS}", "route {SIG} {SIG}", "route {SIG} {SIG} {SIG}", "shunt {SIG} {SIG}",
    "cancel {SIG}", "release {SIG}",
    "reopen {SIG}", "guide {SIG}", "guide-lock {WORD}", "throw {TO} {POS}", "lock {TO}", "unlock {TO}", "block {TO}",
    "unblock {TO}", "fault-release {SEC}", "occupy {SEC}", "vacate {SEC}", "axle-reset {SEC}", "doors {PLAT} {WORD}",
    "block-line {LINK} {WORD}", "line-direction {LINK} {WORD}", "neighbour {LINK} {WORD}", "power-up-release",
    "restart", "faults", "run {DUR}", "axles {NAME} {TRACK} {NUM} {NUM}", "axles {NAME} clear",
    "fault broken-rail {SEC} at={NUM}", "fault poor-shunt {SEC} ohm={NUM}", "fault low-ballast {SEC} ohm_km={NUM}",
    "fault capacitor {SEC} n={NUM} mode={WORD}", "fault axle-miscount {SEC}", "fault insulation {JOINT}",
    "fault insulation {TO}", "fault filament {SIG} lamp={WORD} which={WORD}", "fault flasher {SIG}",
    "fault no-indication {TO}", "fault obstruction {TO} mm={NUM}", "fault high-resistance {TO} N={NUM}",
    "fault squeezed {TO}", "fault psd-stuck {PLAT}", "repair {KIND} {SEC}", "repair {KIND} {TO}",
    "train {NAME} at {SEC}", "train {NAME} at {SEC} {PARAM}={NUM}", "train {NAME} at {TRACK} {PARAM}={NUM} "
    "{PARAM}={WORD}", "train {NAME} at {SEC} length={NUM} axles={NUM} vmax={NUM}", "train {NAME} remove",
    "drive {NAME} {NUM}", "stop {NAME}", "auto {NAME}", "auto {NAME} plan={ROUTE}", "slip {NAME} {NUM} {DUR}",
    "estop {NAME} {WORD}", "estop-release {NAME} {WORD}", "reverse {NAME}", "expect odometry {NAME} within {NUM}",
    "expect signal {SIG} {WORD}", "expect route {ROUTE} {WORD}", "expect section {SEC} {WORD}",
    "expect turnout {TO} {POS}", "expect cab {NAME} {WORD}", "expect refused {WORD}",
)
NUMERIC = tuple(t for t in TEMPLATES if "{NUM}" in t or "{DUR}" in t)
SANE = ("0", "0.5", "1", "3", "5", "10", "20", "30", "45", "100", "300", "390", "600", "1000")


def strategy() -> SearchStrategy[Session]:
    """Sessions: a script's prefix, then one to three lines, mutated from the scripts' or made from the grammar."""
    from hypothesis import strategies as st

    sources = corpus()
    commands = sorted(LANGUAGE)
    numbers = st.one_of(st.sampled_from(NUMBERS), st.sampled_from(SANE), st.floats().map(repr),
                        st.integers().map(str))

    def token(station: str) -> SearchStrategy[str]:
        pair = st.builds(lambda k, v: f"{k}={v}", st.sampled_from(PARAMETERS),
                         numbers | st.sampled_from(_ids(station)) | st.sampled_from(KEYWORDS))
        return st.one_of(st.sampled_from(_ids(station)), numbers, st.sampled_from(DURATIONS),
                         st.sampled_from(KEYWORDS), pair, st.sampled_from(ODD), st.text(max_size=12))

    @st.composite
    def mutated(draw: DrawFn, station: str, steps: tuple[str, ...]) -> str:
        line = draw(st.sampled_from(steps))
        try:
            words = shlex.split(line.split("#", 1)[0])
        except ValueError:
            words = line.split()
        for _ in range(draw(st.integers(1, 3))):
            how = draw(st.sampled_from(("number", "number", "replace", "insert", "append", "drop", "repeat")))
            # the command word stays, mostly: a line that names no command stops at the first word
            at = draw(st.integers(0 if draw(st.integers(0, 9)) == 0 else min(1, len(words) - 1),
                                  max(0, len(words) - 1)))
            if how == "number":
                spots = [i for i, w in enumerate(words) if any(c.isdigit() for c in w)]
                if spots:
                    i = draw(st.sampled_from(spots))
                    key, eq, _ = words[i].rpartition("=")
                    words[i] = f"{key}{eq}{draw(numbers)}" if eq else draw(numbers | st.sampled_from(DURATIONS))
            elif how == "replace" and words:
                words[at] = draw(token(station))
            elif how == "insert":
                words.insert(at, draw(token(station)))
            elif how == "append":
                words.append(draw(token(station)))
            elif how == "drop" and words:
                del words[at]
            elif words:
                words.insert(at, words[at])
        return " ".join(shlex.quote(w) if draw(st.booleans()) else w for w in words)

    @st.composite
    def template(draw: DrawFn, station: str, templates: tuple[str, ...]) -> str:
        slots = _slots(station)
        fill = {**{k: st.sampled_from(v) for k, v in slots.items()}, "NUM": numbers,
                "DUR": st.sampled_from(DURATIONS), "POS": st.sampled_from(("normal", "reverse", "middle")),
                "WORD": st.sampled_from(KEYWORDS) | st.sampled_from(ODD), "KIND": st.sampled_from(sorted(KINDS)),
                "PARAM": st.sampled_from(PARAMETERS)}
        out = []
        for word in draw(st.sampled_from(templates)).split(" "):
            head, brace, rest = word.partition("{")
            while brace:
                name, _, tail = rest.partition("}")
                value = draw(fill[name])
                head += shlex.quote(value) if value.strip() != value or not value else value
                head, brace, rest = (head + tail).partition("{")
                rest = rest if brace else ""
            out.append(head)
        return " ".join(out)

    @st.composite
    def grammar(draw: DrawFn, station: str) -> str:
        words = [draw(st.sampled_from(commands))]
        words += draw(st.lists(token(station), max_size=5))
        return " ".join(words)

    @st.composite
    def sessions(draw: DrawFn) -> Session:
        station, steps = draw(st.sampled_from(sources))
        cut = draw(st.integers(0, len(steps)))
        # every second line puts a number at or past its limit into a command that takes one
        line = st.one_of(template(station, NUMERIC), template(station, NUMERIC), template(station, TEMPLATES),
                         mutated(station, steps), grammar(station), st.sampled_from(steps))
        lines = draw(st.lists(line, min_size=1, max_size=3))
        return Session(station, steps[:cut], tuple(lines))

    return sessions()


__all__ = ["NAME", "RefusalChangedState", "Session", "attempt", "corpus", "strategy"]

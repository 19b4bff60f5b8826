"""YAML route-test scripts (``liansuo test``).

```yaml
station: jiaopei
tests:
  - name: receiving route onto the main track
    steps:
      - route X XI
      - run 15s
      - expect signal X U
```
Each test runs on a fresh simulation. A command that is refused fails the test unless the next step is
``expect refused ...``. A failing step prints the step, what was expected and what the state was. With
``safety: true`` the safety oracle (:class:`~proving.oracle.Watch`) watches every cycle and a violation of a safety
property fails the test at the step where it happens (``liansuo soak`` writes its reproducers this way); a hazard (a
danger the interlocking cannot see by design, such as a vehicle hidden in a dead zone) is reported without failing the
test, and ``expect hazard TEXT`` checks that one was seen.
"""

from __future__ import annotations

import time
from dataclasses import dataclass, field
from pathlib import Path

from liansuo.interlocking.io import Result
from liansuo.simulation.sim import LANGUAGE, Simulation
from liansuo.stations.filekind import read_source
from liansuo.stations.loader import load
from liansuo.stations.source import Diagnostic, StationError
from liansuo.stations.station import Station

from .oracle import Watch


@dataclass
class Step:
    text: str
    line: int


@dataclass
class ScriptTest:
    name: str
    steps: list[Step]
    line: int


@dataclass
class Script:
    file: str
    station: str
    tests: list[ScriptTest]
    cycle_s: float = 0.25
    safety: bool = False  # check the safety properties every cycle


@dataclass
class Outcome:
    script: str
    name: str
    passed: bool
    failure: str = ""
    line: int = 0
    log: list[str] = field(default_factory=list)
    hazards: list[str] = field(default_factory=list)  # what the oracle found that the interlocking cannot see
    time_s: float = 0.0  # wall-clock seconds the test took to run

    def report(self) -> str:
        """A failure as ``liansuo test -v`` prints it: where, which step and why, then every step's answer."""
        lines = [f"FAIL {self.script}:{self.line}: {self.name}", f"    {self.failure}", "  steps:"]
        return "\n".join(lines + [f"    {entry}" for entry in self.log])

    def as_dict(self) -> dict[str, object]:
        """The outcome as ``liansuo test --format json`` lists it (docs/commands.md)."""
        return {"script": self.script, "name": self.name, "passed": self.passed, "line": self.line or None,
                "failure": self.failure or None, "hazards": self.hazards, "log": [] if self.passed else self.log}


@dataclass
class Unrunnable:
    """A script that could not be run at all (it is malformed, or its station does not load): an error, as opposed
    to a test whose expectation failed."""

    script: str
    diagnostics: list[str]  # FILE:LINE:COLUMN: error: ... each


def parse_script(path: Path) -> Script:
    src = read_source(path, "script", "give the path of a YAML test script (see examples/scripts/)")
    errors: list[Diagnostic] = []
    data = src.data
    if not isinstance(data, dict):
        raise StationError([src.diagnostic((), "a test script is a mapping with 'station:' and 'tests:'",
                                           "see examples/ for scripts")])
    for key in data:
        if key not in ("station", "tests", "cycle_ms", "safety"):
            errors.append(src.diagnostic((key,), f"unknown key '{key}'", "a script has station, tests and "
                                         "optionally cycle_ms and safety", at_key=True))
    station = data.get("station")
    if not isinstance(station, str):
        errors.append(src.diagnostic(("station",) if "station" in data else (), "missing or invalid 'station:'",
                                     "name a bundled station or a station file path"))
    tests_raw = data.get("tests")
    tests: list[ScriptTest] = []
    if not isinstance(tests_raw, list) or not tests_raw:
        errors.append(src.diagnostic(("tests",) if "tests" in data else (), "'tests:' must be a non-empty list", ""))
        tests_raw = []
    for i, t in enumerate(tests_raw):
        if not isinstance(t, dict) or not isinstance(t.get("name"), str) or not isinstance(t.get("steps"), list):
            errors.append(src.diagnostic(("tests", i), "each test needs 'name:' and a list of 'steps:'", ""))
            continue
        for key in t:
            if key not in ("name", "steps"):
                errors.append(src.diagnostic(("tests", i, key), f"unknown key '{key}' in a test", "", at_key=True))
        steps = [Step(s, line) for s, line in LANGUAGE.read_steps(src, ("tests", i, "steps"), t["steps"], errors)]
        tests.append(ScriptTest(t["name"], steps, src.mark(("tests", i)).line))
    cycle_ms = data.get("cycle_ms", 250)
    if not isinstance(cycle_ms, int | float) or isinstance(cycle_ms, bool) or not 10 <= cycle_ms <= 2000:
        errors.append(src.diagnostic(("cycle_ms",), "cycle_ms must be a number from 10 to 2000", ""))
        cycle_ms = 250
    safety = data.get("safety", False)
    if not isinstance(safety, bool):
        errors.append(src.diagnostic(("safety",), "safety must be true or false", ""))
        safety = False
    if errors:
        raise StationError(errors)
    return Script(str(path), str(station), tests, cycle_ms / 1000.0, safety)


def _resolve_station(script: Script, src_dir: Path) -> Station:
    try:
        return load(script.station)
    except StationError:
        candidate = src_dir / script.station
        if candidate.exists():
            return load(candidate)
        raise


def script_station(script: Script) -> Station:
    """The station the script runs on: a bundled name, or a path as given or relative to the script's folder;
    :class:`StationError` when it does not load."""
    return _resolve_station(script, Path(script.file).parent)


def selected(script: Script, only: str | None) -> list[ScriptTest]:
    """The script's tests whose name contains ``only`` (case-insensitive); all of them without it."""
    return [t for t in script.tests if not only or only.lower() in t.name.lower()]


def run_script(script: Script, only: str | None = None, station: Station | None = None) -> list[Outcome]:
    """Run the tests ``only`` selects, each on a fresh simulation of the script's station (loaded unless given)."""
    station = station or script_station(script)
    from liansuo.interlocking.table import build_table

    table = build_table(station)
    outcomes = []
    for test in selected(script, only):
        outcomes.append(run_test(script, test, station, table))
    return outcomes


def run_test(script: Script, test: ScriptTest, station: Station, table: object) -> Outcome:
    """Run one test on a fresh simulation; the outcome carries the wall-clock time it took."""
    start = time.perf_counter()
    outcome = _run_steps(script, test, station, table)
    outcome.time_s = time.perf_counter() - start
    return outcome


def _run_steps(script: Script, test: ScriptTest, station: Station, table: object) -> Outcome:
    sim = Simulation(station, cycle_s=script.cycle_s, table=table)  # type: ignore[arg-type]
    checker = Watch(sim) if script.safety else None
    log: list[str] = []
    steps = test.steps
    for k, step in enumerate(steps):
        hazard = _expect_hazard(step.text, checker)
        result = hazard if hazard is not None else sim.command(step.text)
        log.append(f"{step.text} -> {'ok' if result.ok else 'refused'}: {result.message}")
        if checker is not None and checker.violations:
            v = checker.violations[0]
            return Outcome(script.file, test.name, False, f"step '{step.text}': safety violation at t = {v.t:g} s "
                           f"({v.prop}): {v.text}", step.line, log, _hazards(checker))
        is_expect = step.text.strip().startswith("expect")
        if result.ok:
            continue
        if not is_expect:
            nxt = steps[k + 1].text.strip() if k + 1 < len(steps) else ""
            if nxt.startswith("expect refused"):
                continue
            return Outcome(script.file, test.name, False,
                           f"step '{step.text}' was refused: {result.message}", step.line, log, _hazards(checker))
        return Outcome(script.file, test.name, False, f"step '{step.text}': {result.message} (t = {sim.t:g} s)",
                       step.line, log, _hazards(checker))
    return Outcome(script.file, test.name, True, log=log, hazards=_hazards(checker))


def _expect_hazard(line: str, checker: Watch | None) -> Result | None:
    """``expect hazard TEXT``: the oracle has reported a hazard (a danger the interlocking cannot see by design)
    whose text contains TEXT; needs ``safety: true``. None for any other line."""
    words = line.split("#", 1)[0].split()
    if words[:2] != ["expect", "hazard"]:
        return None
    if checker is None:
        return Result.refuse("'expect hazard' needs the safety oracle: add 'safety: true' to the script")
    text = " ".join(words[2:]).lower()
    seen = [h.text for h in checker.hazards]
    hits = [h for h in seen if text in h.lower()]
    return Result(bool(hits), f"hazards: {'; '.join(seen) or 'none'}")


def _hazards(checker: Watch | None) -> list[str]:
    return [f"t = {h.t:g} s {h.prop}: {h.text}" for h in checker.hazards] if checker is not None else []

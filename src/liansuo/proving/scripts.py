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
from liansuo.kit.filekind import read_source
from liansuo.kit.source import Diagnostic, Source, StationError
from liansuo.proving.fileschemas import ScriptFile
from liansuo.proving.keywords import Expression
from liansuo.proving.oracle import Watch
from liansuo.simulation.sim import LANGUAGE, Simulation
from liansuo.stations.loader import load_named
from liansuo.stations.station import Station
from liansuo.stations.validation import validate


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
    """Read and check a test script (:class:`~.fileschemas.ScriptFile`, then every step a command of the language);
    :class:`StationError` with FILE:LINE:COLUMN diagnostics when malformed, or when it is a file of another kind."""
    src = read_source(path, "script", "give the path of a YAML test script (see examples/scripts/)")
    data = src.data
    if not isinstance(data, dict):
        raise StationError([src.diagnostic((), "a test script is a mapping with 'station:' and 'tests:'",
                                           "see examples/ for scripts")])
    errors: list[Diagnostic] = []
    tests_raw = data.get("tests")
    steps = [LANGUAGE.read_steps(src, ("tests", i, "steps"), t.get("steps") if isinstance(t, dict) else None, errors)
             for i, t in enumerate(tests_raw if isinstance(tests_raw, list) else [])]
    model = validate(src, ScriptFile, errors, "script", "'liansuo docs commands'")
    if model is not None:
        errors += _same_names(src, [t.name for t in model.tests])
    if errors or model is None:
        raise StationError(errors)
    tests = [ScriptTest(t.name, [Step(text, line) for text, line in lines], src.mark(("tests", i)).line)
             for i, (t, lines) in enumerate(zip(model.tests, steps, strict=True))]
    return Script(str(path), model.station, tests, model.cycle_ms / 1000.0, model.safety)


def _same_names(src: Source, names: list[str]) -> list[Diagnostic]:
    """A test whose name an earlier test of the script has: the JUnit report, pytest's node ids and ``-k`` tell
    tests apart by name."""
    first: dict[str, int] = {}
    out = []
    for i, name in enumerate(names):
        if name in first:
            line = src.mark(("tests", first[name], "name")).line
            out.append(src.diagnostic(("tests", i, "name"), f"a second test named {name!r} (the first is on line "
                                      f"{line})", "give each test of a script its own name: reports and -k tell "
                                      "tests apart by it"))
        else:
            first[name] = i
    return out


def script_station(script: Script) -> Station:
    """The station the script runs on: a bundled name, or a path relative to the script's folder (from wherever the
    script is run); :class:`StationError` when it does not load."""
    return load_named(script.station, script.file)


def selected(script: Script, only: str | None) -> list[ScriptTest]:
    """The script's tests that the ``-k`` expression ``only`` selects (:mod:`.keywords`: pytest's, on the test's name
    and the script's file name); all of them without it."""
    if not only:
        return list(script.tests)
    expr = Expression(only)
    return [t for t in script.tests if expr.matches((t.name, Path(script.file).name))]


def run_script(script: Script, only: str | None = None, station: Station | None = None) -> list[Outcome]:
    """Run the tests ``only`` selects, each on a fresh simulation of the script's station (loaded unless given)."""
    station = station or script_station(script)
    from liansuo.interlocking.table.build import build_table

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

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

from dataclasses import dataclass, field
from pathlib import Path

from liansuo.interlocking.io import Result
from liansuo.simulation.sim import LANGUAGE, Simulation
from liansuo.stations.loader import load
from liansuo.stations.source import Diagnostic, StationError, read_file
from liansuo.stations.station import Station
from liansuo.stations.validation import validate

from .fileschemas import ScriptFile
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


def parse_script(path: Path) -> Script:
    """Read and check a test script (:class:`~.fileschemas.ScriptFile`, then every step a command of the language);
    :class:`StationError` with FILE:LINE:COLUMN diagnostics when malformed."""
    src = read_file(path, "give the path of a YAML test script (see examples/scripts/)")
    data = src.data
    if not isinstance(data, dict):
        raise StationError([src.diagnostic((), "a test script is a mapping with 'station:' and 'tests:'",
                                           "see examples/ for scripts")])
    errors: list[Diagnostic] = []
    tests_raw = data.get("tests")
    steps = [LANGUAGE.read_steps(src, ("tests", i, "steps"), t.get("steps") if isinstance(t, dict) else None, errors)
             for i, t in enumerate(tests_raw if isinstance(tests_raw, list) else [])]
    model = validate(src, ScriptFile, errors, "script", "docs/commands.md")
    if errors or model is None:
        raise StationError(errors)
    tests = [ScriptTest(t.name, [Step(text, line) for text, line in lines], src.mark(("tests", i)).line)
             for i, (t, lines) in enumerate(zip(model.tests, steps, strict=True))]
    return Script(str(path), model.station, tests, model.cycle_ms / 1000.0, model.safety)


def _resolve_station(script: Script, src_dir: Path) -> Station:
    try:
        return load(script.station)
    except StationError:
        candidate = src_dir / script.station
        if candidate.exists():
            return load(candidate)
        raise


def run_script(script: Script, only: str | None = None) -> list[Outcome]:
    station = _resolve_station(script, Path(script.file).parent)
    from liansuo.interlocking.table import build_table

    table = build_table(station)
    outcomes = []
    for test in script.tests:
        if only and only.lower() not in test.name.lower():
            continue
        outcomes.append(run_test(script, test, station, table))
    return outcomes


def run_test(script: Script, test: ScriptTest, station: Station, table: object) -> Outcome:
    sim = Simulation(station, cycle_s=script.cycle_s, table=table)  # type: ignore[arg-type]
    checker = Watch(sim) if script.safety else None
    log: list[str] = []
    steps = test.steps
    for k, step in enumerate(steps):
        result = _expect_hazard(step.text, checker) or sim.command(step.text)
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

"""Exercises: a lesson an instructor loads into the console (bundled in ``liansuo/exercises/``).

```yaml
title: A broken rail in IG
station: jiaopei              # a bundled name or a path (relative to the exercise file)
description: what the trainee is told
setup:                        # commands sent when the exercise is loaded (faults, occupancy, trains, time)
  - fault broken-rail IG
goal:
  description: what counts as done
  expect:                     # expect lines (with or without the word 'expect'); all must hold at once
    - section IG occupied
    - signal X UU
```
The goal is checked with the command language's own ``expect`` lines, which read the state and change nothing.
"""

from __future__ import annotations

from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path

from liansuo.stations.filekind import read_source
from liansuo.stations.library import bundled, resolve_from
from liansuo.stations.source import Diagnostic, StationError
from liansuo.stations.validation import validate

from .exerciseschema import ExerciseFile, Goal
from .sim import LANGUAGE, Simulation


@dataclass
class Exercise:
    file: str
    title: str
    station: str
    description: str
    setup: list[str] = field(default_factory=list)
    goal: str = ""
    expect: list[str] = field(default_factory=list)

    def station_ref(self) -> str:
        """The station as a bundled name, or a path resolved against the exercise file."""
        if self.station in bundled():
            return self.station
        return str(resolve_from(self.station, self.file).resolve())


@dataclass
class GoalCheck:
    reached: bool
    lines: list[tuple[str, bool, str]]  # (expect line, holds, what the state is)


def parse_exercise(path: str | Path) -> Exercise:
    """Read and check an exercise file, or a bundled exercise by name; :class:`StationError` with FILE:LINE:COLUMN
    diagnostics when malformed."""
    given = Path(path)
    if not given.exists():
        given = next((p for p in bundled_exercises() if p.stem == str(path)), given)
    names = ", ".join(p.stem for p in bundled_exercises())
    src = read_source(given, "exercise", f"give the path of an exercise file, or a bundled exercise: {names}")
    data = src.data
    if not isinstance(data, dict):
        raise StationError([src.diagnostic((), "an exercise is a mapping with title, station, setup and goal", "")])
    errors: list[Diagnostic] = []
    setup = [s for s, _ in LANGUAGE.read_steps(src, ("setup",), data.get("setup"), errors)]
    model = validate(src, ExerciseFile, errors, "exercise", "docs/console.md")
    if errors or model is None:
        raise StationError(errors)
    goal = model.goal or Goal()
    expect = [line if line.strip().startswith("expect") else f"expect {line.strip()}" for line in goal.expect]
    return Exercise(str(given), model.title, model.station, str(model.description).strip(), setup,
                    str(goal.description).strip(), expect)


def check_goal(sim: Simulation, ex: Exercise) -> GoalCheck:
    """Evaluate the goal's expect lines now (they change nothing)."""
    lines = []
    for line in ex.expect:
        r = sim.command(line)
        lines.append((line, r.ok, r.message))
    return GoalCheck(bool(lines) and all(ok for _, ok, _ in lines), lines)


def bundled_exercises() -> list[Path]:
    """The exercises installed with liansuo (package data)."""
    here = Path(str(files("liansuo") / "exercises"))
    return sorted(here.glob("*.yaml")) if here.is_dir() else []

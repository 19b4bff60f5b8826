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
from liansuo.stations.library import bundled
from liansuo.stations.source import Diagnostic, StationError

from .sim import LANGUAGE, Simulation

KEYS = ("title", "station", "description", "setup", "goal")
GOAL_KEYS = ("description", "expect")


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
        return str((Path(self.file).parent / self.station).resolve())


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
    errors: list[Diagnostic] = []
    if not isinstance(data, dict):
        raise StationError([src.diagnostic((), "an exercise is a mapping with title, station, setup and goal", "")])
    for key in data:
        if key not in KEYS:
            errors.append(src.diagnostic((key,), f"unknown key '{key}'", f"an exercise has {', '.join(KEYS)}",
                                         at_key=True))
    for key in ("title", "station"):
        if not isinstance(data.get(key), str) or not data.get(key):
            errors.append(src.diagnostic((key,) if key in data else (), f"missing or invalid '{key}:'", ""))
    setup: list[str] = []
    raw = data.get("setup", [])
    if not isinstance(raw, list):
        errors.append(src.diagnostic(("setup",), "'setup:' is a list of commands", ""))
        raw = []
    setup = [s for s, _ in LANGUAGE.read_steps(src, ("setup",), raw, errors)]
    goal = data.get("goal", {}) or {}
    expect: list[str] = []
    if not isinstance(goal, dict):
        errors.append(src.diagnostic(("goal",), "'goal:' is a mapping with description and expect", ""))
        goal = {}
    for key in goal:
        if key not in GOAL_KEYS:
            errors.append(src.diagnostic(("goal", key), f"unknown key '{key}'", "a goal has description and expect",
                                         at_key=True))
    lines = goal.get("expect", [])
    if not isinstance(lines, list):
        errors.append(src.diagnostic(("goal", "expect"), "'expect:' is a list of expect lines", ""))
        lines = []
    for i, line in enumerate(lines):
        if not isinstance(line, str):
            errors.append(src.diagnostic(("goal", "expect", i), "an expect line is text", ""))
            continue
        expect.append(line if line.strip().startswith("expect") else f"expect {line.strip()}")
    if errors:
        raise StationError(errors)
    return Exercise(str(path), str(data["title"]), str(data["station"]), str(data.get("description", "")).strip(),
                    setup, str(goal.get("description", "")).strip(), expect)


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

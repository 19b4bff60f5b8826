"""Exercises: a lesson an instructor loads into the console, or an assessment the classroom server or ``liansuo
exercise run`` scores (bundled in ``liansuo/exercises/``; the format is in docs/exercises.md).

```yaml
title: A broken rail in IG
station: jiaopei              # a bundled name or a path (relative to the exercise file)
briefing: what the trainee is told   # (its old name, 'description', is still read)
difficulty: 2                 # 1 easy, 2 medium, 3 hard: how many pool faults are drawn
time_limit: 10min
setup:                        # commands sent when the exercise is loaded (occupancy, trains, time)
  - run 1s
faults:
  fixed: [fault broken-rail IG at=300]
  pool: [fault filament X lamp=U, fault no-indication 5]
  draw: {easy: 0, medium: 1, hard: 2}
goals:                        # or one 'goal:' as before
  - description: what counts as done
    expect:                   # expect lines (with or without the word 'expect'); all must hold at once
      - route X X3 open
    points: 10
diagnosis:                    # what the trainee must register with 'diagnose KIND ELEMENT'
  - fault: broken-rail IG
    accept: [broken-rail IG]
```
Goals are checked with the command language's own ``expect`` lines, which read the state and change nothing.
"""

from __future__ import annotations

import random
from collections.abc import Iterable
from dataclasses import dataclass, field
from importlib.resources import files
from pathlib import Path

from liansuo.classroom.schema import ExerciseFile, FaultDraw, Faults, Scoring
from liansuo.kit.filekind import read_source
from liansuo.kit.source import Diagnostic, Source, StationError
from liansuo.simulation.diagnosis import DIAGNOSIS_KINDS
from liansuo.simulation.sim import LANGUAGE, Simulation
from liansuo.stations.library import bundled, resolve_from
from liansuo.stations.loader import load
from liansuo.stations.validation import validate

DIFFICULTIES = {1: "easy", 2: "medium", 3: "hard"}


@dataclass(frozen=True)
class ExerciseGoal:
    """One goal: met once every expect line holds at once."""

    description: str
    expect: tuple[str, ...]
    points: float = 10.0


@dataclass(frozen=True)
class FindingSpec:
    """What the trainee must find: ``fault`` ('KIND TARGET', or '' for a finding that always counts) and the
    diagnoses ('KIND ELEMENT') that count as correct."""

    fault: str
    finding: str
    accept: tuple[str, ...]


@dataclass
class Exercise:
    file: str
    title: str
    station: str
    description: str  # the briefing: what the trainee is told
    setup: list[str] = field(default_factory=list)
    goal: str = ""  # every goal's description, for the console's status
    expect: list[str] = field(default_factory=list)  # every goal's expect lines
    goals: list[ExerciseGoal] = field(default_factory=list)
    difficulty: int = 1
    time_limit: float = 600.0
    fixed_faults: list[str] = field(default_factory=list)
    pool: list[str] = field(default_factory=list)
    draw: dict[int, int] = field(default_factory=lambda: {1: 1, 2: 1, 3: 2})
    diagnosis: list[FindingSpec] = field(default_factory=list)
    scoring: Scoring = field(default_factory=Scoring)

    @property
    def briefing(self) -> str:
        return self.description

    @property
    def name(self) -> str:
        """The file's stem: the name a bundled exercise is known by."""
        return Path(self.file).stem

    def station_ref(self) -> str:
        """The station as a bundled name, or a path resolved against the exercise file."""
        if self.station in bundled():
            return self.station
        return str(resolve_from(self.station, self.file).resolve())

    def draw_count(self, difficulty: int | None = None) -> int:
        """How many pool faults are drawn at ``difficulty`` (the exercise's own by default)."""
        return min(self.draw[difficulty or self.difficulty], len(self.pool))

    def drawn_faults(self, seed: int, difficulty: int | None = None) -> list[str]:
        """The pool's fault lines drawn for ``seed``: the same seed always draws the same lines."""
        return random.Random(seed).sample(self.pool, self.draw_count(difficulty))

    def lines(self, seed: int, difficulty: int | None = None) -> list[str]:
        """What the instructor's side sends to start the exercise: the setup, the fixed faults, the drawn ones."""
        return [*self.setup, *self.fixed_faults, *self.drawn_faults(seed, difficulty)]


@dataclass
class GoalCheck:
    reached: bool
    lines: list[tuple[str, bool, str]]  # (expect line, holds, what the state is)
    met: list[bool] = field(default_factory=list)  # per goal: met now, or before when the caller keeps them


def _expect(line: str) -> str:
    return line if line.strip().startswith("expect") else f"expect {line.strip()}"


def _draws(draw: int | FaultDraw) -> dict[int, int]:
    if isinstance(draw, int):
        return dict.fromkeys(DIFFICULTIES, draw)
    return {1: draw.easy, 2: draw.medium, 3: draw.hard}


def _diagnosis_lines(src: Source, data: object, errors: list[Diagnostic]) -> None:
    """Each accepted diagnosis is 'KIND ELEMENT' with a kind 'diagnose' knows."""
    findings = data.get("diagnosis") if isinstance(data, dict) else None
    for i, item in enumerate(findings if isinstance(findings, list) else []):
        accept = item.get("accept") if isinstance(item, dict) else None
        for j, line in enumerate(accept if isinstance(accept, list) else []):
            if not isinstance(line, str):
                continue
            words = line.split()
            if len(words) != 2 or words[0] not in DIAGNOSIS_KINDS:
                errors.append(src.diagnostic(("diagnosis", i, "accept", j), f"'{line}' is not a diagnosis",
                                             f"write 'KIND ELEMENT', KIND one of {', '.join(DIAGNOSIS_KINDS)}"))


def _goal_lines(src: Source, data: object, errors: list[Diagnostic]) -> None:
    """A goal of 'goals:' needs expect lines: without them it could never be met."""
    goals = data.get("goals") if isinstance(data, dict) else None
    for i, item in enumerate(goals if isinstance(goals, list) else []):
        if isinstance(item, dict) and not item.get("expect"):
            errors.append(src.diagnostic(("goals", i), "a goal needs expect lines", "add 'expect:' with the state "
                                         "that shows the goal met, e.g. '- route X XI open'"))


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
    raw_faults = data.get("faults")
    if isinstance(raw_faults, dict):
        for key in ("fixed", "pool"):
            LANGUAGE.read_steps(src, ("faults", key), raw_faults.get(key), errors)
    _diagnosis_lines(src, data, errors)
    _goal_lines(src, data, errors)
    model = validate(src, ExerciseFile, errors, "exercise", "'liansuo docs exercises'")
    if errors or model is None:
        raise StationError(errors)
    goals = [ExerciseGoal(str(g.description).strip(), tuple(_expect(line) for line in g.expect), g.points)
             for g in ([model.goal] if model.goal is not None else model.goals)]
    faults: Faults = model.faults
    findings = [FindingSpec(" ".join(f.fault.split()), str(f.finding).strip(),
                            tuple(" ".join(a.split()) for a in f.accept)) for f in model.diagnosis]
    briefing = str(model.briefing or model.description).strip()
    return Exercise(str(given), model.title, model.station, briefing, setup,
                    "; ".join(g.description for g in goals if g.description),
                    [line for g in goals for line in g.expect], goals, model.difficulty, model.time_limit,
                    list(faults.fixed), list(faults.pool), _draws(faults.draw), findings, model.scoring)


def check_goal(sim: Simulation, ex: Exercise, met: set[int] | None = None) -> GoalCheck:
    """Evaluate the goals' expect lines now (they change nothing). With ``met`` (kept by the caller) a goal once met
    stays met, and the goals met now are added to it; without it every goal must hold now."""
    lines: list[tuple[str, bool, str]] = []
    now: list[bool] = []
    for i, g in enumerate(ex.goals):
        results = []
        for line in g.expect:
            r = sim.command(line)
            results.append((line, r.ok, r.message))
        holds = bool(results) and all(ok for _, ok, _ in results)
        if met is not None:
            if holds:
                met.add(i)
            holds = i in met
        now.append(holds)
        lines += results
    return GoalCheck(bool(now) and all(now), lines, now)


def exercises_for(station_id: str, paths: Iterable[Path]) -> list[Path]:
    """Those of ``paths`` that are exercises for the station ``station_id`` (one that cannot be read is left out:
    starting it says why)."""
    ids: dict[str, str] = {}  # a station's reference: its id
    out: list[Path] = []
    for p in paths:
        try:
            ref = parse_exercise(p).station_ref()
            if ref not in ids:
                ids[ref] = load(ref).id
        except (StationError, OSError):
            continue
        if ids[ref] == station_id:
            out.append(p)
    return out


def bundled_exercises() -> list[Path]:
    """The exercises installed with liansuo (package data)."""
    here = Path(str(files("liansuo") / "exercises"))
    return sorted(here.glob("*.yaml")) if here.is_dir() else []

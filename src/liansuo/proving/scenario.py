"""Scenarios (``liansuo run SCENARIO.yaml [--until DURATION]``): a station and a list of commands, run headless.

```yaml
station: jiaopei
description: a receiving then departing train
steps:
  - train T1 at IAG mode=signal length=300
  - route X XI
  - run 2min
until: 10min          # optional: keep running to this simulated time after the last step
```
Every command of the language may appear; a refused command stops the run with its reason. The event log of the
interlocking and of the world is printed as the run goes.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from liansuo.kit.filekind import read_source
from liansuo.kit.printable import printable
from liansuo.kit.source import Diagnostic, StationError
from liansuo.proving.fileschemas import ScenarioFile
from liansuo.simulation.sim import LANGUAGE, Simulation
from liansuo.stations.loader import load_named
from liansuo.stations.station import Station
from liansuo.stations.validation import validate


@dataclass
class Scenario:
    file: str
    station: str
    description: str
    steps: list[tuple[str, int]]  # (command, line)
    until_s: float | None


def parse_scenario(path: Path) -> Scenario:
    """Read and check a scenario (:class:`~.fileschemas.ScenarioFile`, then every step a command of the language);
    :class:`StationError` with FILE:LINE:COLUMN diagnostics when malformed, or when it is a file of another kind."""
    src = read_source(path, "scenario", "give the path of a scenario file (see examples/scenarios/)")
    data = src.data
    if not isinstance(data, dict):
        raise StationError([src.diagnostic((), "a scenario is a mapping with 'station:' and 'steps:'", "")])
    errors: list[Diagnostic] = []
    steps = LANGUAGE.read_steps(src, ("steps",), data.get("steps"), errors)
    model = validate(src, ScenarioFile, errors, "scenario", "'liansuo docs trains'")
    if errors or model is None:
        raise StationError(errors)
    return Scenario(str(path), model.station, str(model.description), steps, model.until)


@dataclass
class ScenarioLog:
    """What a run showed, as ``liansuo run --format json`` writes it: the events in time order, the steps that were
    refused or whose expectation failed, and the trains at the end."""

    events: list[dict[str, Any]] = field(default_factory=list)  # {t, kind, text}
    problems: list[dict[str, Any]] = field(default_factory=list)  # {line, command, refused, message}
    end_s: float = 0.0
    trains: list[dict[str, Any]] = field(default_factory=list)  # {name, sections, speed_kmh}


def station_of(sc: Scenario) -> Station:
    """The scenario's station: a bundled name, or a path relative to the scenario's folder (from wherever the
    scenario is run); :class:`StationError` when it does not load."""
    return load_named(sc.station, sc.file)


def run_scenario(sc: Scenario, until_s: float | None = None, out: list[str] | None = None,
                 engine: str = "kinematic", log: ScenarioLog | None = None,
                 station: Station | None = None, watch: Callable[[Simulation], None] | None = None,
                 ) -> tuple[int, Simulation]:
    """Run the scenario; returns (exit status, the simulation). Lines of the event log go to ``out`` (or stdout),
    and the same as data to ``log`` when one is given. ``engine``: the train engine, "kinematic" or "sumo" (see
    :class:`Simulation`); ``station``: the scenario's station when already loaded; ``watch``: called with the
    simulation before the first step (to attach a recorder, e.g. :class:`~.trainplot.TrainTrace`)."""
    sim = Simulation(station or station_of(sc), engine=engine)
    if watch is not None:
        watch(sim)
    seen = [0, 0]  # events already printed from the interlocking and from the world
    log = log if log is not None else ScenarioLog()

    def emit(text: str) -> None:
        if out is None:
            print(printable(text))  # an event may quote a step of the file
        else:
            out.append(text)

    def flush() -> None:
        il_events, world = list(sim.view.events()), list(sim.events)
        new = sorted(il_events[seen[0]:] + world[seen[1]:], key=lambda e: e.t)
        seen[0], seen[1] = len(il_events), len(world)
        for e in new:
            log.events.append({"t": round(e.t, 2), "kind": e.kind, "text": e.text})
            emit(f"{e.t:9.2f} {e.kind:8} {e.text}")

    def problem(command: str, line: int, refused: bool, message: str) -> None:
        log.problems.append({"line": line, "command": command, "refused": refused, "message": message})
        emit(f"{sc.file}:{line}: '{command}'{' refused' if refused else ''}: {message}")

    def finish(status: int) -> tuple[int, Simulation]:
        log.end_s = round(sim.t, 2)
        log.trains = [{"name": v.name, "sections": list(v.sections), "speed_kmh": v.speed_kmh}
                      for v in sim.train_views()]
        return status, sim

    status = 0
    for command, line in sc.steps:
        result = sim.command(command)
        flush()
        if not result.ok and not command.strip().startswith("expect"):
            problem(command, line, True, result.message)
            return finish(1)  # a refused command stops the run
        if command.strip().startswith("expect") and not result.ok:
            problem(command, line, False, result.message)
            status = 1
    end = until_s if until_s is not None else sc.until_s
    while end is not None and sim.t < end:
        sim.run(min(60.0, end - sim.t))
        flush()
    emit(f"-- end of scenario at t = {sim.t:g} s; trains: "
         + (", ".join(f"{v.name} in {' '.join(v.sections) or 'nothing'} at {v.speed_kmh:g} km/h"
                      for v in sim.train_views()) or "none"))
    return finish(status)

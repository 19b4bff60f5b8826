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

from dataclasses import dataclass
from pathlib import Path

from liansuo.simulation.sim import LANGUAGE, Simulation
from liansuo.stations.loader import load
from liansuo.stations.source import Diagnostic, StationError, read_file
from liansuo.stations.validation import validate

from .fileschemas import ScenarioFile


@dataclass
class Scenario:
    file: str
    station: str
    description: str
    steps: list[tuple[str, int]]  # (command, line)
    until_s: float | None


def parse_scenario(path: Path) -> Scenario:
    """Read and check a scenario (:class:`~.fileschemas.ScenarioFile`, then every step a command of the language);
    :class:`StationError` with FILE:LINE:COLUMN diagnostics when malformed."""
    src = read_file(path, "give the path of a scenario file (see examples/scenarios/)")
    data = src.data
    if not isinstance(data, dict):
        raise StationError([src.diagnostic((), "a scenario is a mapping with 'station:' and 'steps:'", "")])
    errors: list[Diagnostic] = []
    steps = LANGUAGE.read_steps(src, ("steps",), data.get("steps"), errors)
    model = validate(src, ScenarioFile, errors, "scenario", "docs/trains.md")
    if errors or model is None:
        raise StationError(errors)
    return Scenario(str(path), model.station, str(model.description), steps, model.until)


def run_scenario(sc: Scenario, until_s: float | None = None, out: list[str] | None = None,
                 engine: str = "kinematic") -> tuple[int, Simulation]:
    """Run the scenario; returns (exit status, the simulation). Lines of the event log go to ``out`` (or stdout).
    ``engine``: the train engine, "kinematic" or "sumo" (see :class:`Simulation`)."""
    try:
        station = load(sc.station)
    except StationError:
        station = load(Path(sc.file).parent / sc.station)
    sim = Simulation(station, engine=engine)
    seen = [0, 0]  # events already printed from the interlocking and from the world

    def emit(text: str) -> None:
        if out is None:
            print(text)
        else:
            out.append(text)

    def flush() -> None:
        il_events, world = list(sim.view.events()), list(sim.events)
        new = sorted(il_events[seen[0]:] + world[seen[1]:], key=lambda e: e.t)
        seen[0], seen[1] = len(il_events), len(world)
        for e in new:
            emit(f"{e.t:9.2f} {e.kind:8} {e.text}")

    status = 0
    for command, line in sc.steps:
        result = sim.command(command)
        flush()
        if not result.ok and not command.strip().startswith("expect"):
            emit(f"{sc.file}:{line}: '{command}' refused: {result.message}")
            return 1, sim
        if command.strip().startswith("expect") and not result.ok:
            emit(f"{sc.file}:{line}: '{command}': {result.message}")
            status = 1
    end = until_s if until_s is not None else sc.until_s
    while end is not None and sim.t < end:
        sim.run(min(60.0, end - sim.t))
        flush()
    emit(f"-- end of scenario at t = {sim.t:g} s; trains: "
         + (", ".join(f"{v.name} in {' '.join(v.sections) or 'nothing'} at {v.speed_kmh:g} km/h"
                      for v in sim.train_views()) or "none"))
    return status, sim

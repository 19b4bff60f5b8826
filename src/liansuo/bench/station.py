"""The figures of one station: load, table build, and the interlocking cycle idle and busy (see the package's
docstring and docs/benchmark.md)."""

from __future__ import annotations

import gc
import time
from typing import Any, cast

from liansuo.bench.busy import BUSY_ROUTES, Traversal, busy_routes
from liansuo.bench.machine import peak_rss_mb
from liansuo.circuits.field import Field
from liansuo.interlocking.table.build import build_table
from liansuo.simulation.sim import Simulation
from liansuo.stations.loader import load, load_text
from liansuo.stations.station import Station


class _TimedField:
    """The simulation's field as the world reaches it, with the time spent in its step and in the track-circuit
    evaluations occupancy changes cause added up; everything else passes through. A stand-in rather than methods
    replaced on the field itself, which a native build's compiled field does not allow (docs/native.md)."""

    def __init__(self, fld: Field) -> None:
        self._field = fld
        self.spent = 0.0

    def __getattr__(self, name: str) -> Any:
        return getattr(self._field, name)

    def step(self, *args: Any) -> None:
        t0 = time.perf_counter()
        self._field.step(*args)
        self.spent += time.perf_counter() - t0

    def occupy(self, section: str) -> None:
        t0 = time.perf_counter()
        self._field.occupy(section)
        self.spent += time.perf_counter() - t0

    def vacate(self, section: str) -> None:
        t0 = time.perf_counter()
        self._field.vacate(section)
        self.spent += time.perf_counter() - t0


def _time_circuits(sim: Simulation) -> _TimedField:
    """Time spent in the trackside field while the busy run goes on (``spent`` of the returned stand-in)."""
    timed = _TimedField(sim.field)
    sim.field = cast(Field, timed)
    return timed


def _time_steps(sim: Simulation, cycles: int) -> float:
    step = sim.step
    t0 = time.perf_counter()
    for _ in range(cycles):
        step()
    return time.perf_counter() - t0


def measure(station_source: str, *, label: str, text: bool, idle_cycles: int, busy_cycles: int,
            routes_limit: int = BUSY_ROUTES, warmup_limit: int = 2400) -> dict[str, Any]:
    """Every figure for one station; ``station_source`` is YAML text (``text=True``) or a name or path."""
    gc.collect()
    t0 = time.perf_counter()
    station: Station = load_text(station_source, f"<{label}>") if text else load(station_source)
    t1 = time.perf_counter()
    table = build_table(station)
    t2 = time.perf_counter()
    out: dict[str, Any] = {
        "station": station.id,
        "turnouts": len(station.turnouts),
        "sections": len(station.sections),
        "signals": len(station.signals),
        "routes": len(table.routes),
        "load_s": round(t1 - t0, 4),
        "table_build_s": round(t2 - t1, 4),
    }
    conflicts = sum(len(r.conflicts) for r in table.routes.values())
    out["conflicting_pairs"] = conflicts // 2

    # idle: nothing set, nothing moving
    sim = Simulation(station, table=table)
    _time_steps(sim, 8)  # first indications and lamps
    gc.collect()
    idle_s = _time_steps(sim, idle_cycles)
    out["idle_cycles"] = idle_cycles
    out["cycle_us_idle"] = round(idle_s / idle_cycles * 1e6, 2)
    out["realtime_factor_idle"] = round(idle_cycles * sim.cycle_s / idle_s, 1)

    # busy: routes set, opened, traversed, released and set again
    sim = Simulation(station, table=table)
    _time_steps(sim, 8)
    routes = busy_routes(table, routes_limit)
    drivers = [Traversal(sim, r) for r in routes]
    cycle = 0
    while cycle < warmup_limit and not all(d.opened for d in drivers):
        for d in drivers:
            d.tick(cycle)
        sim.step()
        cycle += 1
    warmup = cycle
    for d in drivers:
        d.settings = d.traversals = d.stalls = 0
    gc.collect()
    stepping = 0.0
    step = sim.step
    perf = time.perf_counter
    circuit = _time_circuits(sim)
    start = perf()
    for _ in range(busy_cycles):
        for d in drivers:
            d.tick(cycle)
        s0 = perf()
        step()
        stepping += perf() - s0
        cycle += 1
    wall = perf() - start
    out["busy_routes"] = len(routes)
    out["busy_route_ids"] = [r.id for r in routes]
    out["busy_warmup_cycles"] = warmup
    out["busy_cycles"] = busy_cycles
    out["cycle_us_busy"] = round(stepping / busy_cycles * 1e6, 2)
    out["circuit_us_busy"] = round(circuit.spent / busy_cycles * 1e6, 2)
    out["realtime_factor"] = round(busy_cycles * sim.cycle_s / wall, 1)
    out["busy_route_settings"] = sum(d.settings for d in drivers)
    out["busy_traversals"] = sum(d.traversals for d in drivers)
    out["busy_stalls"] = sum(d.stalls for d in drivers)
    out["alarms"] = len(sim.view.alarms())
    out["peak_memory_mb"] = round(peak_rss_mb(), 1)
    return out

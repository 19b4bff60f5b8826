"""``liansuo bench``: how fast the table is derived and the interlocking cycles, on a generated hub and on jiaopei.

The benchmark is the one place that reads the wall clock (``time.perf_counter``); the simulation itself never does.
Figures are reported, never asserted: targets are listed with whether this machine met them. See docs/benchmark.md.

For each station:

* ``load_s``: YAML -> validated :class:`~stations.station.Station`; ``table_build_s``: :func:`build_table` on it;
* ``cycle_us_idle``: mean wall time of one :meth:`Simulation.step` (field step + interlocking cycle) with nothing
  happening;
* ``circuit_us_busy``: of the busy cycle, the time in the trackside field: its step (machines, lamps, flashers,
  doors) and the track-circuit re-evaluations the moving occupancy causes.
* ``cycle_us_busy``: the same with up to 20 non-conflicting train routes set, opened and traversed over and over: a
  driver occupies each route's approach and sections in order and vacates them behind (``field.occupy/vacate``, the
  teaching base's switch K), and sets the route again once it has released;
* ``realtime_factor``: simulated seconds per wall second over the busy run, driver and route commands included.

And on the hub, trains (``simulation.bench_trains``): ``realtime_factor_trains``, 10 signal-obeying trains running
through the hub on the kinematic engine, and ``realtime_factor_trains_sumo``, the same on the SUMO engine, with their
ratio (SUMO "not installed" where the extra is missing).

And once, station-independent: ``zpw_configs_per_s``, ZPW-2000A section configurations (carrier x ballast x
capacitor fault x shunt position) evaluated per second by the vectorised sweep of ``circuits.zpw2000a``.
"""

from __future__ import annotations

import gc
import json
import math
import os
import platform
import resource
import sys
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from liansuo.interlocking.table import InterlockingTable, Route, build_table
from liansuo.stations.hubgen import generate_hub
from liansuo.stations.loader import load, load_text
from liansuo.stations.station import Station

from .bench_trains import TARGET_TRAINS, run_trains, trains_text
from .sim import Simulation

HUB_TURNOUTS = 200
HUB_TRACKS = 80
BUSY_ROUTES = 20
DWELL_CYCLES = 4  # cycles a train head or tail spends before moving on by one section (1 s at 250 ms)

# (figure, comparison, target) per station; reported with the measured value, never asserted
TARGETS: dict[str, list[tuple[str, str, float]]] = {
    "hub": [("table_build_s", "<=", 5.0), ("cycle_us_busy", "<=", 1000.0), ("realtime_factor", ">=", 250.0)],
    "jiaopei": [("realtime_factor", ">=", 5000.0)],
}
ZPW_TARGET_CONFIGS_PER_S = 100_000.0
ZPW_BALLASTS = (1.0, 1.5, 2.0, 3.0, 5.0, 10.0)  # ohm*km


@dataclass(frozen=True)
class Sizes:
    """How much to run: the full benchmark, ``--quick``, or a tiny run for the test suite."""

    hub_turnouts: int = HUB_TURNOUTS
    hub_tracks: int = HUB_TRACKS
    idle_cycles: int = 8000
    busy_cycles: int = 16000
    small_factor: int = 5  # jiaopei runs this many times more cycles (each is much cheaper)
    busy_routes: int = BUSY_ROUTES
    warmup_limit: int = 2400  # cycles allowed for the busy routes to be set and opened once
    zpw_repeats: int = 10  # vectorised ZPW-2000A sweeps timed
    train_cycles: int = 4800  # trains moving on the hub, each engine (bench_trains.py); 0 skips it
    train_slots: int = 10

    @staticmethod
    def quick() -> Sizes:
        return Sizes(idle_cycles=1000, busy_cycles=2400, zpw_repeats=3, train_cycles=1200)

    @staticmethod
    def tiny() -> Sizes:
        return Sizes(hub_turnouts=20, hub_tracks=8, idle_cycles=20, busy_cycles=120, small_factor=1,
                     warmup_limit=400, zpw_repeats=1, train_cycles=240, train_slots=2)


def _peak_rss_mb() -> float:
    rss = resource.getrusage(resource.RUSAGE_SELF).ru_maxrss
    return rss / (1024 * 1024) if sys.platform == "darwin" else rss / 1024  # bytes on macOS, KiB on Linux


def _cpu_model() -> str:
    try:
        with open("/proc/cpuinfo", encoding="utf-8") as f:
            for line in f:
                if line.startswith("model name"):
                    return line.split(":", 1)[1].strip()
    except OSError:
        pass
    return ""


def machine() -> dict[str, Any]:
    return {
        "processor": platform.processor(),
        "cpu_model": _cpu_model(),
        "cpu_count": os.cpu_count(),
        "machine": platform.machine(),
        "system": platform.platform(),
        "python": platform.python_version(),
        "implementation": platform.python_implementation(),
    }


# ---- the busy scenario ---------------------------------------------------------------------------------------------
def _uses_beyond(r: Route) -> bool:
    """A route's last section releases once the train is beyond it, except on a receiving track."""
    return r.beyond is not None and r.category != "receiving"


def _footprint(r: Route) -> set[str]:
    """Every section a traversal of ``r`` occupies or the route locks."""
    return set(r.all_sections) | set(r.approach) | ({r.beyond} if r.beyond and _uses_beyond(r) else set())


def busy_routes(table: InterlockingTable, limit: int = BUSY_ROUTES) -> list[Route]:
    """Up to ``limit`` routes that can be set at once and traversed without touching each other.

    Greedy over receiving routes, then transfers, departures onto lines without a 64D block (a 64D departure would
    also need the block line worked) and shunting routes, shortest routes first."""
    order = {"receiving": 0, "transfer": 1, "departure": 2, "shunting": 3}
    candidates = [r for r in table.routes.values() if r.category in order
                  and not (r.exit_link and any(lk.id == r.exit_link and lk.kind.value == "64d"
                                               for lk in table.station.model.links))]
    candidates.sort(key=lambda r: (order[r.category], len(r.sections), r.id))
    chosen: list[Route] = []
    used: set[str] = set()
    signals: set[str] = set()
    for r in candidates:
        if len(chosen) >= limit:
            break
        fp = _footprint(r)
        if r.signal in signals or fp & used or any(c.id in r.conflicts for c in chosen):
            continue
        chosen.append(r)
        used |= fp
        signals.add(r.signal)
    return chosen


class _Traversal:
    """Sets one route again and again and moves an imaginary train through it by occupying and vacating sections."""

    def __init__(self, sim: Simulation, route: Route) -> None:
        self.sim = sim
        self.route = route
        seq = list(route.approach) + list(route.sections)
        if route.beyond and _uses_beyond(route):
            seq.append(route.beyond)
        self.seq = list(dict.fromkeys(seq))
        verb = "route" if route.kind == "train" else "shunt"
        self.command = " ".join([verb, route.start, *route.via, route.end])
        self.state = "idle"
        self.head = self.tail = -1
        self.next_tick = 0
        self.since = 0
        self.settings = 0
        self.traversals = 0
        self.stalls = 0
        self.opened = False

    def tick(self, cycle: int) -> None:
        sim = self.sim
        if self.state == "idle":
            if (cycle >= self.next_tick and sim.route_state(self.route.id) == "released"
                    and sim.command(self.command).ok):
                self.settings += 1
                self.state, self.since = "setting", cycle
            return
        if self.state == "setting":
            if sim.route_state(self.route.id) == "open":
                self.opened = True
                self.head = self.tail = 0
                sim.field.occupy(self.seq[0])
                self.state, self.next_tick, self.since = "moving", cycle + DWELL_CYCLES, cycle
            elif cycle - self.since > 400:  # 100 s without opening: count it and start again
                self._stall()
            return
        if cycle < self.next_tick:
            return
        last = len(self.seq) - 1
        if self.tail < self.head:
            sim.field.vacate(self.seq[self.tail])
            self.tail += 1
        elif self.head < last:
            self.head += 1
            sim.field.occupy(self.seq[self.head])
        elif sim.route_state(self.route.id) == "released":
            sim.field.vacate(self.seq[self.head])
            self.traversals += 1
            self.state, self.next_tick = "idle", cycle + DWELL_CYCLES
            return
        elif cycle - self.since > 4 * DWELL_CYCLES * (last + 2) + 400:
            self._stall()
            return
        self.next_tick = cycle + DWELL_CYCLES

    def _stall(self) -> None:
        """The route did not open or release as expected: record it, clear the field and release the route."""
        self.stalls += 1
        for s in self.seq:
            self.sim.field.vacate(s)
        if self.sim.route_state(self.route.id) != "released":
            self.sim.command(f"release {self.route.signal}")
        self.state, self.next_tick = "idle", 0


# ---- measuring -----------------------------------------------------------------------------------------------------
def _time_circuits(sim: Simulation) -> list[float]:
    """Time spent in the trackside field (its step, and the track-circuit evaluations occupancy changes cause),
    accumulated in the returned one-element list while the busy run goes on."""
    spent = [0.0]
    fld = sim.field
    perf = time.perf_counter

    def timed(fn: Callable[..., None]) -> Callable[..., None]:
        def wrapper(*args: Any) -> None:
            t0 = perf()
            fn(*args)
            spent[0] += perf() - t0
        return wrapper

    fld.step = timed(fld.step)  # type: ignore[method-assign]
    fld.occupy = timed(fld.occupy)  # type: ignore[method-assign]
    fld.vacate = timed(fld.vacate)  # type: ignore[method-assign]
    return spent


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
    drivers = [_Traversal(sim, r) for r in routes]
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
    out["circuit_us_busy"] = round(circuit[0] / busy_cycles * 1e6, 2)
    out["realtime_factor"] = round(busy_cycles * sim.cycle_s / wall, 1)
    out["busy_route_settings"] = sum(d.settings for d in drivers)
    out["busy_traversals"] = sum(d.traversals for d in drivers)
    out["busy_stalls"] = sum(d.stalls for d in drivers)
    out["alarms"] = len(sim.view.alarms())
    out["peak_memory_mb"] = round(_peak_rss_mb(), 1)
    return out


def measure_zpw(repeats: int = 10, length_m: float = 1400.0) -> dict[str, Any]:
    """``zpw_configs_per_s``: one sweep of a ``length_m`` section with standard capacitors over every carrier (8),
    ``ZPW_BALLASTS``, no fault plus every single capacitor fault (open, -50 %, short) and a 0.15 ohm shunt every
    10 m; a configuration is one (carrier, ballast, fault case, shunt position): receiver voltage and cab current."""
    from liansuo.circuits.zpw2000a import ZpwCircuit, standard_positions, sweep

    sweep([length_m], ballasts=ZPW_BALLASTS)  # warm-up
    gc.collect()
    t0 = time.perf_counter()
    for _ in range(repeats):
        result = sweep([length_m], ballasts=ZPW_BALLASTS)[0]
    elapsed = time.perf_counter() - t0
    configs = result.configurations
    # the live simulation's call: one section, one shunt (a moving wheelset) or a 64-axle train
    circuit = ZpwCircuit(length_m, "2600-1", standard_positions(length_m))
    calls = 200 * repeats
    t1 = time.perf_counter()
    for k in range(calls):
        circuit.evaluate([(k * 7.0 % length_m, 0.15)])
    t2 = time.perf_counter()
    for k in range(calls // 10):
        circuit.evaluate([(k % 500 + 2.5 * axle, 0.15) for axle in range(64)])
    t3 = time.perf_counter()
    return {
        "evaluate_us_one_shunt": round((t2 - t1) / calls * 1e6, 1),
        "evaluate_us_train64": round((t3 - t2) / (calls // 10) * 1e6, 1),
        "length_m": length_m, "carriers": len(result.carriers), "ballasts": len(result.ballasts_ohm_km),
        "fault_cases": len(result.faults), "shunt_positions": len(result.positions_m),
        "configurations": configs, "sweeps": repeats, "sweep_s": round(elapsed / repeats, 5),
        "zpw_configs_per_s": round(configs * repeats / elapsed, 1),
    }


def _check_targets(results: dict[str, dict[str, Any]]) -> list[dict[str, Any]]:
    checks = []
    for key, targets in TARGETS.items():
        res = results.get(key)
        if res is None:
            continue
        for figure, op, target in targets:
            value = float(res[figure])
            met = value <= target if op == "<=" else value >= target
            checks.append({"station": res["station"], "figure": figure, "target": f"{op} {target:g}",
                           "value": value, "met": met})
    return checks


def run_bench(sizes: Sizes | None = None, *, quick: bool = False, stations: tuple[str, ...] = ("jiaopei", "hub"),
              ) -> dict[str, Any]:
    """Run the benchmark and return every figure (see the module docstring and docs/benchmark.md)."""
    sizes = sizes or (Sizes.quick() if quick else Sizes())
    start = time.perf_counter()
    results: dict[str, dict[str, Any]] = {}
    for key in stations:  # the small station first, so its peak memory is its own
        if key == "hub":
            text = generate_hub(sizes.hub_turnouts, sizes.hub_tracks)
            results[key] = measure(text, label=f"hub{sizes.hub_turnouts}", text=True,
                                   idle_cycles=sizes.idle_cycles, busy_cycles=sizes.busy_cycles,
                                   routes_limit=sizes.busy_routes, warmup_limit=sizes.warmup_limit)
            results[key]["hub_tracks"] = sizes.hub_tracks
        else:
            results[key] = measure(key, label=key, text=False, idle_cycles=sizes.idle_cycles * sizes.small_factor,
                                   busy_cycles=sizes.busy_cycles * sizes.small_factor,
                                   routes_limit=sizes.busy_routes, warmup_limit=sizes.warmup_limit)
    zpw = measure_zpw(sizes.zpw_repeats)
    trains = _trains(sizes) if "hub" in stations and sizes.train_cycles > 0 else None
    targets = _check_targets(results)
    targets.append({"station": "zpw", "figure": "zpw_configs_per_s", "target": f">= {ZPW_TARGET_CONFIGS_PER_S:g}",
                    "value": zpw["zpw_configs_per_s"], "met": zpw["zpw_configs_per_s"] >= ZPW_TARGET_CONFIGS_PER_S})
    if trains is not None:
        value = trains["realtime_factor_trains"]
        targets.append({"station": trains["station"], "figure": "realtime_factor_trains",
                        "target": f">= {TARGET_TRAINS:g}", "value": value, "met": value >= TARGET_TRAINS})
    return {
        "benchmark": "liansuo bench",
        "mode": "quick" if quick else ("custom" if sizes != Sizes() else "full"),
        "machine": machine(),
        "cycle_s": 0.25,
        "results": results,
        "zpw": zpw,
        **({"trains": trains} if trains is not None else {}),
        "targets": targets,
        "total_s": round(time.perf_counter() - start, 2),
    }


def _trains(sizes: Sizes) -> dict[str, Any]:
    """Trains moving on the hub: the kinematic engine and SUMO side by side (bench_trains.py)."""
    station = load_text(generate_hub(sizes.hub_turnouts, sizes.hub_tracks), f"<hub{sizes.hub_turnouts}>")
    return run_trains(station, build_table(station), cycles=sizes.train_cycles, sumo_cycles=sizes.train_cycles,
                      slots=sizes.train_slots)


def all_finite(value: object) -> bool:
    """True when every number in a (nested) benchmark result is finite."""
    if isinstance(value, dict):
        return all(all_finite(v) for v in value.values())
    if isinstance(value, list):
        return all(all_finite(v) for v in value)
    if isinstance(value, float):
        return math.isfinite(value)
    return True


# ---- output --------------------------------------------------------------------------------------------------------
_TEXT_ROWS = [
    ("turnouts", "turnouts", "{:d}"), ("sections", "sections", "{:d}"), ("routes", "routes", "{:d}"),
    ("load_s", "load (s)", "{:.3f}"), ("table_build_s", "table build (s)", "{:.3f}"),
    ("cycle_us_idle", "cycle idle (us)", "{:.1f}"), ("cycle_us_busy", "cycle busy (us)", "{:.1f}"),
    ("circuit_us_busy", "  of it circuits (us)", "{:.1f}"),
    ("busy_routes", "busy routes", "{:d}"), ("realtime_factor", "real-time factor (busy)", "{:.0f}x"),
    ("realtime_factor_idle", "real-time factor (idle)", "{:.0f}x"), ("busy_traversals", "traversals", "{:d}"),
    ("busy_stalls", "stalls", "{:d}"), ("peak_memory_mb", "peak RSS (MB)", "{:.1f}"),
]


def as_text(report: dict[str, Any]) -> str:
    m = report["machine"]
    lines = [f"liansuo bench ({report['mode']}) on {m['cpu_model'] or m['processor'] or m['machine']}, "
             f"{m['cpu_count']} CPUs, Python {m['python']}"]
    results = report["results"]
    keys = list(results)
    lines.append(f"{'':26}" + "".join(f"{results[k]['station']:>14}" for k in keys))
    for field, title, fmt in _TEXT_ROWS:
        lines.append(f"{title:26}" + "".join(f"{fmt.format(results[k][field]):>14}" for k in keys))
    z = report.get("zpw")
    if z:
        lines.append(f"{'zpw configs/s':26}{z['zpw_configs_per_s']:>14.0f}  ({z['configurations']} per sweep of "
                     f"{z['sweep_s'] * 1000:.1f} ms; evaluate {z['evaluate_us_one_shunt']:.0f} us, 64-axle train "
                     f"{z['evaluate_us_train64']:.0f} us)")
    if report.get("trains"):
        lines += trains_text(report["trains"])
    lines.append("targets:")
    for t in report["targets"]:
        lines.append(f"  {t['station']:10} {t['figure']:16} {t['target']:>8}  measured {t['value']:g}  "
                     f"{'met' if t['met'] else 'MISSED'}")
    lines.append(f"total {report['total_s']:.1f} s")
    return "\n".join(lines)


def main(quick: bool = False, fmt: str = "json") -> int:
    report = run_bench(quick=quick)
    print(json.dumps(report, indent=2) if fmt == "json" else as_text(report))
    return 0

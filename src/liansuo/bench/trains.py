"""The trains figure of ``liansuo bench``: real trains moving on the generated 200-turnout hub, on each engine.

``realtime_factor_trains``: simulated seconds per wall second with ``TRAIN_SLOTS`` (10) signal-obeying freight trains
moving at once through the hub, driven by the kinematic engine; ``realtime_factor_trains_sumo``: the same scenario on
the SUMO engine (when the ``sumo`` extra is installed), and their ratio. Each slot is a receiving route and the
departure from the track it ends on, chosen so that no two slots' routes conflict or share a section. A slot's
dispatcher places a train in the approach section, sets the receiving route, lets the train run in and stop at the
closed starting signal, sets the departure once the receiving route has released, and places the next train when
this one has left the station; a train that has not left ten minutes after it was placed counts as a stall and is
removed. The whole simulation is timed (field, interlocking, trains, dispatching); starting SUMO is not.
"""

from __future__ import annotations

import gc
import time
from dataclasses import dataclass
from typing import Any

from liansuo.interlocking.table.build import InterlockingTable, Route
from liansuo.simulation.sim import Simulation
from liansuo.simulation.trains.sumo import sumo_installed
from liansuo.stations.station import Station

TRAIN_SLOTS = 10
TRAIN_LENGTH_M = 300.0
TICK_CYCLES = 4  # the dispatchers look once a simulated second
STALL_S = 600.0
TARGET_TRAINS = 250.0  # realtime_factor_trains >= 250x on hub200
TARGET_RATIO = 5.0  # ratio_kinematic_to_sumo >= 5x on hub200, side by side in one run (issue 13)


def _footprint(r: Route) -> set[str]:
    return set(r.all_sections) | set(r.approach) | ({r.beyond} if r.beyond else set())


def train_slots(table: InterlockingTable, count: int = TRAIN_SLOTS) -> list[tuple[Route, Route]]:
    """Up to ``count`` (receiving route, departure route from its end signal) pairs, pairwise free of conflicts and
    of shared sections, shortest first, alternating the directions."""
    routes = table.routes
    pairs: list[tuple[Route, Route]] = []
    for r in routes.values():
        if r.category != "receiving" or not r.approach:
            continue
        for d in routes.values():
            if d.category == "departure" and d.start == r.end and d.kind == r.kind and not d.exit_link:
                pairs.append((r, d))
    pairs.sort(key=lambda p: (len(p[0].sections) + len(p[1].sections), p[0].id))
    chosen: list[tuple[Route, Route]] = []
    used: set[str] = set()
    for want in ("down", "up") * count:
        for r, d in pairs:
            if len(chosen) >= count:
                return chosen
            if r.direction.value != want:
                continue
            fp = _footprint(r) | _footprint(d)
            ids = {c.id for pair in chosen for c in pair}
            if fp & used or any(i in r.conflicts or i in d.conflicts for i in ids) or \
                    any(r.signal == c.signal for c, _ in chosen):
                continue
            chosen.append((r, d))
            used |= fp
            break
    return chosen


@dataclass
class _Dispatcher:
    """One slot: place a train, receive it, send it on, and again."""

    sim: Simulation
    name: str
    receive: Route
    depart: Route
    state: str = "idle"
    since: float = 0.0
    departures: int = 0
    stalls: int = 0
    refused: int = 0

    def _command(self, line: str) -> bool:
        ok = self.sim.command(line).ok
        self.refused += not ok
        return ok

    def _route(self, r: Route) -> str:
        return " ".join(["route", *r.buttons])

    def tick(self) -> None:
        sim = self.sim
        train = sim.fleet.trains.get(self.name)
        if self.state == "idle":
            if (sim.route_state(self.receive.id) == "released" and sim.route_state(self.depart.id) == "released"
                    and all(sim.section_state(s) == "free" for s in self.receive.approach)
                    and self._command(f"train {self.name} at {self.receive.approach[0]} mode=signal "
                                      f"length={TRAIN_LENGTH_M:g}")
                    and self._command(self._route(self.receive))):
                self.state, self.since = "arriving", sim.t
            return
        if sim.t - self.since > STALL_S:
            self.stalls += 1
            if train is not None:
                sim.command(f"train {self.name} remove")
            self.state = "idle"
            return
        if self.state == "arriving":
            if (train is not None and train.speed_ms == 0.0 and sim.route_state(self.receive.id) == "released"
                    and sim.t - self.since > 10.0 and self._command(self._route(self.depart))):
                self.state = "departing"
        elif self.state == "departing" and train is None:
            self.departures += 1
            self.state = "idle"


def _time_engine(sim: Simulation) -> list[float]:
    """Wall time spent in the train engine's ``step`` (SUMO: the round trip to the worker included), accumulated in
    the returned one-element list."""
    spent = [0.0]
    engine = sim.fleet.engine
    inner = engine.step
    perf = time.perf_counter

    def timed(dt: float, targets: Any, limits: Any) -> dict[str, tuple[float, float]]:
        t0 = perf()
        try:
            return inner(dt, targets, limits)
        finally:
            spent[0] += perf() - t0

    engine.step = timed  # type: ignore[method-assign]
    return spent


def measure_trains(station: Station, table: InterlockingTable, engine: str, cycles: int,
                   slots: int = TRAIN_SLOTS) -> dict[str, Any]:
    """Run the trains scenario for ``cycles`` cycles on ``engine`` and return its figures."""
    gc.collect()
    t0 = time.perf_counter()
    sim = Simulation(station, table=table, engine=engine)
    started = time.perf_counter() - t0
    try:
        dispatchers = [_Dispatcher(sim, f"B{i + 1}", r, d) for i, (r, d) in enumerate(train_slots(table, slots))]
        moving = 0
        samples = 0
        step = sim.step
        perf = time.perf_counter
        in_engine = _time_engine(sim)
        start = perf()
        for cycle in range(cycles):
            if cycle % TICK_CYCLES == 0:
                for d in dispatchers:
                    d.tick()
                moving += sum(1 for tr in sim.fleet.trains.values() if tr.speed_ms > 0.0)
                samples += 1
            step()
        wall = perf() - start
        out: dict[str, Any] = {
            "engine": engine,
            "start_s": round(started, 3),
            "cycles": cycles,
            "simulated_s": round(cycles * sim.cycle_s, 1),
            "wall_s": round(wall, 3),
            "cycle_us": round(wall / cycles * 1e6, 1),
            "engine_us": round(in_engine[0] / cycles * 1e6, 1),
            "realtime_factor": round(cycles * sim.cycle_s / wall, 1),
            "slots": len(dispatchers),
            "mean_trains_moving": round(moving / max(samples, 1), 2),
            "departures": sum(d.departures for d in dispatchers),
            "stalls": sum(d.stalls for d in dispatchers),
            "refused_commands": sum(d.refused for d in dispatchers),
            "alarms": len(sim.alarm_texts()),
        }
        counts = getattr(sim.fleet.engine, "counts", None)
        if counts is not None:
            out["sumo_corrections"] = dict(counts)
            out["engine_failed"] = str(getattr(sim.fleet.engine, "failed", ""))
        return out
    finally:
        sim.close()


def run_trains(station: Station, table: InterlockingTable, *, cycles: int, sumo_cycles: int,
               slots: int = TRAIN_SLOTS) -> dict[str, Any]:
    """``realtime_factor_trains`` (kinematic), ``realtime_factor_trains_sumo`` and the ratio, side by side."""
    kin = measure_trains(station, table, "kinematic", cycles, slots)
    out: dict[str, Any] = {"station": station.id, "trains": kin["slots"], "kinematic": kin,
                           "realtime_factor_trains": kin["realtime_factor"]}
    missing = sumo_installed()
    if missing:
        out["sumo"] = {"engine": "sumo", "status": f"not installed: {missing}"}
        out["realtime_factor_trains_sumo"] = None
        out["ratio_kinematic_to_sumo"] = None
        return out
    try:
        sumo = measure_trains(station, table, "sumo", sumo_cycles, slots)
    except RuntimeError as exc:  # SUMO could not start here: report it, the rest of the benchmark stands
        out["sumo"] = {"engine": "sumo", "status": f"failed: {exc}"}
        out["realtime_factor_trains_sumo"] = None
        out["ratio_kinematic_to_sumo"] = None
        return out
    sumo["status"] = "ok" if not sumo.get("engine_failed") else f"failed: {sumo['engine_failed']}"
    out["sumo"] = sumo
    out["realtime_factor_trains_sumo"] = sumo["realtime_factor"]
    out["ratio_kinematic_to_sumo"] = round(kin["realtime_factor"] / sumo["realtime_factor"], 2)
    out["engine_ratio_sumo_to_kinematic"] = round(sumo["engine_us"] / max(kin["engine_us"], 0.01), 1)
    return out


def trains_text(t: dict[str, Any]) -> list[str]:
    """The trains figures as text lines, the two engines side by side."""
    kin, sumo = t["kinematic"], t["sumo"]
    lines = [f"trains on {t['station']} ({t['trains']} signal-obeying trains){'':4}{'kinematic':>12}{'sumo':>12}"]
    rows = [("realtime_factor", "real-time factor", "{:.0f}x"), ("cycle_us", "cycle (us)", "{:.0f}"),
            ("engine_us", "  of it in the engine (us)", "{:.0f}"),
            ("simulated_s", "simulated (s)", "{:.0f}"), ("mean_trains_moving", "trains moving (mean)", "{:.1f}"),
            ("departures", "trains gone through", "{:d}"), ("stalls", "stalls", "{:d}"),
            ("start_s", "engine start (s)", "{:.2f}")]
    for key, title, fmt in rows:
        right = fmt.format(sumo[key]) if key in sumo else "-"
        lines.append(f"  {title:50}{fmt.format(kin[key]):>12}{right:>12}")
    if t["ratio_kinematic_to_sumo"] is not None:
        lines.append(f"  {'kinematic / sumo':50}{t['ratio_kinematic_to_sumo']:>12.1f}x")
    else:
        lines.append(f"  sumo: {sumo.get('status', '')}")
    return lines


__all__ = ["TARGET_RATIO", "TARGET_TRAINS", "TRAIN_SLOTS", "measure_trains", "run_trains", "train_slots", "trains_text"]

"""Random operation of a station for the safety properties (``liansuo soak``, tests/test_oracle.py).

A :class:`StepGenerator` draws one step at a time: a console command (routes, cancel, release, reopen, guide,
turnouts, 64D, station block, doors), a field or instructor action (occupancy, faults and repairs, counter resets), a
movement, or a wait. Every step is a line of the command language, so a run is a script: :func:`soak` records it,
and a violation comes with the lines that lead to it. Movements are trains (``train``, ``drive``, ``stop``,
``auto``, ``reverse``) when the command language has them, and always sets of wheelsets (``axles``) walked along a
route from its approach to beyond its end, a short train-like consist that shunts each section it stands on.
"""

from __future__ import annotations

import random
import time
from dataclasses import dataclass, field
from pathlib import Path

from liansuo.interlocking.aspects import is_open
from liansuo.interlocking.table.build import Route
from liansuo.proving.oracle import Violation, Watch
from liansuo.simulation.sim import Simulation
from liansuo.stations.schema import Direction
from liansuo.stations.station import Station

WALK_STEP_M = 12.0  # a walker's wheelsets advance this far per step
MAX_TRAINS = 3
MAX_WALKERS = 3


@dataclass
class Walker:
    """Wheelsets walking a route: ``points`` are (track, position) along it, ``at`` the leading one."""

    route: str
    points: list[tuple[str, float]]
    at: int = 0


class StepGenerator:
    def __init__(self, sim: Simulation, rng: random.Random) -> None:
        self.sim = sim
        self.rng = rng
        st = sim.station
        self.routes = list(sim.table.routes.values())
        self.signals = [s.id for s in st.model.signals if s.kind.value != "block"]
        self.sections = list(st.sections)
        self.turnouts = list(st.turnouts)
        self.throats = list(sim.table.throats)
        self.links64 = [lk.id for lk in st.model.links if lk.kind.value == "64d"]
        self.station_lines = [lk.id for lk in st.model.links if lk.kind.value == "station"]
        self.counted = [s.id for s in st.model.sections if s.type.value == "axle_counter"]
        self.platforms = [p.id for p in st.model.platforms if p.screen_doors]
        self.usu = [s.id for s in st.model.signals if s.usu]
        self.joints = list(st.joints)
        self.zpw = [s.id for s in st.model.sections if s.type.value == "zpw2000a"]
        self.walkers: dict[str, Walker] = {}
        self.serial = 0
        self.trains = "train" in sim.language
        families = [(self.route, 18), (self.signal_op, 10), (self.turnout_op, 6), (self.occupancy, 5),
                    (self.fault, 4), (self.disturb, 6), (self.repair, 6), (self.walk, 22), (self.wait, 3)]
        if self.links64:
            families.append((self.block_line, 4))
        if self.station_lines:
            families.append((self.station_block, 3))
        if self.platforms:
            families.append((self.doors, 3))
        if self.trains:
            families.append((self.train, 16))
        self.families = [f for f, _ in families]
        self.weights = [w for _, w in families]

    def next(self) -> tuple[list[str], int]:
        """The lines of the next step, and how many cycles to run after them."""
        family = self.rng.choices(self.families, self.weights)[0]
        lines = family()
        return lines, self.rng.randint(1, 8)

    # ---- console ------------------------------------------------------------------------------------------------
    def route(self) -> list[str]:
        il = self.sim.interlocking
        free = [r for r in self.routes if r.signal not in il.by_signal]
        r = self.rng.choice(free or self.routes)
        word = "route" if r.kind == "train" else "shunt"
        return [" ".join([word, *r.buttons])]

    def signal_op(self) -> list[str]:
        il = self.sim.interlocking
        busy = list(il.by_signal) + list(il.core.guide_only)
        sig = self.rng.choice(busy) if busy and self.rng.random() < 0.85 else self.rng.choice(self.signals)
        op = self.rng.choices(["cancel", "release", "reopen", "guide"], [4, 3, 4, 1])[0]
        if op == "release" and self.rng.random() < 0.3:
            locked = sorted(il.locks.sections)
            if locked:
                return [f"fault-release {self.rng.choice(locked)}"]
        return [f"{op} {sig}"]

    def turnout_op(self) -> list[str]:
        t = self.rng.choice(self.turnouts)
        op = self.rng.choices(["throw", "lock", "unlock", "block", "unblock", "guide-lock", "guide-unlock"],
                              [8, 2, 3, 1, 2, 1, 2])[0]
        if op == "throw":
            return [f"throw {t} {self.rng.choice(['normal', 'reverse'])}"]
        if op.startswith("guide"):
            return [f"{op} {self.rng.choice(self.throats)}"] if self.throats else []
        return [f"{op} {t}"]

    def block_line(self) -> list[str]:
        link = self.rng.choice(self.links64)
        if self.rng.random() < 0.3:
            return [f"neighbour {link} {self.rng.choice(['request', 'depart', 'restore', 'accident'])}"]
        return [f"block-line {link} {self.rng.choice(['request', 'request', 'accept', 'cancel', 'restore'])}"]

    def station_block(self) -> list[str]:
        """The neighbour's departures on a station-block line, and the operator's counter reset (计轴复零)."""
        if self.counted and self.rng.random() < 0.3:
            return [f"axle-reset {self.rng.choice(self.counted)}"]
        return [f"neighbour {self.rng.choice(self.station_lines)} {self.rng.choice(['block', 'cancel'])}"]

    def doors(self) -> list[str]:
        return [f"doors {self.rng.choice(self.platforms)} {self.rng.choice(['open', 'close', 'close'])}"]

    # ---- field and instructor ------------------------------------------------------------------------------------
    def occupancy(self) -> list[str]:
        occupied = [s for s, c in self.sim.field.circuits.items() if c.k_switch]
        if occupied and self.rng.random() < 0.6:
            return [f"vacate {self.rng.choice(occupied)}"]
        return [f"occupy {self.rng.choice(self.sections)}"]

    def fault(self) -> list[str]:
        rng = self.rng
        kind = rng.choice(["broken-rail", "poor-shunt", "insulation", "filament", "filament", "no-indication",
                           "obstruction", "high-resistance", "squeezed", "flasher", "capacitor", "low-ballast",
                           "psd-stuck", "psd-no-close", "psd-no-open", "psd-bypass", "axle-miscount"])
        if kind == "axle-miscount":
            return [f"fault axle-miscount {rng.choice(self.counted)}"] if self.counted else []
        if kind in ("broken-rail", "poor-shunt", "low-ballast"):
            return [f"fault {kind} {rng.choice(self.sections)}"]
        if kind == "capacitor":
            return [f"fault capacitor {rng.choice(self.zpw)} n=1 mode={rng.choice(['open', 'half', 'short'])}"] \
                if self.zpw else []
        if kind == "insulation":
            return [f"fault insulation {rng.choice(self.joints + self.turnouts)}"]
        if kind == "filament":
            sig = self.sim.station.signals[rng.choice(self.signals)]
            lamp = rng.choice([lamp.value for lamp in sig.lamps])
            return [f"fault filament {sig.id} lamp={lamp} which={rng.choice(['both', 'both', 'main'])}"]
        if kind == "flasher":
            return [f"fault flasher {rng.choice(self.usu)}"] if self.usu else []
        if kind.startswith("psd"):
            return [f"fault {kind} {rng.choice(self.platforms)}"] if self.platforms else []
        return [f"fault {kind} {rng.choice(self.turnouts)}"]

    def disturb(self) -> list[str]:
        """Take away a condition of an open route: a section occupied, a turnout's indication, a lamp, the doors."""
        il, rng = self.sim.interlocking, self.rng
        open_routes = [rs.route for rs in il.routes.values() if is_open(il.out.signals.get(rs.route.signal, ""))]
        if not open_routes:
            return self.fault()
        r = rng.choice(open_routes)
        what = rng.choice(["section", "section", "turnout", "lamp", "doors"])
        if what == "turnout" and r.all_turnouts:
            return [f"fault {rng.choice(['no-indication', 'no-indication', 'squeezed'])} "
                    f"{rng.choice(r.all_turnouts).id}"]
        if what == "lamp":
            lamps = [lamp.value for lamp in self.sim.station.signals[r.signal].lamps]
            return [f"fault filament {r.signal} lamp={rng.choice(lamps)} which=both"]
        if what == "doors" and self.platforms:
            return [f"fault psd-stuck {rng.choice(self.platforms)}"]
        return [f"occupy {rng.choice(r.all_sections)}"]

    def repair(self) -> list[str]:
        active = sorted(self.sim.field.faults)
        if not active:
            return []
        kind, target = self.rng.choice(active)
        return [f"repair {kind} {target}"]

    def wait(self) -> list[str]:
        return [f"run {self.rng.choice([5, 10, 30, 60, 200])}s"]

    # ---- movements -----------------------------------------------------------------------------------------------
    def walk(self) -> list[str]:
        """Advance a walker (or start one on a route, preferring routes whose signal is open)."""
        if self.walkers and (len(self.walkers) >= MAX_WALKERS or self.rng.random() < 0.8):
            name = self.rng.choice(sorted(self.walkers))
            w = self.walkers[name]
            w.at += self.rng.choice([1, 1, 2, 3])
            if w.at >= len(w.points):
                del self.walkers[name]
                return [f"axles {name} clear"]
            return [self._axles_line(name, w)]
        il = self.sim.interlocking
        open_routes = [il.routes[rid].route for rid in il.by_signal.values()
                       if rid in il.routes and is_open(il.out.signals.get(il.routes[rid].route.signal, ""))]
        r = self.rng.choice(open_routes) if open_routes and self.rng.random() < 0.7 else self.rng.choice(self.routes)
        points = self._points(r)
        if len(points) < 2:
            return []
        self.serial += 1
        name = f"W{self.serial}"
        self.walkers[name] = Walker(r.id, points)
        return [self._axles_line(name, self.walkers[name])]

    def _axles_line(self, name: str, w: Walker) -> str:
        """Four wheelsets: two at the leading point, two at the one behind (a two-bogie vehicle)."""
        words = [f"axles {name}"]
        for i in (w.at, w.at - 1):
            if i < 0:
                continue
            track, x = w.points[i]
            lo, hi = self.sim.station.track_span(track)
            b = min(hi, max(lo, x + 2.5))
            words.append(f"{track} {x:g} {b:g}")
        return " ".join(words)

    def _points(self, r: Route) -> list[tuple[str, float]]:
        st = self.sim.station
        tracks: list[str] = []
        rear = st.signal_rear_track(r.signal)
        if rear is not None:
            tracks.append(rear)
        tracks += list(r.path.tracks)
        if r.end_node in st.joints:
            tracks.append(st.entry_track(r.end_node, r.direction))
        points: list[tuple[str, float]] = []
        down = r.direction is Direction.down
        for k, t in enumerate(tracks):
            lo, hi = st.track_span(t)
            xs = [lo + 1.0 + i * WALK_STEP_M for i in range(max(1, int((hi - lo - 2.0) // WALK_STEP_M) + 1))]
            xs = [x for x in xs if x <= hi - 1.0] or [(lo + hi) / 2]
            if not down:
                xs.reverse()
            if k == 0 and rear is not None:
                xs = xs[-4:]  # start just in rear of the signal
            if k == len(tracks) - 1 and r.end_node in st.joints:
                xs = xs[:4]
            points += [(t, round(x, 1)) for x in xs]
        return points

    def train(self) -> list[str]:
        rng = self.rng
        trains = sorted(self.sim.fleet.trains)
        if trains and (len(trains) >= MAX_TRAINS or rng.random() < 0.75):
            name = rng.choice(trains)
            op = rng.choices(["drive", "stop", "auto", "remove", "reverse"], [6, 3, 1, 1, 1])[0]
            if op == "drive":
                return [f"drive {name} {rng.choice([5, 15, 30, 45])}"]
            if op == "remove":
                return [f"train {name} remove"]
            return [f"{op} {name}"]
        r = rng.choice(self.routes)
        approach = r.approach[0] if r.approach else r.sections[0]
        self.serial += 1
        mode = rng.choice(["signal", "signal", "manual"])
        movement = "shunt" if r.kind == "shunt" else "train"
        kind = rng.choice(["freight", "emu", "shunter"]) if movement == "train" else "shunter"
        line = (f"train T{self.serial} at {approach} mode={mode} movement={movement} kind={kind} "
                f"length={rng.choice([40, 80, 150])} dir={r.direction.value}")
        return [line] + ([f"drive T{self.serial} {rng.choice([10, 20, 30])}"] if mode == "manual" else [])


@dataclass
class SoakRun:
    station: str  # the station's id
    seed: int
    steps: int
    source: str = ""  # what loads it again: a bundled name, or the station file's absolute path
    lines: list[str] = field(default_factory=list)  # the whole run as command lines
    line_of_step: list[int] = field(default_factory=list)  # index into ``lines`` after each step
    violations: list[tuple[Violation, int]] = field(default_factory=list)  # (violation, lines up to it)
    refused: int = 0
    hazards: dict[str, int] = field(default_factory=dict)  # property -> how often: dangers it cannot see by design
    elapsed_s: float = 0.0
    simulated_s: float = 0.0
    cycles: int = 0


def soak(station: str | Station, steps: int, seed: int, *, cycle_s: float = 0.25,
         sim: Simulation | None = None) -> SoakRun:
    """Run ``steps`` random steps with the safety oracle watching; the run is kept as command lines."""
    t0 = time.perf_counter()
    sim = sim or Simulation(station, cycle_s=cycle_s)
    checker = Watch(sim)
    gen = StepGenerator(sim, random.Random(seed))
    source = sim.station.id
    if isinstance(station, str):
        path = Path(station)
        source = str(path.resolve()) if path.suffix in (".yaml", ".yml") else station
    run = SoakRun(sim.station.id, seed, steps, source)
    pending = 0  # cycles run since the last line
    ms = round(sim.cycle_s * 1000)

    def flush() -> None:
        nonlocal pending
        if pending:
            run.lines.append(f"run {pending * ms}ms")
            pending = 0

    for _ in range(steps):
        lines, cycles = gen.next()
        for line in lines:
            flush()
            run.lines.append(line)
            seen = len(checker.violations)
            if not sim.command(line).ok:
                run.refused += 1
            if line.startswith("run "):
                run.violations += [(v, len(run.lines)) for v in checker.violations[seen:]]
        for _ in range(cycles):
            seen = len(checker.violations)
            sim.step()
            pending += 1
            if len(checker.violations) > seen:
                flush()
                run.violations += [(v, len(run.lines)) for v in checker.violations[seen:]]
        run.line_of_step.append(len(run.lines))
    flush()
    run.elapsed_s = time.perf_counter() - t0
    run.simulated_s = sim.t
    run.cycles = checker.cycles
    for h in checker.hazards:
        run.hazards[h.prop] = run.hazards.get(h.prop, 0) + 1
    return run

"""Eclipse SUMO as the train engine (``Simulation(station, engine="sumo")``; ``pip install 'liansuo[sumo]'``).

SUMO computes how each train accelerates and brakes towards the speed its driver chose; our model still moves the
train over the topology (squeezing or derailing at turnouts), feeds the track circuits and runs the interlocking,
exactly as with the kinematic engine. What the engine does each cycle:

1. for every train, its route: the SUMO edges from its front on, along the way the turnouts' switch rails lie now
   (so a turnout thrown ahead of a train changes its SUMO route), and where its front is;
2. the traffic lights of the exported network mirror our signals' aspects (only the changes are sent);
3. one SUMO step of the simulation's cycle; SUMO's odometer (``getDistance``) gives the metres run, clipped at an
   exact stopping point (a platform stop mark).

SUMO runs in a worker process (:mod:`simulation.trains.sumo_worker`, ``spawn`` context). If the worker dies or SUMO
raises, the engine raises the alarm "SUMO engine failed: ..." in the simulation and the trains go on, from the speeds
they had, with the kinematic engine (or, with ``fallback=False``, :class:`SumoEngineError` is raised to the caller).
"""

from __future__ import annotations

import multiprocessing
import signal
import sys
import types
import weakref
from collections.abc import Callable, Iterator, Mapping
from contextlib import contextmanager, suppress
from multiprocessing.connection import Connection
from multiprocessing.process import BaseProcess
from typing import TYPE_CHECKING, Any

from liansuo.circuits.machines import SwitchMachine
from liansuo.simulation.trains.consist import Consist
from liansuo.simulation.trains.engine import KinematicEngine
from liansuo.simulation.trains.movement import OUTSIDE, Position
from liansuo.simulation.trains.sumo_export import SumoNetwork, SumoUnavailable, build_network, link_state, sumo_home
from liansuo.simulation.trains.sumo_worker import main as worker_main
from liansuo.stations.station import Station
from liansuo.stations.topology import Move

if TYPE_CHECKING:
    from liansuo.simulation.trains.fleet import Fleet


class SumoEngineError(RuntimeError):
    """The SUMO engine could not start, or failed while running."""


def sumo_installed() -> str:
    """'' when libsumo and eclipse-sumo are importable here, else why not."""
    import importlib.util

    missing = [m for m in ("libsumo", "sumo") if importlib.util.find_spec(m) is None]
    if missing:
        return (f"{' and '.join(missing)} not installed (pip install 'liansuo[sumo]' installs libsumo and "
                "eclipse-sumo)")
    return ""


@contextmanager
def _bare_main() -> Iterator[None]:
    """Start the worker without re-running the caller's script: a ``spawn`` child otherwise imports the parent's
    ``__main__`` file again, which would start another engine in any script without a ``__main__`` guard."""
    main = sys.modules.get("__main__")
    sys.modules["__main__"] = types.ModuleType("__main__")
    try:
        yield
    finally:
        if main is not None:
            sys.modules["__main__"] = main


def _shutdown(proc: BaseProcess, conn: Connection) -> None:
    try:
        if proc.is_alive():
            with suppress(OSError):
                conn.send(("close",))
            proc.join(2.0)
        if proc.is_alive():
            proc.kill()
            proc.join(2.0)
    finally:
        conn.close()


def _exit_text(proc: BaseProcess) -> str:
    proc.join(1.0)
    code = proc.exitcode
    if code is None:
        return "the worker does not answer"
    if code < 0:
        try:
            return f"the worker was killed by {signal.Signals(-code).name}"
        except ValueError:
            return f"the worker was killed by signal {-code}"
    return f"the worker exited with status {code}"


class SumoEngine:
    """A :class:`~simulation.trains.engine.MotionEngine` backed by SUMO in a worker process."""

    name = "sumo"

    def __init__(self, station: Station, *, step_s: float = 0.25, fallback: bool = True, step_timeout_s: float = 30.0,
                 start_timeout_s: float = 120.0, sumo_args: tuple[str, ...] = ()) -> None:
        why = sumo_installed()
        if why:
            raise SumoUnavailable(f"the SUMO engine is not available: {why}")
        self.station = station
        self.step_s = step_s
        self.fallback = fallback
        self.step_timeout_s = step_timeout_s
        self.network: SumoNetwork = build_network(station)
        self.consists: dict[str, Consist] = {}
        self.speeds: dict[str, float] = {}
        self.failed = ""  # why SUMO stopped, once it has
        self.replacement: KinematicEngine | None = None
        self._add: list[tuple[str, float, float, float, float, float]] = []
        self._remove: list[str] = []
        self._force: dict[str, float] = {}
        self._routes: dict[str, tuple[str, ...]] = {}  # the route last sent for each train
        self._ways: dict[str, tuple[Move, tuple[str, ...], tuple[tuple[SwitchMachine, str | None], ...]]] = {}
        self._exit: dict[str, str] = {}  # train -> the exit edge its front took last
        self._lights: dict[str, str] = {}
        self._aspects: dict[str, str] = {}
        self._fleet: Fleet | None = None
        self._notify: Callable[[str, str], None] = lambda kind, text: None
        self.cycles = 0
        self.counts: dict[str, int] = {}  # from the worker: vehicles inserted, moved back, rerouted
        ctx = multiprocessing.get_context("spawn")
        self._conn, child = ctx.Pipe()
        assert self.network.net_file is not None
        self.process: BaseProcess = ctx.Process(
            target=worker_main, name=f"liansuo-sumo-{station.id}", daemon=True,
            args=(child, str(self.network.net_file), step_s, str(sumo_home()), sumo_args))
        with _bare_main():
            self.process.start()
        child.close()
        self._finalizer = weakref.finalize(self, _shutdown, self.process, self._conn)
        try:
            if not self._conn.poll(start_timeout_s):
                raise SumoEngineError(f"SUMO did not start within {start_timeout_s:g} s")
            kind, detail = self._conn.recv()
        except (EOFError, OSError) as exc:
            self._finalizer()
            raise SumoEngineError(f"SUMO did not start: {_exit_text(self.process)}") from exc
        except SumoEngineError:
            self._finalizer()
            raise
        if kind != "ready":
            self._finalizer()
            raise SumoEngineError(str(detail))

    # ---- wiring to the fleet -----------------------------------------------------------------------------------
    def attach(self, fleet: Fleet) -> None:
        """Give the engine the trains' positions, the signals' aspects and the event log."""
        self._fleet = fleet
        self._notify = fleet.notify

    @property
    def active(self) -> str:
        """The engine moving the trains now: 'sumo', or 'kinematic' after a SUMO failure."""
        return "kinematic" if self.replacement is not None else "sumo"

    # ---- MotionEngine ----------------------------------------------------------------------------------------
    def add(self, train: str, consist: Consist, speed_ms: float) -> str:
        if self.replacement is not None:
            return self.replacement.add(train, consist, speed_ms)
        self.consists[train] = consist
        self.speeds[train] = speed_ms
        self._add = [a for a in self._add if a[0] != train]
        self._add.append((train, consist.length_m, consist.accel_ms2, consist.brake_ms2, consist.emergency_ms2,
                          consist.vmax_kmh / 3.6))
        self._routes.pop(train, None)
        return ""

    def remove(self, train: str) -> None:
        if self.replacement is not None:
            self.replacement.remove(train)
        if train not in self.consists:
            return
        del self.consists[train]
        self.speeds.pop(train, None)
        self._routes.pop(train, None)
        self._ways.pop(train, None)
        self._exit.pop(train, None)
        self._force.pop(train, None)
        self._add = [a for a in self._add if a[0] != train]
        self._remove.append(train)

    def set_speed(self, train: str, speed_ms: float) -> None:
        if self.replacement is not None:
            self.replacement.set_speed(train, speed_ms)
            return
        if train in self.consists:
            self.speeds[train] = speed_ms
            self._force[train] = speed_ms

    def step(self, dt: float, targets: Mapping[str, float],
             limits: Mapping[str, float]) -> dict[str, tuple[float, float]]:
        if self.replacement is not None:
            return self.replacement.step(dt, targets, limits)
        try:
            payload = self._payload(dt, targets, limits)
            motion: dict[str, tuple[float, float]]
            motion, self.counts = self._call(("step", payload))
        except SumoEngineError as exc:
            return self._fail(str(exc)).step(dt, targets, limits)
        except Exception as exc:  # a fault in this engine itself: still an alarm, never a crash of the simulator
            return self._fail(f"{type(exc).__name__}: {exc}").step(dt, targets, limits)
        self._add, self._remove, self._force = [], [], {}
        self.cycles += 1
        for name, (speed, _) in motion.items():
            self.speeds[name] = speed
        return motion

    def close(self) -> None:
        self._finalizer()

    # ---- the worker ------------------------------------------------------------------------------------------
    def _call(self, msg: tuple[str, Any]) -> Any:
        try:
            self._conn.send(msg)
            if not self._conn.poll(self.step_timeout_s):
                self.process.kill()
                raise SumoEngineError(f"SUMO did not answer within {self.step_timeout_s:g} s")
            kind, detail = self._conn.recv()
        except (EOFError, OSError) as exc:
            raise SumoEngineError(_exit_text(self.process)) from exc
        if kind != "ok":
            raise SumoEngineError(f"SUMO raised {detail}")
        return detail

    def _fail(self, why: str) -> KinematicEngine:
        """SUMO is gone: raise the alarm, stop the worker, and hand the trains to the kinematic engine."""
        self.failed = why
        self._finalizer()
        if not self.fallback:
            self._notify("alarm", f"SUMO engine failed: {why}")
            raise SumoEngineError(f"SUMO engine failed: {why}")
        self._notify("alarm", f"SUMO engine failed: {why}; the trains go on with the kinematic engine")
        engine = KinematicEngine()
        for name, consist in self.consists.items():
            engine.add(name, consist, self.speeds.get(name, 0.0))
        self.replacement = engine
        return engine

    # ---- what the worker is told each cycle -------------------------------------------------------------------
    def _payload(self, dt: float, targets: Mapping[str, float], limits: Mapping[str, float]) -> dict[str, Any]:
        fleet = self._fleet
        if fleet is None:
            raise SumoEngineError("the engine was not attached to a fleet (SumoEngine.attach)")
        trains: dict[str, tuple[float, float | None, tuple[str, ...] | None, float, float]] = {}
        for name, target in targets.items():
            tr = fleet.trains.get(name)
            if tr is None or name not in self.consists:
                continue
            route, pos = self._route(name, tr.pos)
            changed = route if route != self._routes.get(name) else None
            self._routes[name] = route
            trains[name] = (target, limits.get(name), changed, pos, tr.speed_ms)
        return {"dt": dt, "add": self._add, "remove": self._remove, "force": self._force,
                "hold": [n for n in self.consists if n not in trains], "tls": self._light_changes(fleet),
                "trains": trains}

    def _route(self, name: str, pos: Position) -> tuple[tuple[str, ...], float]:
        """The SUMO edges from the train's front on, along the way the turnouts lie now (to a buffer stop, a turnout
        in no end position, or out through a boundary onto its exit edge), and the front's distance into the
        first. The rear is left to our model: SUMO only needs where the front goes."""
        assert self._fleet is not None
        net = self.network
        front = pos.moves[-1]
        if front[0] == OUTSIDE:  # leaving: the front is out on the exit edge past the boundary
            inside = [m for m in pos.moves if m[0] != OUTSIDE]
            far = self._fleet.track.topo.far_node(inside[-1]) if inside else None
            exit_edge = (net.exits.get(far) if far else None) or self._exit.get(name)
            if exit_edge is None:
                raise SumoEngineError(f"train {name} left the station where the network has no exit edge")
            self._exit[name] = exit_edge
            return (exit_edge,), pos.front_s
        cached = self._ways.get(name)
        if cached is not None and cached[0] == front and all(m.rails == rails for m, rails in cached[2]):
            return cached[1], pos.front_s
        edges, facing = self._way(front)
        self._ways[name] = (front, edges, facing)
        return edges, pos.front_s

    def _way(self, front: Move) -> tuple[tuple[str, ...], tuple[tuple[SwitchMachine, str | None], ...]]:
        """The edges from ``front`` on as the rails lie (as :meth:`Track.moves_ahead` follows them), and the facing
        turnouts it passes with the position each lies in: the way stays the same while they do."""
        assert self._fleet is not None
        topo = self._fleet.track.topo
        machines = self._fleet.field.machines
        net = self.network
        edges = [net.edges[front]]
        facing: list[tuple[SwitchMachine, str | None]] = []
        move = front
        for _ in range(len(net.edges)):
            options = topo.next_moves(move)
            if not options:
                far = topo.far_node(move)
                if far in net.exits:
                    edges.append(net.exits[far])
                break
            if len(options) > 1:
                m = machines[str(options[0][1]["turnout"])]
                facing.append((m, m.rails))
                options = [(n, data) for n, data in options if data["position"] == m.rails]
                if not options:
                    break  # a turnout in no end position: the way ends here (a train reaching it derails)
            move = options[0][0]
            edges.append(net.edges[move])
        return tuple(edges), tuple(facing)

    def _light_changes(self, fleet: Fleet) -> dict[str, str]:
        """The traffic lights whose state changed since the last cycle, mirroring our aspects."""
        aspects = fleet.aspects()
        if aspects == self._aspects:
            return {}
        changed = {s for s in set(aspects) | set(self._aspects) if aspects.get(s) != self._aspects.get(s)}
        self._aspects = dict(aspects)
        lights = self.network.lights
        touched = {i for s in changed for i, _ in self.network.signal_lights.get(s, ())}
        out: dict[str, str] = {}
        for i in sorted(touched):
            light = lights[i]
            state = "".join(link_state(sigs, aspects, fleet.rules.aspects) for sigs in light.links)
            if self._lights.get(light.tls) != state:
                self._lights[light.tls] = out[light.tls] = state
        return out


__all__ = ["SumoEngine", "SumoEngineError", "SumoUnavailable", "sumo_installed"]

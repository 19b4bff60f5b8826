"""The SUMO worker process: libsumo runs here, never in the simulator's own process.

The parent (:class:`simulation.trains.sumo.SumoEngine`) sends one message per interlocking cycle and waits for the
answer; a SUMO error is sent back as text, and a SUMO crash only ends this process, which the parent notices.

Messages (parent -> worker), each answered by ``("ok", result)`` or ``("error", text)``:

* ``("step", payload)``: ``payload`` is a dict with ``dt``; ``add``: ``[(train, length, accel, decel, emergency,
  vmax)]``; ``remove``: ``[train]``; ``force``: ``{train: speed}`` (a speed imposed by our model: 0 after a derailment
  or at a buffer stop); ``hold``: ``[train]`` (trains standing outside the drivers' control); ``tls``: ``{light:
  state}``; ``trains``: ``{train: (target, limit, route or None, position, speed)}``: the speed the driver aims
  for, the exact stopping distance or None, the edges from the front on to the end of the way ahead (None when
  unchanged), how far the front is into the first of them, and the train's speed in our model. The result is
  ``({train: (speed, metres run)}, counts)``, ``counts`` telling how often a vehicle had to be inserted, moved
  back to where our model has it, or rerouted.
* ``("close",)``: stop SUMO and end.

Each train is a SUMO vehicle of its own vehicle type (the consist's length, acceleration, service and emergency
deceleration, maximum speed), driven with ``setSpeed`` in speed mode 6: SUMO keeps the acceleration and
deceleration limits but ignores its own safe-speed, right-of-way and red-light checks, since our drivers decide
(obeying or passing our signals). Whenever the vehicle is not where our model has the train (an exact stop clipped
the step, a buffer stop, a reversal, a vanished vehicle), it is put back with ``moveTo`` or inserted anew.
"""

from __future__ import annotations

from collections.abc import Sequence
from contextlib import suppress
from dataclasses import dataclass
from multiprocessing.connection import Connection
from typing import Any

SPEED_MODE = 6  # bit1 max acceleration, bit2 max deceleration; no safe speed, no right of way, run red lights
TOLERANCE_M = 0.01


@dataclass
class _Vehicle:
    train: str
    vtype: str
    accel: float
    decel: float
    vid: str = ""
    route: tuple[str, ...] = ()
    target: float = -1.0
    held: bool = False


class SumoWorld:
    """libsumo driven on behalf of the parent's trains."""

    def __init__(self, sumo: Any, step_s: float) -> None:
        self.sumo = sumo
        self.step_s = step_s
        self.vehicles: dict[str, _Vehicle] = {}
        self.serial = 0
        self.lengths: dict[str, float] = {}
        self.counts = {"inserted": 0, "moved": 0, "rerouted": 0}  # how often SUMO had to be put right

    # ---- helpers ---------------------------------------------------------------------------------------------
    def _length(self, edge: str) -> float:
        found = self.lengths.get(edge)
        if found is None:
            found = self.lengths[edge] = float(self.sumo.lane.getLength(edge + "_0"))
        return found

    def _new_id(self, prefix: str) -> str:
        self.serial += 1
        return f"{prefix}{self.serial}"

    def _insert(self, rec: _Vehicle, route: tuple[str, ...], pos: float, speed: float) -> None:
        """A new SUMO vehicle for the train, standing exactly where our model has it."""
        s = self.sumo
        if rec.vid:
            self._drop(rec)
        self.counts["inserted"] += 1
        rid = self._new_id("r")
        s.route.add(rid, list(route))
        rec.vid = self._new_id("v")
        s.vehicle.add(rec.vid, rid, typeID=rec.vtype, depart="now", departLane="0", departPos=f"{pos:.6f}",
                      departSpeed=f"{max(speed, 0.0):.6f}")
        s.vehicle.setSpeedMode(rec.vid, SPEED_MODE)
        s.vehicle.moveTo(rec.vid, route[0] + "_0", pos)  # inserts it now, whatever stands there
        s.vehicle.setPreviousSpeed(rec.vid, max(speed, 0.0))
        rec.route = route
        rec.target = -1.0
        rec.held = False

    def _drop(self, rec: _Vehicle) -> None:
        with suppress(self.sumo.TraCIException):  # already gone when it arrived at the end of its route
            self.sumo.vehicle.remove(rec.vid)
        rec.vid = ""

    def _matches(self, route: tuple[str, ...], pos: float, road: str, lane_pos: float) -> bool:
        """Is the vehicle where our model has the train's front (the start of ``route``, ``pos`` into it)?"""
        if road == route[0]:
            return abs(lane_pos - pos) <= TOLERANCE_M
        if len(route) > 1 and road == route[1]:  # just across the end of the front's edge
            return lane_pos <= TOLERANCE_M and abs(self._length(route[0]) - pos) <= TOLERANCE_M
        return False

    def _remaining(self, route: tuple[str, ...], pos: float) -> float:
        return self._length(route[0]) - pos + sum(self._length(e) for e in route[1:])

    def _reroute(self, rec: _Vehicle, route: tuple[str, ...], pos: float, speed: float) -> None:
        """A new way ahead: tell SUMO only when it differs from the vehicle's edge on (not when the front has just
        moved on to the next edge of the same way)."""
        veh = self.sumo.vehicle
        road = veh.getRoadID(rec.vid)
        old = rec.route[rec.route.index(road):] if road in rec.route else ()
        new = route[route.index(road):] if road in route else ()
        rec.route = route
        if new and new == old:
            return
        try:  # SUMO keeps the edges already passed and takes the new route from the current edge on
            if not new:
                raise ValueError(road)
            veh.setRoute(rec.vid, list(new))
            self.counts["rerouted"] += 1
        except (ValueError, self.sumo.TraCIException):  # its edge is not on the new way at all: a reversal
            self._insert(rec, route, pos, speed)

    # ---- one cycle -------------------------------------------------------------------------------------------
    def step(self, p: dict[str, Any]) -> tuple[dict[str, tuple[float, float]], dict[str, int]]:
        s = self.sumo
        veh = s.vehicle
        for name in p.get("remove", ()):
            rec = self.vehicles.pop(name, None)
            if rec is not None and rec.vid:
                self._drop(rec)
        for name, length, accel, decel, emergency, vmax in p.get("add", ()):
            old = self.vehicles.pop(name, None)
            if old is not None and old.vid:
                self._drop(old)
            vtype = self._new_id("t")
            vt = s.vehicletype
            vt.copy("DEFAULT_VEHTYPE", vtype)
            vt.setVehicleClass(vtype, "rail")
            vt.setLength(vtype, float(length))
            vt.setMinGap(vtype, 0.0)
            vt.setAccel(vtype, float(accel))
            vt.setDecel(vtype, float(decel))
            vt.setEmergencyDecel(vtype, max(float(emergency), float(decel)))
            vt.setApparentDecel(vtype, float(decel))
            vt.setMaxSpeed(vtype, float(vmax))
            vt.setImperfection(vtype, 0.0)
            vt.setSpeedFactor(vtype, 1.0)
            vt.setSpeedDeviation(vtype, 0.0)
            self.vehicles[name] = _Vehicle(name, vtype, float(accel), float(decel))
        for tls, state in p.get("tls", {}).items():
            s.trafficlight.setRedYellowGreenState(tls, state)
        present = set(veh.getIDList())
        for name in p.get("hold", ()):
            rec = self.vehicles.get(name)
            if rec is not None and rec.vid in present and not rec.held:
                veh.setSpeed(rec.vid, 0.0)
                veh.setPreviousSpeed(rec.vid, 0.0)
                rec.held, rec.target = True, 0.0
        trains: dict[str, tuple[float, float | None, Sequence[str] | None, float, float]] = p["trains"]
        force: dict[str, float] = p.get("force", {})
        before: dict[str, float] = {}
        speeds: dict[str, float] = {}
        for name, (target, _limit, new_route, pos, speed) in trains.items():
            rec = self.vehicles[name]
            route = tuple(new_route) if new_route is not None else rec.route
            speed = force.get(name, speed)
            if rec.vid not in present:
                self._insert(rec, route, pos, speed)
            else:
                if route != rec.route:
                    self._reroute(rec, route, pos, speed)
                if not self._matches(route, pos, veh.getRoadID(rec.vid), veh.getLanePosition(rec.vid)):
                    self.counts["moved"] += 1
                    try:
                        veh.moveTo(rec.vid, route[0] + "_0", pos)
                    except s.TraCIException:
                        self._insert(rec, route, pos, speed)
                if name in force:
                    veh.setPreviousSpeed(rec.vid, max(force[name], 0.0))
            rec.held = False
            if target != rec.target:
                veh.setSpeed(rec.vid, max(target, 0.0))
                rec.target = target
            before[name] = float(veh.getDistance(rec.vid))
            speeds[name] = float(veh.getSpeed(rec.vid))
        s.simulationStep(float(s.simulation.getTime()) + float(p["dt"]))
        present = set(veh.getIDList())
        out: dict[str, tuple[float, float]] = {}
        for name, (target, limit, _r, pos, _v) in trains.items():
            rec = self.vehicles[name]
            if rec.vid in present:
                v = float(veh.getSpeed(rec.vid))
                ds = float(veh.getDistance(rec.vid)) - before[name]
            else:  # ran off the end of its route (a buffer stop, a turnout in no end position) and arrived:
                # what SUMO's step did (explicit Euler), so our model takes the train past the end and stops it
                # at the buffer or derails it at the turnout
                v0, dt = speeds[name], float(p["dt"])
                v = min(target, v0 + rec.accel * dt) if v0 < target else max(target, v0 - rec.decel * dt)
                ds = max(v * dt, self._remaining(rec.route, pos))
                rec.vid = ""
            if limit is not None and ds >= limit:
                ds, v = max(limit, 0.0), 0.0  # the exact stopping point; the vehicle is put back next cycle
                if rec.vid:
                    veh.setPreviousSpeed(rec.vid, 0.0)
            out[name] = (v, max(ds, 0.0))
        return out, dict(self.counts)


def sumo_command(net_file: str, step_s: float, extra: Sequence[str] = ()) -> list[str]:
    return ["sumo", "--net-file", net_file, "--step-length", f"{step_s:g}", "--begin", "0",
            "--time-to-teleport", "-1", "--time-to-teleport.disconnected", "-1",
            "--collision.action", "none", "--collision.check-junctions", "false",
            "--no-step-log", "true", "--no-warnings", "true", "--duration-log.disable", "true",
            "--default.speeddev", "0", "--seed", "0", *extra]


def main(conn: Connection, net_file: str, step_s: float, sumo_home: str, extra: Sequence[str] = ()) -> None:
    """Entry point of the worker process."""
    import os

    os.environ.setdefault("SUMO_HOME", sumo_home)
    try:
        import libsumo

        libsumo.start(sumo_command(net_file, step_s, extra))
    except Exception as exc:  # libsumo missing or SUMO refusing the network: the parent reports it
        conn.send(("error", f"SUMO did not start: {type(exc).__name__}: {exc}"))
        conn.close()
        return
    conn.send(("ready", str(libsumo.simulation.getTime())))
    world = SumoWorld(libsumo, step_s)
    try:
        while True:
            try:
                msg = conn.recv()
            except (EOFError, OSError):
                break  # the parent is gone
            if msg[0] == "close":
                break
            try:
                if msg[0] == "step":
                    conn.send(("ok", world.step(msg[1])))
                else:
                    conn.send(("error", f"unknown message {msg[0]!r}"))
            except Exception as exc:  # a SUMO error in this cycle: the parent decides what to do
                conn.send(("error", f"{type(exc).__name__}: {exc}"))
    finally:
        with suppress(Exception):
            libsumo.close()
        conn.close()

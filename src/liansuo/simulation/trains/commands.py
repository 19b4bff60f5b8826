"""Train commands of the command language: ``train``, ``drive``, ``stop``, ``auto``, ``reverse``."""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import Protocol

from liansuo.interlocking.io import Result
from liansuo.interlocking.table.build import InterlockingTable
from liansuo.simulation.language import Command
from liansuo.simulation.timeparse import parse_duration
from liansuo.simulation.trains.consist import make_consist
from liansuo.simulation.trains.fleet import MODES, Fleet, Train
from liansuo.stations import limits
from liansuo.stations.schema import Direction
from liansuo.stations.station import Station


class Yard(Protocol):
    """What the train commands need of the world: the station and its table, the fleet, where the wheelsets stand,
    automatic shunting, and the log."""

    @property
    def station(self) -> Station: ...
    @property
    def table(self) -> InterlockingTable: ...
    @property
    def fleet(self) -> Fleet: ...
    def update_axles(self) -> None:
        """Tell the field where every wheelset stands."""
    def attach_auto(self, train: Train, plan: list[str], flags: dict[str, bool] | None = None) -> Result:
        """Switch ``train`` to automatic shunting."""
    def log(self, kind: str, text: str) -> None: ...


Handler = Callable[[Yard, list[str]], Result]

USAGE = {
    "train": "train NAME at SECTION|TRACK [kind=freight|emu|shunter|trolley] [length=M] [axles=N] [vmax=KMH] "
             "[mode=manual|signal|auto] [dir=down|up] [movement=train|shunt] [back=M] [front=X] [stop=PLATFORM] "
             "| train NAME remove",
    "drive": "drive NAME SPEED (km/h; manual driving, overrides automatic)",
    "stop": "stop NAME",
    "auto": "auto NAME [plan=ROUTE,ROUTE,...] [onboard=on|off] [centre=on|off] [loco=ok|fault] "
            "[perception=ok|fault]",
    "estop": "estop NAME SOURCE (team, cab, remote, system)",
    "slip": "slip NAME RATIO DURATION (wheel speed off by RATIO: 0.3 slips 30 % fast, -0.3 slides)",
    "estop-release": "estop-release NAME SOURCE [by=SOURCE]",
    "reverse": "reverse NAME (change the direction of travel; the train must stand)",
}

# the range of each number a train is placed with (stations/limits.py says why); front is a position on the track,
# checked where the train is placed
_TRAIN_LIMITS = {"length": limits.TRAIN_LENGTH, "axles": limits.AXLES, "vmax": limits.TRAIN_SPEED,
                 "back": limits.BACK, "front": limits.POSITION}


def _train(sim: Yard, args: list[str]) -> Result:
    if len(args) == 2 and args[1] == "remove":
        if args[0] not in sim.fleet.trains:
            return Result.refuse(f"there is no train '{args[0]}'")
        sim.fleet.remove(args[0])
        sim.update_axles()
        return Result.accept(f"train {args[0]} removed")
    if len(args) < 3 or args[1] != "at":
        return Result.refuse(f"usage: {USAGE['train']}")
    name, _, section, *opts = args
    if name in sim.fleet.trains:
        return Result.refuse(f"train {name} is already on the track; 'train {name} remove' first")
    if section not in sim.station.sections and section not in sim.station.tracks:
        return Result.refuse(f"there is no section '{section}' at {sim.station.id}")
    params: dict[str, str] = {}
    for o in opts:
        k, eq, v = o.partition("=")
        if not eq or k not in ("kind", "length", "axles", "vmax", "mode", "dir", "stop", "movement", "back", "front"):
            return Result.refuse(f"unknown train parameter '{o}'; usage: {USAGE['train']}")
        params[k] = v
    kind = params.get("kind", "freight")
    if kind not in ("freight", "emu", "shunter", "trolley"):
        return Result.refuse("kind must be freight, emu, shunter or trolley")
    nums: dict[str, float] = {}
    for k in ("length", "axles", "vmax", "back", "front"):
        if k in params:
            try:
                nums[k] = float(params[k])
            except ValueError:
                return Result.refuse(f"{k} must be a number, not '{params[k]}'")
            if not math.isfinite(nums[k]):
                return Result.refuse(f"{k} must be a finite number, not '{params[k]}'")
            why = _TRAIN_LIMITS[k].problem(k, nums[k], params[k])
            if why:
                return Result.refuse(f"train {name}: {why}")
    mode = params.get("mode", "manual")
    if mode not in MODES:
        return Result.refuse(f"mode must be one of {', '.join(MODES)}")
    direction = params.get("dir") or _facing(sim, section)
    if direction not in ("down", "up"):
        return Result.refuse("dir must be down or up")
    consist = make_consist(kind, length_m=nums.get("length"), axles=int(nums["axles"]) if "axles" in nums else None,
                           vmax_kmh=nums.get("vmax"))
    why = sim.fleet.place(name, consist, section, Direction(direction), mode, nums.get("back", 5.0),
                          nums.get("front"))
    if why:
        return Result.refuse(f"train {name}: {why}")
    tr = sim.fleet.trains[name]
    movement = params.get("movement", "shunt" if kind in ("shunter", "trolley") or mode == "auto" else "train")
    if movement not in ("train", "shunt"):
        sim.fleet.remove(name)
        return Result.refuse("movement must be train or shunt")
    tr.shunting = movement == "shunt"
    tr.traction = kind != "trolley"
    if "stop" in params:
        why = sim.fleet.set_platform_stop(tr, params["stop"])
        if why:
            sim.fleet.remove(name)
            return Result.refuse(f"train {name}: {why}")
    if mode == "auto":
        result = sim.attach_auto(tr, [])
        if not result.ok:
            sim.fleet.remove(name)
            return result
    sim.update_axles()
    sim.log("train", f"train {name} placed in {section}: {consist.axles} wheelsets, {consist.length_m:g} m, "
            f"{mode}, {direction}")
    return Result.accept(f"train {name} placed in {section} ({consist.axles} wheelsets, {consist.length_m:g} m, "
                         f"facing {direction}, {mode})")


def _facing(sim: Yard, section: str) -> str:
    """The way the signals at the far end of ``section`` face (an approach faces its home signal); down if both."""
    ways = set()
    for sig in sim.station.model.signals:
        rear = sim.station.signal_rear_track(sig.id)
        if rear is not None and sim.station.tracks[rear].section == section:
            ways.add(sig.direction.value)
    return ways.pop() if len(ways) == 1 else "down"


def _named(sim: Yard, args: list[str], usage: str, n: int) -> tuple[str, Result | None]:
    if len(args) != n:
        return "", Result.refuse(f"usage: {USAGE[usage]}")
    if args[0] not in sim.fleet.trains:
        return "", Result.refuse(f"there is no train '{args[0]}'")
    return args[0], None


def _drive(sim: Yard, args: list[str]) -> Result:
    name, bad = _named(sim, args, "drive", 2)
    if bad is not None:
        return bad
    try:
        kmh = float(args[1])
    except ValueError:
        return Result.refuse(f"speed must be a number of km/h, not '{args[1]}'")
    if not math.isfinite(kmh):
        return Result.refuse(f"speed must be a finite number of km/h, not '{args[1]}'")
    tr = sim.fleet.trains[name]
    if kmh < 0:
        return Result.refuse("to drive the other way, 'stop' then 'reverse' the train")
    if kmh > tr.consist.vmax_kmh:
        return Result.refuse(f"train {name} runs at most {tr.consist.vmax_kmh:g} km/h")
    if tr.state == "derailed":
        return Result.refuse(f"train {name} is derailed")
    tr.mode = "manual"  # manual driving always overrides automatic driving
    tr.controller = None
    tr.commanded_kmh = kmh
    return Result.accept(f"train {name}: manual, {kmh:g} km/h")


def _stop(sim: Yard, args: list[str]) -> Result:
    name, bad = _named(sim, args, "stop", 1)
    if bad is not None:
        return bad
    tr = sim.fleet.trains[name]
    tr.mode = "manual"
    tr.controller = None
    tr.commanded_kmh = 0.0
    return Result.accept(f"train {name} braking to a stop")


def _auto(sim: Yard, args: list[str]) -> Result:
    if not args:
        return Result.refuse(f"usage: {USAGE['auto']}")
    name = args[0]
    if name not in sim.fleet.trains:
        return Result.refuse(f"there is no train '{name}'")
    plan: list[str] = []
    flags: dict[str, bool] = {}
    words = {"on": True, "ok": True, "off": False, "fault": False}
    for o in args[1:]:
        k, eq, v = o.partition("=")
        if k == "plan" and eq:
            plan = [p for p in v.split(",") if p]
            unknown = [p for p in plan if p not in sim.table.routes]
            if unknown:
                return Result.refuse(f"the plan names routes that do not exist: {', '.join(unknown)}")
        elif k in ("onboard", "centre", "loco", "perception") and v in words:
            flags[k] = words[v]
        else:
            return Result.refuse(f"usage: {USAGE['auto']}")
    return sim.attach_auto(sim.fleet.trains[name], plan, flags)


def _slip(sim: Yard, args: list[str]) -> Result:
    name, bad = _named(sim, args, "slip", 3)
    if bad is not None:
        return bad
    try:
        ratio = float(args[1])
        seconds = parse_duration(args[2])
    except ValueError as exc:
        return Result.refuse(f"slip: {exc}" if "duration" in str(exc) else "RATIO must be a number, e.g. 0.3 or -0.3")
    if not -0.9 <= ratio <= 2.0:
        return Result.refuse("RATIO must lie between -0.9 (a locked wheel slides) and 2 (a wheel spinning 3x)")
    why = limits.SLIP.problem("the slip's duration", seconds, args[2])
    if why:
        return Result.refuse(f"slip: {why}")
    tr = sim.fleet.trains[name]
    tr.slip_ratio, tr.slip_until = ratio, sim.fleet.t + seconds
    tr.slip_from = sim.fleet.t
    what = "slipping" if ratio > 0 else "sliding"
    return Result.accept(f"train {name}: wheels {what} {abs(ratio) * 100:g} % for {seconds:g} s")


def _estop(sim: Yard, args: list[str]) -> Result:
    name, bad = _named(sim, args, "estop", 2)
    if bad is not None:
        return bad
    tr = sim.fleet.trains[name]
    tr.estops.apply(args[1])
    sim.log("train", f"train {name}: emergency stop from {args[1]}")
    return Result.accept(f"train {name}: emergency stop from {args[1]}")


def _estop_release(sim: Yard, args: list[str]) -> Result:
    if len(args) not in (2, 3):
        return Result.refuse(f"usage: {USAGE['estop-release']}")
    name, source = args[0], args[1]
    if name not in sim.fleet.trains:
        return Result.refuse(f"there is no train '{name}'")
    by = source
    if len(args) == 3:
        k, eq, by = args[2].partition("=")
        if k != "by" or not eq:
            return Result.refuse(f"usage: {USAGE['estop-release']}")
    why = sim.fleet.trains[name].estops.release(source, by)
    if why:
        return Result.refuse(why)
    sim.log("train", f"train {name}: emergency stop from {source} released")
    return Result.accept(f"train {name}: emergency stop from {source} released")


def _reverse(sim: Yard, args: list[str]) -> Result:
    name, bad = _named(sim, args, "reverse", 1)
    if bad is not None:
        return bad
    tr = sim.fleet.trains[name]
    if tr.speed_ms > 0.01:
        return Result.refuse(f"train {name} is moving: stop it before reversing")
    tr.pos = sim.fleet.track.reverse(tr.pos, tr.consist.length_m)
    tr.aspect_limit_ms = 1e9
    return Result.accept(f"train {name} now faces {tr.direction.value}")


_HANDLERS: dict[str, Handler] = {"train": _train, "drive": _drive, "stop": _stop, "auto": _auto,
                                  "reverse": _reverse, "estop": _estop, "estop-release": _estop_release, "slip": _slip}

TRAIN_COMMANDS: tuple[Command[Yard], ...] = tuple(Command(name, USAGE[name], h) for name, h in _HANDLERS.items())

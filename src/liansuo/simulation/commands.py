"""The world's commands of the command language (docs/commands.md): the operator's (CBI console), the field's and the
instructor's. Scripts' checks are in :mod:`.expect`, the trains' commands in :mod:`.trains.commands`.

Each command returns a :class:`Result`; a refusal says why.
"""

from __future__ import annotations

import math
from collections.abc import Callable

from liansuo.circuits.faults import KINDS, parse_fault
from liansuo.circuits.railgeometry import Axle
from liansuo.interlocking.io import Result
from liansuo.interlocking.table.build import Kind
from liansuo.simulation.changeover import USAGE as CHANGEOVER_USAGE
from liansuo.simulation.changeover import changeover
from liansuo.simulation.language import Command
from liansuo.simulation.timeparse import parse_duration
from liansuo.simulation.world import World
from liansuo.stations import limits

Handler = Callable[[World, list[str]], Result]

USAGE = {
    "route": "route START END [VIA ...]",
    "shunt": "shunt START END [VIA ...]",
    "cancel": "cancel SIGNAL",
    "release": "release SIGNAL",
    "fault-release": "fault-release SECTION",
    "reopen": "reopen SIGNAL",
    "guide": "guide SIGNAL [END [VIA ...]]",
    "guide-lock": "guide-lock THROAT",
    "guide-unlock": "guide-unlock THROAT",
    "throw": "throw TURNOUT normal|reverse",
    "lock": "lock TURNOUT",
    "unlock": "unlock TURNOUT",
    "block": "block TURNOUT",
    "unblock": "unblock TURNOUT",
    "block-line": "block-line LINK request|accept|cancel|restore|accident",
    "line-direction": "line-direction LINK out|in",
    "power-up-release": "power-up-release",
    "restart": "restart",
    "neighbour": "neighbour LINK request|depart|restore|accident (64D) or block|cancel (station block)",
    "axle-reset": "axle-reset SECTION",
    "doors": "doors PLATFORM open|close",
    "fault": "fault KIND TARGET [key=value ...]",
    "repair": "repair KIND TARGET",
    "faults": "faults",
    "axles": "axles NAME TRACK POSITION [POSITION ...] [TRACK POSITION ...] | axles NAME clear",
    "occupy": "occupy SECTION",
    "vacate": "vacate SECTION",
    "run": "run DURATION",
    "changeover": CHANGEOVER_USAGE,
}



def _route(kind: Kind) -> Handler:
    def handler(sim: World, args: list[str]) -> Result:
        if len(args) < 2:
            return Result.refuse(f"usage: {USAGE['route' if kind == 'train' else 'shunt']}")
        return sim.interlocking.operator.set_route(kind, args[0], args[-1], tuple(args[1:-1]))

    return handler


# sealed buttons (铅封按钮), by their command: each accepted use is counted (``World.sealed_uses``). 'guide-lock'
# counts the locking only (breaking the seal); 'guide-unlock' restores the button. SGA, the 64D accident button, is
# counted as 'block-line accident'; QHA, the change-over to field control, as 'changeover'.
SEALED = ("release", "fault-release", "guide", "guide-lock", "power-up-release", "axle-reset", "block-line accident",
          "changeover")


def _sealed(name: str, handler: Handler) -> Handler:
    def counted(sim: World, args: list[str]) -> Result:
        result = handler(sim, args)
        if result.ok:
            sim.count_sealed(name)
        return result

    return counted


def _one(name: str, fn: Callable[[World, str], Result]) -> Handler:
    def handler(sim: World, args: list[str]) -> Result:
        if len(args) != 1:
            return Result.refuse(f"usage: {USAGE[name]}")
        return fn(sim, args[0])

    return handler


def _guide(sim: World, args: list[str]) -> Result:
    """引导 over the route set from the signal (or a throat under guide total lock); with an end button, a guide
    route (引导进路锁闭): ``guide START [VIA ...] END``, as a route's buttons."""
    if not args:
        return Result.refuse(f"usage: {USAGE['guide']}")
    if len(args) == 1:
        return sim.interlocking.operator.guide(args[0])
    return sim.interlocking.operator.guide(args[0], args[-1], tuple(args[1:-1]))


def _throw(sim: World, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE['throw']}")
    return sim.interlocking.operator.throw(args[0], args[1])


def _section(sim: World, name: str) -> str:
    return "" if name in sim.station.sections else f"there is no section '{name}' at {sim.station.id}"


def _occupy(sim: World, section: str) -> Result:
    why = _section(sim, section)
    if why:
        return Result.refuse(why)
    sim.field.occupy(section)
    return Result.accept(f"{section} occupied")


def _vacate(sim: World, section: str) -> Result:
    why = _section(sim, section)
    if why:
        return Result.refuse(why)
    sim.field.vacate(section)
    return Result.accept(f"{section} vacated")


def _fault(sim: World, args: list[str]) -> Result:
    if len(args) < 2:
        return Result.refuse(f"usage: {USAGE['fault']}; kinds: {', '.join(KINDS)}")
    parsed = parse_fault(sim.station, args[0], args[1], args[2:])
    if isinstance(parsed, str):
        return Result.refuse(parsed)
    if (parsed.kind, parsed.target) in sim.field.faults:
        return Result.refuse(f"{parsed.kind} on {parsed.target} is already active; repair it first")
    why = sim.field.inject(parsed)
    if why:
        return Result.refuse(f"fault {parsed.kind}: {why}")
    sim.log("fault", f"fault injected: {parsed.describe()}")
    return Result.accept(f"fault injected: {parsed.describe()}")


def _repair(sim: World, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE['repair']}")
    why = sim.field.repair(args[0], args[1])
    if why:
        return Result.refuse(why)
    sim.log("fault", f"repaired: {args[0]} {args[1]}")
    return Result.accept(f"repaired: {args[0]} {args[1]}")


def _faults(sim: World, args: list[str]) -> Result:
    active = [f.describe() for f in sim.field.faults.values()]
    return Result.accept("; ".join(active) if active else "no active faults")


def _axles(sim: World, args: list[str]) -> Result:
    """Wheelsets standing on a track at positions along the line: each shunts its section unless in a dead zone."""
    if len(args) == 2 and args[1] == "clear":
        if args[0] not in sim.parked:
            return Result.refuse(f"no wheelsets named '{args[0]}' are on the track")
        sim.place_axles(args[0], [])
        return Result.accept(f"wheelsets {args[0]} removed")
    if len(args) < 3:
        return Result.refuse(f"usage: {USAGE['axles']}")
    name, *words = args
    axles: list[Axle] = []
    track = ""
    for w in words:
        if w in sim.station.tracks:
            track = w
            continue
        try:
            x = float(w)
        except ValueError:
            return Result.refuse(f"'{w}' is neither a track of {sim.station.id} nor a position in metres")
        if not math.isfinite(x):
            return Result.refuse(f"position '{w}' is not a number of metres: give where the wheelset stands, "
                                 "e.g. 350.5")
        if not track:
            return Result.refuse(f"name the track before the positions: {USAGE['axles']}")
        lo, hi = sim.station.track_span(track)
        if not lo <= x <= hi:
            return Result.refuse(f"position {x:g} m is off track {track} ({lo:g}-{hi:g} m)")
        axles.append(Axle(track, x))
    if not axles:
        return Result.refuse(f"usage: {USAGE['axles']}")
    sim.place_axles(name, axles)
    shunting = sorted({s.section for a in axles if (s := sim.field.geometry.shunt(a)) is not None})
    hidden = sum(sim.field.geometry.shunt(a) is None for a in axles)
    note = f"; {hidden} in dead zones" if hidden else ""
    return Result.accept(f"{len(axles)} wheelsets {name}, shunting {', '.join(shunting) or 'nothing'}{note}")


def _run(sim: World, args: list[str]) -> Result:
    if len(args) != 1:
        return Result.refuse(f"usage: {USAGE['run']}")
    try:
        seconds = parse_duration(args[0])
    except ValueError as exc:
        return Result.refuse(str(exc))
    why = limits.RUN.problem("a run", seconds, args[0])
    if why:
        return Result.refuse(f"{why}: run longer stretches in several steps")
    sim.run(seconds)
    return Result.accept(f"t = {sim.t:g} s")


def _block_line(sim: World, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE['block-line']}")
    result = sim.interlocking.operator.block_line(args[0], args[1])
    if result.ok and args[1] == "accident":
        sim.count_sealed("block-line accident")
    return result


def _line_direction(sim: World, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE['line-direction']}")
    return sim.interlocking.operator.line_direction(args[0], args[1])


def _power_up_release(sim: World, args: list[str]) -> Result:
    if args:
        return Result.refuse(f"usage: {USAGE['power-up-release']}")
    return sim.interlocking.operator.power_up_release()


def _restart(sim: World, args: list[str]) -> Result:
    if args:
        return Result.refuse(f"usage: {USAGE['restart']}")
    return sim.restart_interlocking()


def _neighbour(sim: World, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE['neighbour']}")
    link, action = args
    if link in sim.neighbours.station_lines:
        why = sim.neighbours.station_action(link, action, sim.track_up)
        return Result.refuse(why) if why else Result.accept(f"neighbour on {link}: {action}")
    if link not in sim.neighbours.by_link:
        return Result.refuse(f"there is no virtual neighbour on block line '{link}'")
    if action not in ("request", "depart", "restore", "accident"):
        return Result.refuse(f"usage: {USAGE['neighbour']}")
    why = sim.neighbours.refuses(link, action)
    if why:
        return Result.refuse(why)
    sim.neighbours.send(link, action)
    return Result.accept(f"neighbour on {link}: {action}")


def _doors(sim: World, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE['doors']}")
    return sim.doors(args[0], args[1])


_HANDLERS: dict[str, Handler] = {
    "route": _route("train"),
    "shunt": _route("shunt"),
    "cancel": _one("cancel", lambda s, a: s.interlocking.operator.cancel(a)),
    "release": _sealed("release", _one("release", lambda s, a: s.interlocking.operator.release(a))),
    "fault-release": _sealed("fault-release",
                             _one("fault-release", lambda s, a: s.interlocking.operator.fault_release(a))),
    "reopen": _one("reopen", lambda s, a: s.interlocking.operator.reopen(a)),
    "guide": _sealed("guide", _guide),
    "guide-lock": _sealed("guide-lock",
                          _one("guide-lock", lambda s, a: s.interlocking.operator.guide_lock(a, True))),
    "guide-unlock": _one("guide-unlock", lambda s, a: s.interlocking.operator.guide_lock(a, False)),
    "throw": _throw,
    "lock": _one("lock", lambda s, a: s.interlocking.operator.single_lock(a, True)),
    "unlock": _one("unlock", lambda s, a: s.interlocking.operator.single_lock(a, False)),
    "block": _one("block", lambda s, a: s.interlocking.operator.single_block(a, True)),
    "unblock": _one("unblock", lambda s, a: s.interlocking.operator.single_block(a, False)),
    "block-line": _block_line,
    "line-direction": _line_direction,
    "power-up-release": _sealed("power-up-release", _power_up_release),
    "restart": _restart,
    "neighbour": _neighbour,
    "axle-reset": _sealed("axle-reset", _one("axle-reset", lambda s, a: s.interlocking.operator.axle_reset(a))),
    "doors": _doors,
    "fault": _fault,
    "repair": _repair,
    "faults": _faults,
    "axles": _axles,
    "occupy": _one("occupy", _occupy),
    "vacate": _one("vacate", _vacate),
    "run": _run,
    "changeover": changeover,
}

WORLD_COMMANDS: tuple[Command[World], ...] = tuple(Command(name, USAGE[name], h) for name, h in _HANDLERS.items())

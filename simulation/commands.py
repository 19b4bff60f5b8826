"""The command language shared by the console, scripts, scenarios and the API (DESIGN.md).

Each command returns a :class:`Result`; a refusal (or a failed ``expect``) says why.
"""

from __future__ import annotations

import shlex
from collections.abc import Callable
from typing import TYPE_CHECKING

from liansuo.interlocking.io import Result
from liansuo.interlocking.table import Kind
from liansuo.stations.source import Diagnostic, Source

from .timeparse import parse_duration

if TYPE_CHECKING:
    from .sim import Simulation

Handler = Callable[["Simulation", list[str]], Result]

USAGE = {
    "route": "route START END [VIA ...]",
    "shunt": "shunt START END [VIA ...]",
    "cancel": "cancel SIGNAL",
    "release": "release SIGNAL",
    "fault-release": "fault-release SECTION",
    "reopen": "reopen SIGNAL",
    "guide": "guide SIGNAL",
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
    "neighbour": "neighbour LINK request|depart|restore|accident",
    "doors": "doors PLATFORM open|close",
    "fault": "fault KIND TARGET [key=value ...]",
    "repair": "repair KIND TARGET",
    "faults": "faults",
    "axles": "axles NAME TRACK POSITION [POSITION ...] [TRACK POSITION ...] | axles NAME clear",
    "occupy": "occupy SECTION",
    "vacate": "vacate SECTION",
    "run": "run DURATION",
    "expect": "expect signal|route|turnout|section|refused|accepted|alarm|no-alarm|block-line|code|odometry ...",
}


def _route(kind: Kind) -> Handler:
    def handler(sim: Simulation, args: list[str]) -> Result:
        if len(args) < 2:
            return Result.refuse(f"usage: {USAGE['route' if kind == 'train' else 'shunt']}")
        return sim.interlocking.operator.set_route(kind, args[0], args[-1], tuple(args[1:-1]))

    return handler


def _one(name: str, fn: Callable[[Simulation, str], Result]) -> Handler:
    def handler(sim: Simulation, args: list[str]) -> Result:
        if len(args) != 1:
            return Result.refuse(f"usage: {USAGE[name]}")
        return fn(sim, args[0])

    return handler


def _throw(sim: Simulation, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE['throw']}")
    return sim.interlocking.operator.throw(args[0], args[1])


def _section(sim: Simulation, name: str) -> str:
    return "" if name in sim.station.sections else f"there is no section '{name}' at {sim.station.id}"


def _occupy(sim: Simulation, section: str) -> Result:
    why = _section(sim, section)
    if why:
        return Result.refuse(why)
    sim.field.occupy(section)
    return Result.accept(f"{section} occupied")


def _vacate(sim: Simulation, section: str) -> Result:
    why = _section(sim, section)
    if why:
        return Result.refuse(why)
    sim.field.vacate(section)
    return Result.accept(f"{section} vacated")


def _fault(sim: Simulation, args: list[str]) -> Result:
    from liansuo.circuits.faults import KINDS, parse_fault

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


def _repair(sim: Simulation, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE['repair']}")
    why = sim.field.repair(args[0], args[1])
    if why:
        return Result.refuse(why)
    sim.log("fault", f"repaired: {args[0]} {args[1]}")
    return Result.accept(f"repaired: {args[0]} {args[1]}")


def _faults(sim: Simulation, args: list[str]) -> Result:
    active = [f.describe() for f in sim.field.faults.values()]
    return Result.accept("; ".join(active) if active else "no active faults")


def _axles(sim: Simulation, args: list[str]) -> Result:
    """Wheelsets standing on a track at positions along the line: each shunts its section unless in a dead zone."""
    from liansuo.circuits.railgeometry import Axle

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


def _run(sim: Simulation, args: list[str]) -> Result:
    if len(args) != 1:
        return Result.refuse(f"usage: {USAGE['run']}")
    try:
        seconds = parse_duration(args[0])
    except ValueError as exc:
        return Result.refuse(str(exc))
    if seconds > 7 * 24 * 3600:
        return Result.refuse("run at most a week of simulated time in one command")
    sim.run(seconds)
    return Result.accept(f"t = {sim.t:g} s")


def _block_line(sim: Simulation, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE['block-line']}")
    return sim.interlocking.operator.block_line(args[0], args[1])


def _line_direction(sim: Simulation, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE['line-direction']}")
    return sim.interlocking.operator.line_direction(args[0], args[1])


def _power_up_release(sim: Simulation, args: list[str]) -> Result:
    if args:
        return Result.refuse(f"usage: {USAGE['power-up-release']}")
    return sim.interlocking.operator.power_up_release()


def _restart(sim: Simulation, args: list[str]) -> Result:
    if args:
        return Result.refuse(f"usage: {USAGE['restart']}")
    return sim.restart_interlocking()


def _neighbour(sim: Simulation, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE['neighbour']}")
    link, action = args
    if link not in sim.neighbours.by_link:
        return Result.refuse(f"there is no virtual neighbour on block line '{link}'")
    if action not in ("request", "depart", "restore", "accident"):
        return Result.refuse(f"usage: {USAGE['neighbour']}")
    sim.neighbours.send(link, action)
    return Result.accept(f"neighbour on {link}: {action}")


def _doors(sim: Simulation, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE['doors']}")
    return sim.interlocking.operator.doors(args[0], args[1])


# ---- expect ----------------------------------------------------------------------------------------------------
def _expect(sim: Simulation, args: list[str]) -> Result:
    if not args:
        return Result.refuse(f"usage: {USAGE['expect']}")
    what, rest = args[0], args[1:]
    il = sim.interlocking
    st = sim.station
    if what == "signal" and len(rest) == 2:
        sig, want = rest
        if sig not in st.signals:
            return Result.refuse(f"there is no signal '{sig}'")
        got = sim.aspect(sig)
        return Result(got == want, f"signal {sig} shows {got}" + ("" if got == want else f", expected {want}"))
    if what == "route" and len(rest) in (2, 3):
        if len(rest) == 2:
            route_id, want = rest
        else:
            route_id, want = f"{rest[0]}-{rest[1]}", rest[2]
        if route_id not in sim.table.routes and not any(r.startswith(route_id + "(") for r in sim.table.routes):
            return Result.refuse(f"there is no route {route_id}")
        got = sim.route_state(route_id)
        ok = got == want or (want == "locked" and got in ("locked", "open", "guide", "closed", "in_use", "time_release")
                             ) or (want == "open" and got == "guide")
        return Result(ok, f"route {route_id} is {got}" + ("" if ok else f", expected {want}"))
    if what == "turnout" and len(rest) in (2, 3):
        t, want = rest[0], rest[1]
        if t not in st.turnouts:
            return Result.refuse(f"there is no turnout '{t}'")
        pos, locked = sim.turnout_state(t)
        ok = (pos or "none") == want and (len(rest) == 2 or (rest[2] == "locked") == locked)
        state = f"turnout {t} is {pos or 'without indication'}{' and locked' if locked else ''}"
        return Result(ok, state + ("" if ok else f", expected {' '.join(rest[1:])}"))
    if what == "section" and len(rest) == 2:
        s, want = rest
        if s not in st.sections:
            return Result.refuse(f"there is no section '{s}'")
        got = sim.section_state(s)
        return Result(got == want, f"section {s} is {got}" + ("" if got == want else f", expected {want}"))
    if what in ("refused", "accepted"):
        last = sim.last_result
        text = " ".join(rest)
        if last is None:
            return Result.refuse("no command before this expect")
        if what == "refused":
            ok = not last.ok and _mentions(last.message, text)
            return Result(ok, f"the command was {'refused' if not last.ok else 'accepted'}: {last.message}")
        ok = last.ok and _mentions(last.message, text)
        return Result(ok, f"the command was {'accepted' if last.ok else 'refused'}: {last.message}")
    if what in ("alarm", "no-alarm"):
        text = " ".join(rest).lower()
        hits = [a for a in sim.alarm_texts() if _mentions(a, text)]
        ok = bool(hits) if what == "alarm" else not hits
        shown = "; ".join(sim.alarm_texts()) or "none"
        return Result(ok, f"active alarms: {shown}")
    if what == "block-line" and len(rest) == 2:
        bl = il.core.links.get(rest[0])
        if bl is None:
            return Result.refuse(f"there is no 64D block line '{rest[0]}'")
        return Result(bl.state.value == rest[1], f"block line {rest[0]} is {bl.state.value}")
    if what == "odometry" and len(rest) == 3 and rest[1] == "within":
        tr = sim.fleet.trains.get(rest[0])
        if tr is None:
            return Result.refuse(f"there is no train '{rest[0]}'")
        try:
            bound = float(rest[2].removesuffix("m"))
        except ValueError:
            return Result.refuse("expect odometry NAME within METRES")
        err = tr.odometer.error_m(tr.travelled_m)
        return Result(abs(err) <= bound, f"odometry of {rest[0]} is {err:+.2f} m off" +
                      ("" if abs(err) <= bound else f", expected within {bound:g} m"))
    if what == "code" and len(rest) == 2:
        s, want = rest
        shown = il.out.cab_codes.get(s) or "none"
        return Result(shown == want, f"section {s} carries code {shown}" + ("" if shown == want else
                                                                              f", expected {want}"))
    return Result.refuse(f"usage: {USAGE['expect']}")


COMMANDS: dict[str, Handler] = {
    "route": _route("train"),
    "shunt": _route("shunt"),
    "cancel": _one("cancel", lambda s, a: s.interlocking.operator.cancel(a)),
    "release": _one("release", lambda s, a: s.interlocking.operator.release(a)),
    "fault-release": _one("fault-release", lambda s, a: s.interlocking.operator.fault_release(a)),
    "reopen": _one("reopen", lambda s, a: s.interlocking.operator.reopen(a)),
    "guide": _one("guide", lambda s, a: s.interlocking.operator.guide(a)),
    "guide-lock": _one("guide-lock", lambda s, a: s.interlocking.operator.guide_lock(a, True)),
    "guide-unlock": _one("guide-unlock", lambda s, a: s.interlocking.operator.guide_lock(a, False)),
    "throw": _throw,
    "lock": _one("lock", lambda s, a: s.interlocking.operator.single_lock(a, True)),
    "unlock": _one("unlock", lambda s, a: s.interlocking.operator.single_lock(a, False)),
    "block": _one("block", lambda s, a: s.interlocking.operator.single_block(a, True)),
    "unblock": _one("unblock", lambda s, a: s.interlocking.operator.single_block(a, False)),
    "block-line": _block_line,
    "line-direction": _line_direction,
    "power-up-release": _power_up_release,
    "restart": _restart,
    "neighbour": _neighbour,
    "doors": _doors,
    "fault": _fault,
    "repair": _repair,
    "faults": _faults,
    "axles": _axles,
    "occupy": _one("occupy", _occupy),
    "vacate": _one("vacate", _vacate),
    "run": _run,
    "expect": _expect,
}


def read_steps(src: Source, loc: tuple[str | int, ...], raw: object, errors: list[Diagnostic]) -> list[tuple[str, int]]:
    """The commands of a YAML list at ``loc`` in a script, scenario or exercise, with their lines; a step that is
    not text or names no known command becomes a diagnostic at its position."""
    steps: list[tuple[str, int]] = []
    if not isinstance(raw, list):
        return steps
    for i, s in enumerate(raw):
        at = (*loc, i)
        if not isinstance(s, str):
            errors.append(src.diagnostic(at, "a step is one command as text", "quote it if it contains ':'"))
            continue
        word = s.split("#", 1)[0].split()[:1]
        if word and word[0] not in COMMANDS:
            errors.append(src.diagnostic(at, f"unknown command '{word[0]}'",
                                         f"commands: {', '.join(sorted(COMMANDS))}"))
        steps.append((s, src.mark(at).line))
    return steps


def _with_trains() -> None:
    from .trains.commands import TRAIN_COMMANDS
    from .trains.commands import USAGE as TRAIN_USAGE

    COMMANDS.update(TRAIN_COMMANDS)
    USAGE.update(TRAIN_USAGE)


_with_trains()


def _mentions(message: str, text: str) -> bool:
    """Does ``message`` contain ``text``, ignoring case and quotes? A script's words lose their quotes when the line
    is read (``expect refused there is no train 'T9'``), the interlocking's messages keep theirs."""
    def plain(s: str) -> str:
        return s.replace("'", "").replace('"', "").lower()
    return plain(text) in plain(message)


def execute(sim: Simulation, line: str) -> Result:
    text = line.split("#", 1)[0].strip()
    if not text:
        return Result.accept("")
    try:
        words = shlex.split(text)
    except ValueError as exc:
        return Result.refuse(f"cannot read the command: {exc}")
    handler = COMMANDS.get(words[0])
    if handler is None:
        return Result.refuse(f"unknown command '{words[0]}'; commands: {', '.join(sorted(COMMANDS))}")
    return handler(sim, words[1:])

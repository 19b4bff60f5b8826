"""The scripts' checks, ``expect signal|route|turnout|section|refused|accepted|alarm|no-alarm|block-line|code|cab ...``.

Each compares what the world shows now (through its query API) with what the script expects and says what it saw.
"""

from __future__ import annotations

from liansuo.interlocking.io import Result
from liansuo.interlocking.state import RouteStage
from liansuo.simulation.language import Command
from liansuo.simulation.world import World
from liansuo.stations import limits

USAGE = "expect signal|route|turnout|section|refused|accepted|alarm|no-alarm|block-line|code|cab|odometry ..."
CAB_WORDS = ("none", "lost", "wrong-carrier")  # what 'expect cab' takes besides a code


# the stages of a route (interlocking/state.py) and 'released': what 'expect route' may ask for
ROUTE_WORDS = (*(stage.value for stage in RouteStage), "released")


def _expect(sim: World, args: list[str]) -> Result:
    if not args:
        return Result.refuse(f"usage: {USAGE}")
    what, rest = args[0], args[1:]
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
        if want not in ROUTE_WORDS:
            return Result.refuse(f"a route is {', '.join(ROUTE_WORDS)}, not '{want}'")
        got = sim.route_state(route_id)
        # 'locked' holds from locking until release; 'open' holds for the guide aspect too
        ok = got == want or (want == "locked" and got not in ("setting", "released")) or (
            want == "open" and got == RouteStage.guide.value)
        return Result(ok, f"route {route_id} is {got}" + ("" if ok else f", expected {want}"))
    if what == "turnout" and len(rest) in (2, 3):
        t, want = rest[0], rest[1]
        if t not in st.turnouts:
            return Result.refuse(f"there is no turnout '{t}'")
        pos, locked = sim.turnout_state(t)
        mark = sim.turnout_mark(t)
        # a third word: 'locked' (by anything), 'single-locked' (单锁), 'blocked' (单封); any other word: not locked
        held = {"locked": locked, "single-locked": mark == "locked", "blocked": mark == "blocked"}
        ok = (pos or "none") == want and (len(rest) == 2 or held.get(rest[2], not locked))
        marked = {"locked": ", single-locked", "blocked": ", single-blocked", "guide": ", under guide total lock"}
        state = f"turnout {t} is {pos or 'without indication'}{' and locked' if locked else ''}{marked.get(mark, '')}"
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
        line = sim.view.block_line(rest[0])
        if line is None:
            return Result.refuse(f"there is no 64D or station-block line '{rest[0]}'")
        return Result(line == rest[1], f"block line {rest[0]} is {line}")
    if what == "odometry" and len(rest) == 3 and rest[1] == "within":
        tr = sim.fleet.trains.get(rest[0])
        if tr is None:
            return Result.refuse(f"there is no train '{rest[0]}'")
        try:
            bound = float(rest[2].removesuffix("m"))
        except ValueError:
            return Result.refuse("expect odometry NAME within METRES")
        why = limits.ODOMETRY_BOUND.problem("the bound", bound, rest[2])
        if why:
            return Result.refuse(f"expect odometry: {why}")
        err = tr.odometer.error_m(tr.travelled_m)
        return Result(abs(err) <= bound, f"odometry of {rest[0]} is {err:+.2f} m off" +
                      ("" if abs(err) <= bound else f", expected within {bound:g} m"))
    if what == "code" and len(rest) == 2:
        s, want = rest
        shown = sim.view.cab_code(s) or "none"
        return Result(shown == want, f"section {s} carries code {shown}" + ("" if shown == want else
                                                                              f", expected {want}"))
    if what == "cab" and len(rest) == 2:
        return _cab(sim, *rest)
    return Result.refuse(f"usage: {USAGE}")


def _cab(sim: World, train: str, want: str) -> Result:
    """``expect cab TRAIN CODE|none|lost|wrong-carrier``: what the train's cab signal reads."""
    if train not in sim.fleet.trains:
        return Result.refuse(f"there is no train '{train}' in the yard")
    cab = sim.train_view(train).cab
    shown = cab.state if cab.state in CAB_WORDS else str(cab.code)
    parts = [f"the cab of {train} reads {shown}"]
    if cab.section is not None:
        parts.append(f"on {cab.section}")
    if cab.carrier is not None:
        parts.append(f"carrier {cab.carrier}")
    if cab.level_mA is not None:
        parts.append(f"{cab.level_mA:g} mA")
    if cab.atp_braking:
        parts.append("(ATP braking)")
    return Result(shown == want, " ".join(parts) + ("" if shown == want else f", expected {want}"))


def _mentions(message: str, text: str) -> bool:
    """Does ``message`` contain ``text``, ignoring case and quotes? A script's words lose their quotes when the line
    is read (``expect refused there is no train 'T9'``), the interlocking's messages keep theirs."""
    def plain(s: str) -> str:
        return s.replace("'", "").replace('"', "").lower()
    return plain(text) in plain(message)


EXPECT: Command[World] = Command("expect", USAGE, _expect)

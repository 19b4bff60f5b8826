"""The change-over between simulated and field control (模拟/现场控制切换): the sealed button QHA and the relay QHJ it
drives, as the teaching base's interlocking has them (docs/field-mode.md).

QHA is a sealed, non-self-restoring button (铅封非自复式按钮): each accepted use is counted like the other sealed
buttons, and the console asks for the change-over password before it sends the command. The change-over is accepted
only when nothing could be caught half-way by the equipment changing under it: no route or lock held by the
interlocking, every signal at stop, no turnout being driven, no train or wheelset in the simulated yard, and (towards
the field) a field that answers. Anything else is refused with the reason.

Under field control the field's elements are the field's: a train, wheelsets, an occupied section or a fault on them
belongs at the field (``liansuo field-sim`` reads the same commands), and is refused here.
"""

from __future__ import annotations

from liansuo.interlocking.io import Result
from liansuo.simulation.fieldlink import LinkLost
from liansuo.simulation.world import World

USAGE = "changeover field|simulated"
MODES = {"field": True, "simulated": False}


def changeover(world: World, args: list[str]) -> Result:
    """``changeover field|simulated``: QHA pressed, with the password already given at the console."""
    if len(args) != 1 or args[0] not in MODES:
        return Result.refuse(f"usage: {USAGE}")
    to_field = MODES[args[0]]
    control = world.control
    if control is None:
        return Result.refuse("this station has no field link: start it with a field to change over to "
                             "(liansuo tui STATION --field HOST:PORT, 'liansuo docs field-mode')")
    if control.up == to_field:
        return Result.refuse(f"already in {'field' if to_field else 'simulated'} control")
    why = refuses(world)
    if why:
        return Result.refuse(f"change-over refused: {why}")
    if to_field:
        try:
            control.link.read()
        except LinkLost as exc:
            return Result.refuse(f"change-over refused: the field does not answer ({exc})")
    world.switch_control(to_field)
    world.count_sealed("changeover")
    text = (f"QHJ up: field control (现场控制) of {control.elements.describe()} through {control.link.where}"
            if to_field else "QHJ down: simulated control (模拟控制) of every element")
    world.log("control", text)
    return Result.accept(text)


def refuses(world: World) -> str:
    """Why the equipment may not change over now, in a signaller's words; '' when it may."""
    il = world.interlocking
    if il.core.power_up_locked:
        return "the station is locked since power-up: give the power-up release (上电解锁) first"
    if il.routes:
        route = next(iter(il.routes))
        return f"route {route} is held: cancel it, or let it release, first"
    rules = world.rules.aspects
    closed = {rules.stop, rules.shunt_stop, ""}
    for sig, aspect in world.view.outputs.signals.items():
        if aspect not in closed:
            return f"signal {sig} shows {aspect}: every signal must be at stop"
    view = world.view
    if view.driving():
        return "a turnout is being driven: wait until it shows its position"
    running = sorted(world.field.machines_running())
    if running:
        return f"turnout {running[0]}'s switch machine is running in the simulated yard: wait until it stops"
    for t in world.station.turnouts:
        if world.view.turnout(t).locked and world.view.turnout(t).mark == "guide":
            return f"turnout {t} is under the guide total lock (引导总锁闭): unlock the throat first"
    if world.fleet.trains:
        name = next(iter(world.fleet.trains))
        return f"train {name} is in the simulated yard: the field would not see it; let it run out first"
    if world.parked:
        name = next(iter(world.parked))
        return f"wheelsets {name} stand in the simulated yard: 'axles {name} clear' first"
    return ""


# Commands that put something onto the track or into the equipment of the simulated yard.
YARD_WORDS = ("train", "axles", "occupy", "vacate", "fault", "repair")


def field_refuses(world: World, words: list[str]) -> str:
    """Under field control, why a command that acts on the simulated yard is refused ('' when it is not): the
    elements under field control, and every train, are the field's."""
    control = world.control
    if control is None or not control.up or not words or words[0] not in YARD_WORDS:
        return ""
    word, args = words[0], words[1:]
    where = f"under field control (现场控制): it belongs at the field ({control.link.where}, e.g. liansuo field-sim)"
    if word in ("train", "axles"):
        return f"'{word}' puts a vehicle in the simulated yard, which the interlocking does not read {where}"
    e = control.elements
    if word in ("occupy", "vacate"):
        if args and args[0] in e.tracks:
            return f"section {args[0]} is {where}"
        return ""
    if len(args) < 2:  # fault KIND TARGET ..., repair KIND TARGET
        return ""
    target = args[1]
    platforms = {k.split(":")[0] for k in e.doors}
    if target in e.tracks | e.turnouts | e.signals | e.doors | platforms:
        return f"{target} is {where}"
    return ""

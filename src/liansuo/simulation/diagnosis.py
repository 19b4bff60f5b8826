"""``diagnose KIND ELEMENT``: the trainee registers what they found, as a signaller writes it in the equipment
register (行车设备检查登记簿). It records the finding in the world's log and changes nothing else: the
fault stays until the instructor (the maintainer) repairs it. An assessment (:mod:`~liansuo.classroom.assessment`)
compares the registered findings with the faults it injected.

KIND is a fault kind (docs/faults.md: ``broken-rail``, ``filament``, ``no-indication`` ...), ``red-band`` (a section
shows occupied with no train in it, whatever the cause: what the console shows of a broken rail, low ballast or a
miscounting axle counter) or ``dead-zone`` (a vehicle standing unseen in a dead zone, docs/faults.md "Dead zones").
ELEMENT is an id of the station (a section, a signal, a turnout or crossover pair, an insulated joint, a platform).
"""

from __future__ import annotations

from liansuo.circuits.faults import KINDS
from liansuo.interlocking.io import Result
from liansuo.simulation.language import Command
from liansuo.simulation.unknown import UnknownId, close_matches
from liansuo.simulation.world import World

DIAGNOSIS_KINDS: tuple[str, ...] = (*KINDS, "red-band", "dead-zone")
USAGE = "diagnose KIND ELEMENT"


def element_ids(world: World) -> list[str]:
    """Every id a finding may name."""
    st = world.station
    platforms = [p.id for p in st.model.platforms]
    return [*st.sections, *st.signals, *st.turnouts, *st.pairs, *st.joints, *platforms]


def _diagnose(world: World, args: list[str]) -> Result:
    if len(args) != 2:
        return Result.refuse(f"usage: {USAGE}; KIND one of {', '.join(DIAGNOSIS_KINDS)}")
    kind, element = args
    if kind not in DIAGNOSIS_KINDS:
        return Result.refuse(f"'{kind}' is not a kind of finding; kinds: {', '.join(DIAGNOSIS_KINDS)}")
    known = element_ids(world)
    if element not in known:
        raise UnknownId("element", element, close_matches(element, known), world.station.id)
    world.log("diagnosis", f"registered: {kind} {element}")
    return Result.accept(f"registered: {kind} {element} (行车设备检查登记簿)")


DIAGNOSE: Command[World] = Command("diagnose", USAGE, _diagnose)

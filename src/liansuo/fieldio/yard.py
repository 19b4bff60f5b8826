"""The outdoor equipment of a station with no interlocking of its own: what ``liansuo field-sim`` serves.

A :class:`FieldYard` is the simulation's field, trains and faults, driven by commands that come over the wire
(:mod:`.frames`) instead of from an interlocking in the same process. It steps one interlocking cycle each time it is
given commands, so a field simulator in lockstep with its interlocking is the simulated yard cycle for cycle; its
drivers read the aspects its lamps are commanded to show.

The instructor's commands work on it as on a simulation (faults, repairs, trains, wheelsets, occupied sections);
the signaller's are refused: the signaller works at the interlocking's console.
"""

from __future__ import annotations

from liansuo.circuits.field import FieldCommands
from liansuo.interlocking.io import Result
from liansuo.rules import RuleSet
from liansuo.simulation.commands import WORLD_COMMANDS
from liansuo.simulation.diagnosis import DIAGNOSE
from liansuo.simulation.expect import EXPECT
from liansuo.simulation.language import Command, Language
from liansuo.simulation.sim import Simulation
from liansuo.simulation.trains.commands import TRAIN_COMMANDS
from liansuo.stations.station import Station

# what the field simulator's operator (the instructor) may do: the field's commands and the trains'; automatic
# shunting ('auto') sets routes, which only an interlocking can
FIELD_WORDS = ("fault", "repair", "faults", "axles", "occupy", "vacate")
SIGNALLERS = "is the signaller's: the field simulator has no interlocking; give it at the interlocking's console"


def _refused(name: str, why: str = SIGNALLERS) -> Command[Simulation]:
    def handler(sim: Simulation, args: list[str]) -> Result:
        return Result.refuse(f"'{name}' {why}")
    return Command(name, name, handler)


FIELD_LANGUAGE: Language[Simulation] = Language(
    [c for c in WORLD_COMMANDS if c.name in FIELD_WORDS],
    [_refused(c.name) for c in WORLD_COMMANDS if c.name not in (*FIELD_WORDS, "run")],
    [_refused("run", "is refused: time at the field simulator runs with the interlocking's cycles")],
    [DIAGNOSE], [EXPECT], [c for c in TRAIN_COMMANDS if c.name != "auto"], [_refused("auto")])


class FieldYard(Simulation):
    """A station's trackside equipment and trains, stepped by the commands the wire brings (``step_with``)."""

    language = FIELD_LANGUAGE

    def __init__(self, station: Station, rules: RuleSet, cycle_s: float = 0.25) -> None:
        super().__init__(station, rules=rules, cycle_s=cycle_s)
        self.bus = FieldCommands()  # the last commands the wire brought
        self.shown: dict[str, str] = dict(self.view.outputs.signals)  # what each signal's lamps show
        # each aspect by the lamps it lights and whether the flasher is on
        self._aspect_of = {(frozenset(lamps), a in rules.aspects.flashing): a for a, lamps in rules.lamps.items()}

    def step_with(self, commands: FieldCommands) -> None:
        """One cycle with ``commands``: the trains move, then the equipment acts on the commands."""
        self.bus = commands
        for sig in commands.changed_signals:
            lit = frozenset(commands.lamps.get(sig, ()))
            self.shown[sig] = self._aspect_of.get((lit, sig in commands.flashing), self.rules.aspects.stop)
        self.step()

    def step(self) -> None:
        if self.fleet.trains:
            self.fleet.step(self.cycle_s)
            self.update_axles()
        self.field.step(self.cycle_s, self.bus)
        self.t = round(self.t + self.cycle_s, 9)

    def driver_aspects(self) -> dict[str, str]:
        return self.shown

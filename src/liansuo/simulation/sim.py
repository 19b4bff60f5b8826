"""A running station driven through the command language: the :class:`~simulation.world.World` with its
:data:`LANGUAGE`, and the trains' automation that sends the same commands (automatic shunting, the ATO's doors).

Python API::

    sim = Simulation("jiaopei")          # a bundled name or a path to a station file
    result = sim.command("route X XI")   # Result(ok=True, message='route X-XI selected')
    sim.run(5)                           # advance simulated time by 5 s
    sim.aspect("X")                      # 'U'
    sim.view.route("X-XI")               # RouteView(id='X-XI', signal='X', kind='train', state='open', ...)
"""

from __future__ import annotations

from liansuo.interlocking.io import Result
from liansuo.simulation.changeover import YARD_WORDS, field_refuses
from liansuo.simulation.commands import WORLD_COMMANDS
from liansuo.simulation.diagnosis import DIAGNOSE
from liansuo.simulation.expect import EXPECT
from liansuo.simulation.language import Command, Language
from liansuo.simulation.trains import ato, automatic
from liansuo.simulation.trains.commands import TRAIN_COMMANDS
from liansuo.simulation.trains.fleet import Train
from liansuo.simulation.world import World


def _yard(c: Command[Simulation]) -> Command[Simulation]:
    """``c``, refused under field control where it would act on what the field now owns (:mod:`.changeover`)."""
    if c.name not in YARD_WORDS:
        return c
    inner = c.handler

    def handler(sim: Simulation, args: list[str]) -> Result:
        why = field_refuses(sim, [c.name, *args])
        return Result.refuse(why) if why else inner(sim, args)

    return Command(c.name, c.usage, handler)


LANGUAGE: Language[Simulation] = Language([_yard(c) for c in WORLD_COMMANDS], [DIAGNOSE], [EXPECT],
                                          [_yard(c) for c in TRAIN_COMMANDS])


class Simulation(World):
    """The world, its command language, and trains that drive themselves with it."""

    language = LANGUAGE

    def command(self, line: str) -> Result:
        """Run one line of the command language; scripts' ``expect`` lines check the state."""
        self.publish()
        result = self.language.execute(self, line)
        self.publish()
        if not line.strip().startswith("expect"):
            self.last_result = result
        return result

    def auto_limit(self, train: Train) -> tuple[float, str] | None:
        return automatic.auto_limit(self, train)

    def attach_auto(self, train: Train, plan: list[str], flags: dict[str, bool] | None = None) -> Result:
        return automatic.attach(self, train, plan, flags)

    def after_move(self) -> None:
        ato.platform_doors(self)


__all__ = ["LANGUAGE", "Simulation"]

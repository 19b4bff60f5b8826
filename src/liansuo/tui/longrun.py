"""A ``run DURATION`` typed in the console runs in slices, so the screen never freezes.

The command language judges the line as it judges it anywhere (usage, the duration, its limits): the console sends it
to the language with the simulation's ``run`` only noting how long it was asked to run (:func:`requested_run`). An
accepted run then advances on the console's clock, at most :data:`RUN_SLICE_S` of wall-clock time per tick, with its
progress on the status line; keys, clicks and redraws are handled between slices, and Esc stops it where it is. A
recording holds the cycles of such a run, as it holds the cycles of the running clock; replaying them reproduces it.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable
from dataclasses import dataclass
from typing import TYPE_CHECKING, cast

from liansuo.simulation import Result
from liansuo.tui.panels import clock_text

if TYPE_CHECKING:
    from liansuo.simulation.sim import Simulation
    from liansuo.tui.consolesim import ConsoleSim

# Wall-clock seconds of simulation in one slice. The clock ticks every 0.125 s (tui/app.py, TICK_S), so a long run
# takes less than half of each tick and keys, clicks and redraws keep the rest.
RUN_SLICE_S = 0.05


class _Probe:
    """The simulation as the language's ``run`` sees it, except that ``run`` only notes how long it was asked for."""

    def __init__(self, sim: ConsoleSim) -> None:
        self._sim = sim
        self.seconds: float | None = None

    def run(self, seconds: float) -> None:
        self.seconds = seconds

    def __getattr__(self, name: str) -> object:
        return getattr(self._sim, name)


def requested_run(sim: ConsoleSim, line: str) -> float | None:
    """The simulated seconds a ``run`` line asks for when the command language accepts it; None for any other line,
    a refused one, or a duration the clock cannot count in cycles (the language answers those itself)."""
    words = line.split("#", 1)[0].split()
    if not words or words[0] != "run":
        return None
    probe = _Probe(sim)
    result = sim.language.execute(cast("Simulation", probe), line)
    seconds = probe.seconds
    if not result.ok or seconds is None or not math.isfinite(seconds) or seconds <= 0:
        return None
    return seconds


@dataclass
class LongRun:
    """A ``run`` under way: how many cycles it asked for and how many are done."""

    line: str
    source: str
    cycles: int
    cycle_s: float
    done: int = 0

    @classmethod
    def of(cls, line: str, source: str, seconds: float, cycle_s: float) -> LongRun:
        return cls(line, source, max(0, round(seconds / cycle_s)), cycle_s)  # as World.run counts them

    @property
    def finished(self) -> bool:
        return self.done >= self.cycles

    def advance(self, step: Callable[[], None], budget_s: float | None = None,
                clock: Callable[[], float] = time.monotonic) -> None:
        """Run cycles until the run is done or ``budget_s`` (:data:`RUN_SLICE_S`) of wall-clock time is spent, at
        least one cycle."""
        end = clock() + (RUN_SLICE_S if budget_s is None else budget_s)
        while self.done < self.cycles:
            step()
            self.done += 1
            if clock() >= end:
                break

    def progress(self) -> str:
        share = 100 * self.done // self.cycles if self.cycles else 100
        return (f"{self.line}: {clock_text(self.done * self.cycle_s)} of {clock_text(self.cycles * self.cycle_s)} "
                f"({share}%); Esc stops it")

    def answer(self, t: float) -> Result:
        if self.finished:
            return Result.accept(f"t = {t:g} s")
        return Result.accept(f"'{self.line}' stopped at t = {t:g} s, after {clock_text(self.done * self.cycle_s)} "
                             f"of {clock_text(self.cycles * self.cycle_s)}")

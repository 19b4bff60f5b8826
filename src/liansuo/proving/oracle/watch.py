"""The oracle watching a running :class:`~simulation.sim.Simulation`: after every cycle and every command.

``Watch(sim)`` wraps ``sim.step``, ``sim.rest`` and ``sim.command``; every finding is kept once, when it starts, as a
:class:`Violation` (or, for what the interlocking cannot see, a hazard). The simulation is read through
:class:`SimulationView`: the field's lamps, switch machines, relays, wheelsets and doors, the virtual neighbours'
block machines, and the console's answer to "is this turnout locked".
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from typing import TYPE_CHECKING

from liansuo.proving.oracle.check import Oracle
from liansuo.proving.oracle.records import Finding
from liansuo.rules import RuleSet
from liansuo.simulation.language import split_words

if TYPE_CHECKING:
    from liansuo.interlocking.io import Result
    from liansuo.simulation.sim import Simulation
    from liansuo.stations.station import Station


@dataclass(frozen=True)
class Violation:
    t: float
    prop: str
    text: str
    cycle: int  # the interlocking's cycle count
    key: str = ""  # what it is about (the same key is the same finding)
    hazard: bool = False  # a danger the interlocking cannot see by design, not a violation of its own
    source: str = "oracle"  # who found it: the safety oracle, or the reference judge of commands and releases

    def as_dict(self) -> dict[str, object]:
        return {"t": self.t, "property": self.prop, "text": self.text, "cycle": self.cycle, "key": self.key,
                "hazard": self.hazard, "source": self.source}


class SimulationView:
    """The field as it is, read from a simulation (see :class:`~proving.oracle.view.FieldView`)."""

    def __init__(self, sim: Simulation, rules: RuleSet | None = None) -> None:
        self.sim = sim
        self.field = sim.field
        # read only: shared by every view of a simulation of this station under these rules
        self.stop, self.platform_keys = sim.station.derived(_view_tables, rules or sim.rules)
        self._wheelsets: tuple[float, list[tuple[str, float]]] | None = None
        self._showing: tuple[int, tuple[str, ...]] = (-1, ())

    def showing(self) -> tuple[str, ...]:
        """Signals with a lamp lit other than their stop lamp (read again only after the field applied a lamp
        command: its ``lamp_stamp`` moved)."""
        stamp = self.field.lamp_stamp
        if stamp != self._showing[0]:
            stop = self.stop
            self._showing = (stamp, tuple(sig for sig, lamps in self.field.lamps.items()
                                          if lamps.commanded and lamps.commanded != stop[sig]))
        return self._showing[1]

    def lit(self, signal: str) -> frozenset[str]:
        lit = set(self.field.lamps[signal].lit())
        fl = self.field.flashers.get(signal)
        if fl is not None and fl.energised and fl.bad_contact:
            lit.discard(self.field.flasher_lamp)  # the flashing lamp stays dark
        return frozenset(lit)

    def flashing(self, signal: str) -> bool:
        fl = self.field.flashers.get(signal)
        return (fl is not None and fl.energised and not fl.bad_contact
                and self.field.flasher_lamp in self.field.lamps[signal].lit())

    def proven_lit(self, signal: str) -> tuple[frozenset[str], bool]:
        lamps = self.field.lamps[signal]
        lit = frozenset(name for name in lamps.commanded if lamps.lamps[name].dj_up)
        fl = self.field.flashers.get(signal)
        return lit, fl is not None and fl.energised and self.field.flasher_ok(signal)

    def rails(self, turnout: str) -> str | None:
        return self.field.machines[turnout].rails

    def running(self, turnout: str) -> bool:
        return self.field.machines[turnout].running

    def target(self, turnout: str) -> str | None:
        return self.field.machines[turnout].target

    def moving(self) -> set[str]:
        """Machines running towards a position other than where the rails lie (a machine retrying the position
        its rails are already in moves nothing)."""
        ms = self.field.machines
        return {t for t in self.field.machines_running() if ms[t].rails != ms[t].target}

    def proven(self, turnout: str) -> str | None:
        dbj, fbj = self.field.indication(turnout)
        if dbj and not fbj:
            return "normal"
        if fbj and not dbj:
            return "reverse"
        return None

    def clear(self, section: str) -> bool:
        return self.field.track_up(section)

    def occupied(self, sections: Iterable[str]) -> set[str]:
        return self.field.tracks_down(sections)

    def locked(self, turnout: str) -> bool:
        return self.sim.turnout_locked(turnout)

    def wheelsets(self, tracks: set[str]) -> list[tuple[str, float]]:
        if self._wheelsets is None or self._wheelsets[0] != self.sim.t:
            every = [(a.track, a.x) for a in self.field.axles]
            fleet = self.sim.fleet
            for tr in fleet.trains.values():
                every += [(a.track, a.x) for a in fleet.track.axles(tr.pos, tr.consist.axle_offsets_m)]
            self._wheelsets = (self.sim.t, every)
        return [(t, x) for t, x in self._wheelsets[1] if t in tracks]

    def section_locked(self, section: str) -> bool:
        return self.sim.section_state(section) == "locked" or self.sim.view.section(section).locked

    def doors_safe(self, section: str) -> bool:
        doors = self.field.doors
        return all(not doors[k].is_open or doors[k].faults.bypass for k in self.platform_keys.get(section, ()))

    def line_permits(self, link: str) -> bool:
        return self.sim.neighbours.permits(link)

    def line_outbound(self, link: str) -> bool:
        return self.sim.line_outbound(link)


def _view_tables(st: Station, rules: RuleSet) -> tuple[dict[str, frozenset[str]], dict[str, list[str]]]:
    """The lamps of each signal's stop aspect, and the screen doors (platform:side) of each platform section."""
    names = rules.aspects
    stop = {s.id: frozenset(names.lamps[names.shunt_stop if s.kind.value == "shunting" else names.stop])
            for s in st.model.signals}
    platform_keys: dict[str, list[str]] = {}
    for p in st.model.platforms:
        for d in p.screen_doors:
            platform_keys.setdefault(p.section, []).append(f"{p.id}:{d.side.value}")
    return stop, platform_keys


class Watch:
    """An oracle attached to a simulation; ``violations`` and ``hazards`` are what it found, in order."""

    def __init__(self, sim: Simulation, *, attach: bool = True, rules: RuleSet | None = None,
                 reaction: int = 2, judge: bool = True) -> None:
        """``judge``: the reference judge of commands and releases (:mod:`proving.judge`) watches beside the oracle,
        and its findings are reported as violations too."""
        from liansuo.proving.judge import (
            Judge,  # the judge reads what the oracle's view reads, and the oracle's geometry
        )

        self.sim = sim
        self.oracle = Oracle(sim.station, rules or sim.rules, cycle_s=sim.cycle_s, reaction=reaction)
        self.judge = Judge(sim.station, rules or sim.rules, reaction=reaction) if judge else None
        self.view = SimulationView(sim, rules)
        self.violations: list[Violation] = []
        self.hazards: list[Violation] = []
        self.cycles = 0
        self._last: tuple[object, ...] = ()
        self._wrapped: dict[str, object] = {}  # what ``attach`` set on the simulation: name -> what it had of its own
        if attach:
            self.attach()
        self.check()

    def attach(self) -> None:
        sim = self.sim
        step, command = sim.step, sim.command

        def checked_step() -> None:
            step()
            self.check()

        def noted_command(line: str) -> Result:
            result = command(line)
            self.note(line, result)
            return result

        rest = sim.rest

        def watched_rest(limit: int) -> int:
            # cycles at rest change nothing the oracle reads (its signature stays), so they are checked by counting,
            # unless a finding waits for the interlocking's answer or an overlap's time runs (``Oracle.busy``)
            if self.oracle.busy() or (self.judge is not None and self.judge.busy()):
                return 0
            n = rest(limit)
            self.cycles += n
            return n

        own = vars(sim)  # wrappers set there before this watch's (None: the class's method)
        self._wrapped = {name: own.get(name) for name in ("step", "command", "rest")}
        sim.step = checked_step  # type: ignore[method-assign]
        sim.command = noted_command  # type: ignore[method-assign]
        sim.rest = watched_rest  # type: ignore[method-assign]

    def detach(self) -> None:
        """Stop watching: the simulation's ``step``, ``command`` and ``rest`` are what they were before ``attach``
        (what the watch found stays). The wrappers refer to the simulation and the simulation to them, so a watched
        simulation dropped without this is freed only by the garbage collector."""
        for name, was in self._wrapped.items():
            if was is None:
                delattr(self.sim, name)  # the class's own method again
            else:
                setattr(self.sim, name, was)
        self._wrapped = {}

    def note(self, line: str, result: Result) -> None:
        try:
            words = split_words(line.split("#", 1)[0])
        except ValueError:
            return
        self.oracle.note(words, result.ok)
        if self.judge is not None:
            self._record(self.judge.note(words, result.ok, self.view, self.sim.t), "judge")

    def _signature(self) -> tuple[object, ...]:
        """What the world looks like, in a few numbers: when it is the same as at the last check and nothing there
        runs on time, the findings are the same too."""
        sim = self.sim
        f = sim.field
        return (f.stamp, sim.interlocking.locks.version, id(f.axles), sim.t if sim.fleet.trains else 0.0,
                tuple((t, f.machines[t].target) for t in f.machines_running()),
                tuple(nb.accepted for nb in sim.neighbours.by_link.values()),
                tuple(sim.interlocking.out.line_direction.items()))

    def check(self) -> list[Finding]:
        self.cycles += 1
        signature = self._signature()
        judge = self.judge
        if signature == self._last and not self.oracle.busy() and (judge is None or not judge.busy()):
            if judge is not None:
                judge.memory.commanded = False  # nothing changed: the command released nothing
            return []
        self._last = signature
        showing = self.view.showing()
        new = self.oracle.check(self.view, self.sim.t, showing)
        self._record(new)
        if judge is not None:
            judged = judge.check(self.view, self.sim.t, showing)
            self._record(judged, "judge")
            new += judged
        return new

    def _record(self, found: list[Finding], source: str = "oracle") -> None:
        cycle = self.sim.interlocking.core.cycles  # to name the cycle in the report, not to judge
        for f in found:
            v = Violation(self.sim.t, f.prop, f.text, cycle, f.key, f.hazard, source)
            (self.hazards if f.hazard else self.violations).append(v)

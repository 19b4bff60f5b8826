"""A running station: the clock, the field, the interlocking, and the command language that drives them.

Time is injected: ``step()`` advances the field by one interlocking cycle and then runs the cycle at the new time.
Nothing here reads the wall clock; pacing to real time belongs to the console.
"""

from __future__ import annotations

from collections import deque
from dataclasses import dataclass
from pathlib import Path

from liansuo.circuits.field import Field
from liansuo.circuits.railgeometry import Axle
from liansuo.interlocking.cbi import Interlocking
from liansuo.interlocking.io import Event, Result
from liansuo.interlocking.locks import Hold
from liansuo.interlocking.table import InterlockingTable, build_table
from liansuo.rules import RuleSet, load_rules
from liansuo.stations.loader import load
from liansuo.stations.station import Station

from .neighbour import Neighbours
from .trains.engine import MotionEngine
from .trains.engines import attach_engine, make_engine
from .trains.fleet import Fleet, Train
from .wiring import Wiring


@dataclass(frozen=True)
class TrainView:
    """What a front end shows of a train: its name, the sections its wheelsets shunt, speed and direction."""

    name: str
    sections: tuple[str, ...]
    speed_kmh: float
    direction: str  # "down" or "up"
    mode: str  # "manual", "signal", "auto"
    head_track: str
    head_m: float  # position of the leading wheelset along the line


class Simulation:
    def __init__(self, station: str | Path | Station, *, cycle_s: float = 0.25, rules: str | RuleSet = "china",
                 table: InterlockingTable | None = None, engine: str | MotionEngine = "kinematic") -> None:
        """``engine``: what moves the trains, "kinematic" (built in, the default) or "sumo" (Eclipse SUMO, the
        ``sumo`` extra; see docs/sumo.md), or a :class:`~simulation.trains.engine.MotionEngine`."""
        self.rules = load_rules(rules) if isinstance(rules, str) else rules  # one name chooses every part
        self.station = station if isinstance(station, Station) else load(station, rules=self.rules)
        self.table = table or build_table(self.station, self.rules)
        self.cycle_s = cycle_s
        self.interlocking: Interlocking = Interlocking(self.table, self.rules, cycle_s)
        self.field: Field = Field(self.station, rules=self.rules)
        self.wiring = Wiring(self.station, self.rules, self.field)
        self.neighbours = Neighbours(self.station, self.rules.block_pulse_s)
        self.t = 0.0
        self.last_result: Result | None = None
        self.parked: dict[str, list[Axle]] = {}  # named sets of wheelsets placed by hand (``axles`` command)
        self.events: deque[Event] = deque(maxlen=20_000)  # the world's own events: trains, faults
        self.alarms: dict[str, str] = {}  # the world's alarms (derailment, squeeze by a train)
        motion = make_engine(engine, self.station, cycle_s)
        self.fleet = Fleet(self.station, self.field, lambda: self.interlocking.out.signals, self.log,
                           self._auto_limit, engine=motion, rules=self.rules)
        attach_engine(motion, self.fleet)
        self.wiring.publish(self.interlocking.board, everything=True)
        self.interlocking.cycle(self.t)

    # ---- time -------------------------------------------------------------------------------------------------
    def step(self) -> None:
        il = self.interlocking
        if self.fleet.trains:
            self.fleet.step(self.cycle_s)
            self._platforms()
            self.update_axles()
        self.field.step(self.cycle_s, self.wiring.commands_from(il.out))
        self.t = round(self.t + self.cycle_s, 9)
        self.neighbours.step(self.t, il.out.line_out, self.field.track_up)
        self.publish()
        il.cycle(self.t)

    def publish(self) -> None:
        """Relays follow the field at once; only the interlocking's processing is cyclic."""
        self.wiring.publish(self.interlocking.board)
        self.neighbours.publish(self.interlocking.board)

    def restart_interlocking(self) -> Result:
        """The interlocking loses power and starts again (全站停电恢复): every route and lock is forgotten, every signal
        closes, and the station stays locked (上电锁闭) until the operator's power-up release. The field keeps what
        it had: turnouts lie where they lay, trains stay where they are."""
        self.interlocking = Interlocking(self.table, self.rules, self.cycle_s, locked_at_start=True)
        self.interlocking.core.now = self.t
        self.wiring.relight()
        self.wiring.publish(self.interlocking.board, everything=True)
        self.neighbours.publish(self.interlocking.board)
        self.interlocking.cycle(self.t)
        self.log("power", "interlocking restarted: the station is locked until the power-up release (上电解锁)")
        return Result.accept("interlocking restarted: every section locked and every signal closed until "
                             "'power-up-release' (上电解锁)")

    def place_axles(self, name: str, axles: list[Axle]) -> None:
        """Stand a named set of wheelsets on the track (replacing that name's earlier ones; [] removes them)."""
        if axles:
            self.parked[name] = axles
        else:
            self.parked.pop(name, None)
        self.update_axles()

    def update_axles(self) -> None:
        """Tell the field where every wheelset stands: trains and parked wheelsets."""
        self.field.set_axles([a for group in self.parked.values() for a in group], self.fleet.shunts())

    def log(self, kind: str, text: str) -> None:
        self.events.append(Event(self.t, kind, text))
        if kind == "alarm":
            self.alarms[f"{len(self.alarms)}"] = text

    def _auto_limit(self, train: Train) -> tuple[float, str] | None:
        from .trains.automatic import auto_limit

        return auto_limit(self, train)

    def attach_auto(self, train: Train, plan: list[str], flags: dict[str, bool] | None = None) -> Result:
        from .trains.automatic import attach

        return attach(self, train, plan, flags)

    def _platforms(self) -> None:
        from .trains.ato import platform_doors

        platform_doors(self)

    def close(self) -> None:
        """Release what the train engine holds (the SUMO worker process); the kinematic engine holds nothing."""
        self.fleet.engine.close()

    def run(self, seconds: float) -> None:
        for _ in range(max(0, round(seconds / self.cycle_s))):
            self.step()

    # ---- commands ---------------------------------------------------------------------------------------------
    def command(self, line: str) -> Result:
        """Run one line of the command language; scripts' ``expect`` lines check the state."""
        from .commands import execute

        self.publish()
        result = execute(self, line)
        self.publish()
        if not line.strip().startswith("expect"):
            self.last_result = result
        return result

    # ---- queries ----------------------------------------------------------------------------------------------
    def aspect(self, signal: str) -> str:
        return self.interlocking.out.signals.get(signal, "")

    def route_state(self, route_id: str) -> str:
        rs = self.interlocking.routes.get(route_id)
        return "released" if rs is None else rs.stage.value

    def section_state(self, section: str) -> str:
        if not self.interlocking.board.clear(section):
            return "occupied"
        if self.interlocking.locks.section_locked(section):
            return "locked"
        return "free"

    def turnout_state(self, turnout: str) -> tuple[str | None, bool]:
        """(position indicated or None, locked): locked by a route, an overlap, single lock, guide total lock or the
        power-up lock, or standing in a locked section."""
        il = self.interlocking
        return il.board.indication(turnout), il.locks.turnout_locked(turnout)

    def turnout_mark(self, turnout: str) -> str:
        """What the console marks on a turnout: 'blocked' (单封), 'locked' (单锁), 'guide' (引导总锁闭) or ''."""
        locks = self.interlocking.locks
        if turnout in locks.blocked:
            return "blocked"
        holds = {lk.hold for lk, _, _ in locks.turnout_locks(turnout)}
        return "locked" if Hold.single in holds else "guide" if Hold.guide in holds else ""

    def line_outbound(self, link: str) -> bool:
        """The direction circuit of an automatic line is set for our departures (改方)."""
        return self.interlocking.out.line_direction.get(link) == "outbound"

    def train_views(self) -> list[TrainView]:
        """Every train in the yard."""
        out = []
        for tr in self.fleet.trains.values():
            track, x = self.fleet.front(tr)
            out.append(TrainView(tr.name, self.fleet.sections_of(tr), round(tr.speed_kmh, 2), tr.direction.value,
                                 tr.mode, track, round(x, 2)))
        return out

    def alarm_texts(self) -> list[str]:
        return [a.text for a in self.interlocking.alarms.values()] + list(self.alarms.values())

    def event_texts(self) -> list[str]:
        merged = sorted([*self.interlocking.events, *self.events], key=lambda e: e.t)
        return [f"{e.t:9.2f} {e.kind:8} {e.text}" for e in merged]

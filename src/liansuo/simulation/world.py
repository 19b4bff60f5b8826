"""The world around the interlocking: the clock, the field, the interlocking itself, the trains, and what they show.

Time is injected: ``step()`` advances the field by one interlocking cycle and then runs the cycle at the new time.
Nothing here reads the wall clock; pacing to real time belongs to the console.

The world reads the interlocking through its query API (:mod:`.view`, ``World.view``) and drives it through its
operations. What drives trains on their own (automatic shunting, the ATO's platform doors) sends commands of the
command language, so it is plugged in from above by the :class:`~simulation.sim.Simulation`: a bare world drives
only by hand and by signal.
"""

from __future__ import annotations

import weakref
from collections import deque
from pathlib import Path

from liansuo.circuits.field import Field, FieldCommands
from liansuo.circuits.railgeometry import Axle
from liansuo.interlocking.cbi import Interlocking
from liansuo.interlocking.io import Event, Result
from liansuo.interlocking.table.build import InterlockingTable, build_table
from liansuo.rules import RuleSet, load_rules
from liansuo.simulation.fieldlink import Elements, FieldControl, FieldLink
from liansuo.simulation.neighbour import Neighbours
from liansuo.simulation.trains.cabsignal import ATP
from liansuo.simulation.trains.engine import MotionEngine
from liansuo.simulation.trains.engines import attach_engine, make_engine
from liansuo.simulation.trains.fleet import Fleet, Train
from liansuo.simulation.trains.movement import OUTSIDE
from liansuo.simulation.unknown import UnknownId, close_matches
from liansuo.simulation.view import AlarmView, CabView, InterlockingView, TrainView
from liansuo.simulation.wiring import Wiring
from liansuo.stations.loader import load
from liansuo.stations.station import Station


class World:
    """One station's world: built from a station (a bundled name, a path or a :class:`Station`), its rules and its
    table; ``view`` is the interlocking's query API, ``fleet`` the trains, ``field`` the trackside equipment."""

    def __init__(self, station: str | Path | Station, *, cycle_s: float = 0.25, rules: str | RuleSet = "china",
                 table: InterlockingTable | None = None, engine: str | MotionEngine = "kinematic") -> None:
        """``engine``: what moves the trains, "kinematic" (built in, the default) or "sumo" (Eclipse SUMO, the
        ``sumo`` extra; see docs/sumo.md), or a :class:`~simulation.trains.engine.MotionEngine`."""
        self.rules = load_rules(rules) if isinstance(rules, str) else rules  # one name chooses every part
        self.station = station if isinstance(station, Station) else load(station, rules=self.rules)
        self.table = table or build_table(self.station, self.rules)
        self.cycle_s = cycle_s
        self.interlocking: Interlocking = Interlocking(self.table, self.rules, cycle_s)
        self.view = InterlockingView(self.interlocking)
        self.field: Field = Field(self.station, rules=self.rules)
        self.wiring = Wiring(self.station, self.rules, self.field)
        self.neighbours = Neighbours(self.station, self.rules.block_pulse_s)
        self.t = 0.0
        self.last_result: Result | None = None  # the answer to the last command (what 'expect refused' checks)
        self.parked: dict[str, list[Axle]] = {}  # named sets of wheelsets placed by hand (``axles`` command)
        self.events: deque[Event] = deque(maxlen=20_000)  # the world's own events: trains, faults
        self.alarms: dict[str, str] = {}  # the world's alarms (derailment, squeeze by a train)
        self.sealed: dict[str, int] = {}  # sealed button (铅封) -> its accepted uses (see ``sealed_uses``)
        self.control: FieldControl | None = None  # the change-over to field equipment, once a link is attached
        for reason in self.field.held_down().values():  # sections past their track-circuit model's range
            self.log("alarm", reason)
        motion = make_engine(engine, self.station, cycle_s)
        # what the fleet calls back does not keep the world alive: a dropped world is freed at once, not by the
        # garbage collector (verify drops thousands of simulations)
        me = weakref.proxy(self)
        self.fleet = Fleet(self.station, self.field, lambda: me.driver_aspects(),
                           lambda kind, text: me.log(kind, text), lambda train: me.auto_limit(train),
                           engine=motion, rules=self.rules)
        attach_engine(motion, self.fleet)
        self.wiring.power_on(self.view.inputs, self.view.outputs)
        self.interlocking.cycle(self.t)

    # ---- time -------------------------------------------------------------------------------------------------
    def step(self) -> None:
        if self.fleet.trains:
            self.fleet.step(self.cycle_s)
            self.after_move()
            self.update_axles()
        commands = self.wiring.commands_from(self.view.outputs)
        if self.field_control:
            self._exchange(commands)  # before the simulated field takes the commands it consumes (axle resets)
        self.field.step(self.cycle_s, commands)
        self.t = round(self.t + self.cycle_s, 9)
        self.neighbours.step(self.t, self.view.outputs.line_out, self.track_up)
        self.publish()
        self.interlocking.cycle(self.t)

    def rest(self, limit: int) -> int:
        """Run up to ``limit`` cycles in which nothing happens but time passing and switch machines running on: no
        trains, the interlocking at rest (:mod:`interlocking.quiet`), no relay changing, no move ending, no line pulse
        falling due. The same as as many ``step()`` calls (tests/test_quiet_same.py), without the work of looking at
        everything each time. Returns how many cycles it ran: 0 when the next cycle does more."""
        il = self.interlocking
        quiet = il.quiet
        if quiet is None or not il.skip_quiet or self.fleet.trains or limit <= 0 or self.field_control:
            return 0  # under field control every cycle exchanges with the field (its heartbeat)
        out = self.view.outputs
        if not self.wiring.at_rest(out) or il.core.board.pending() \
                or not self.neighbours.rests(out.line_out, self.track_up):
            return 0
        n = self.field.rest_steps(self.cycle_s, self.wiring.commands, limit)
        due = self.neighbours.next_due()
        t, k = self.t, 0
        while k < n:
            nt = round(t + self.cycle_s, 9)
            if not quiet.holds(nt) or (due is not None and due <= nt):
                break
            t, k = nt, k + 1
        if k:
            self.field.rest(self.cycle_s, k)
            self.t = self.neighbours.t = t
            il.rest(k, t)
        return k

    def run(self, seconds: float) -> None:
        for _ in range(max(0, round(seconds / self.cycle_s))):
            self.step()

    def publish(self) -> None:
        """Relays follow the field at once; only the interlocking's processing is cyclic."""
        self.wiring.publish(self.view.inputs)
        self.neighbours.publish(self.view.inputs)

    # ---- field control (现场控制): fieldlink.py, changeover.py -----------------------------------------------------
    def attach_field(self, link: FieldLink) -> None:
        """Wire a field link behind the change-over relay QHJ; the station stays in simulated control until the
        change-over (``changeover field``)."""
        if self.control is not None:
            self.control.link.close()
        self.control = FieldControl(link, self.wiring.signal_lamps, set(self.field.flashers))

    @property
    def field_control(self) -> bool:
        """QHJ is up: the link's elements are read from and driven in the field."""
        return self.control is not None and self.control.up

    def track_up(self, section: str) -> bool:
        """The track relay as wired now: the field's under field control, the simulated field's otherwise."""
        if self.control is not None and self.control.up and section in self.control.elements.tracks:
            return self.view.inputs.clear(section)
        return self.field.track_up(section)

    def switch_control(self, field: bool) -> None:
        """Pick QHJ up (``field``) or let it drop, and read every relay as now wired. The checks that it is safe
        are the change-over command's (:mod:`.changeover`)."""
        assert self.control is not None
        self.control.up = field
        self.wiring.remote = self.control.elements if field else Elements()
        if field:
            self._log_event(self.control.refresh(self.view.inputs))
        else:
            self.control.lost = ""
            self.wiring.publish(self.view.inputs, everything=True)

    def _exchange(self, commands: FieldCommands) -> None:
        assert self.control is not None
        self._log_event(self.control.exchange(commands, self.view.inputs))

    def _log_event(self, event: tuple[str, str] | None) -> None:
        if event is not None:
            self.log(*event)

    def restart_interlocking(self) -> Result:
        """The interlocking loses power and starts again (全站停电恢复): every route and lock is forgotten, every signal
        closes, and the station stays locked (上电锁闭) until the operator's power-up release. The field keeps what
        it had: turnouts lie where they lay, trains stay where they are."""
        self.interlocking = Interlocking(self.table, self.rules, self.cycle_s, locked_at_start=True, now=self.t)
        self.view = InterlockingView(self.interlocking)
        self.wiring.relight()
        self.wiring.publish(self.view.inputs, everything=True)
        if self.control is not None and self.control.up:
            self._log_event(self.control.refresh(self.view.inputs))
        self.neighbours.publish(self.view.inputs)
        self.interlocking.cycle(self.t)
        self.log("power", "interlocking restarted: the station is locked until the power-up release (上电解锁)")
        return Result.accept("interlocking restarted: every section locked and every signal closed until "
                             "'power-up-release' (上电解锁)")

    def close(self) -> None:
        """Release what the train engine holds (the SUMO worker process; the kinematic engine holds nothing) and
        the field link."""
        self.fleet.engine.close()
        if self.control is not None:
            self.control.link.close()

    # ---- wheelsets, doors, the log ------------------------------------------------------------------------------
    def place_axles(self, name: str, axles: list[Axle]) -> None:
        """Stand a named set of wheelsets on the track (replacing that name's earlier ones; [] removes them)."""
        if axles:
            self.parked[name] = axles
        else:
            self.parked.pop(name, None)
        self.update_axles()

    def update_axles(self) -> None:
        """Tell the field where every wheelset stands (trains and parked wheelsets) and where the trains' traction
        current leaks through long dead zones."""
        self.field.set_axles([a for group in self.parked.values() for a in group], self.fleet.wheelsets())
        self.field.set_leakage(self.fleet.leaking())

    def doors(self, platform: str, action: str) -> Result:
        """Open or close a platform's screen doors through the interlocking (the ``doors`` command, the ATO)."""
        return self.interlocking.operator.doors(platform, action)

    def log(self, kind: str, text: str) -> None:
        self.events.append(Event(self.t, kind, text))
        if kind == "alarm":
            self.alarms[f"{len(self.alarms)}"] = text

    # ---- what drives trains on their own: nothing in a bare world (the Simulation plugs its automation in) -----
    def auto_limit(self, train: Train) -> tuple[float, str] | None:
        """The automatic controller's speed limit for ``train`` this step (m/s) and why; None: the signals rule."""
        return None

    def attach_auto(self, train: Train, plan: list[str], flags: dict[str, bool] | None = None) -> Result:
        """Switch ``train`` to automatic shunting with a plan of routes."""
        return Result.refuse(f"train {train.name}: there is no automatic driving in this world")

    def after_move(self) -> None:
        """What happens on board after the trains moved (the ATO's platform doors)."""

    def driver_aspects(self) -> dict[str, str]:
        """The aspects the drivers see: what the interlocking commands (the field simulator's, what its lamps
        show)."""
        return self.view.outputs.signals

    # ---- queries: each raises UnknownId (a KeyError) for an id the station does not have ---------------------------
    def aspect(self, signal: str) -> str:
        return self.view.aspect(signal)

    def route_state(self, route_id: str) -> str:
        return self.view.route_state(route_id)

    def section_state(self, section: str) -> str:
        return self.view.section(section).state

    def turnout_state(self, turnout: str) -> tuple[str | None, bool]:
        """(position indicated or None, locked): locked by a route, an overlap, single lock, guide total lock or the
        power-up lock, or standing in a locked section."""
        tv = self.view.turnout(turnout)
        return tv.position, tv.locked

    def turnout_locked(self, turnout: str) -> bool:
        """``turnout_state(turnout)[1]``, asked alone (the safety oracle asks it of every turnout it watches)."""
        return self.view.turnout_locked(turnout)

    def turnout_mark(self, turnout: str) -> str:
        """What the console marks on a turnout: 'blocked' (单封), 'locked' (单锁), 'guide' (引导总锁闭) or ''."""
        return self.view.turnout(turnout).mark

    def line_outbound(self, link: str) -> bool:
        """The direction circuit of an automatic line is set for our departures (改方)."""
        return self.view.line_outbound(link)

    def train_views(self) -> list[TrainView]:
        """Every train in the yard (those that have left the station are no longer in it: ask ``train_view``)."""
        return [self._train_view(tr) for tr in self.fleet.trains.values()]

    def train_view(self, name: str) -> TrainView:
        """One train by name, in the yard or gone: a train that has run out of the station answers with
        ``state == 'left'`` (``left``) and no position, until a new train takes its name."""
        tr = self.fleet.trains.get(name)
        if tr is not None:
            return self._train_view(tr)
        gone = self.fleet.departed.get(name)
        if gone is not None:
            return TrainView(name, (), 0.0, gone.direction, gone.mode, None, None, "left")
        known = [*self.fleet.trains, *self.fleet.departed]
        raise UnknownId("train", name, close_matches(name, known), self.station.id)

    def _train_view(self, tr: Train) -> TrainView:
        track, x = self.fleet.front(tr)
        sections, speed = self.fleet.sections_of(tr), round(tr.speed_kmh, 2)
        r = tr.cab.reading
        cab = CabView(r.state, r.section, r.code, r.carrier, r.level_mA, ATP in tr.estops.active)
        if track == OUTSIDE:  # the head has run out over the boundary; the rear is still in
            return TrainView(tr.name, sections, speed, tr.direction.value, tr.mode, None, None, "leaving", cab)
        return TrainView(tr.name, sections, speed, tr.direction.value, tr.mode, track, round(x, 2), tr.state, cab)

    def count_sealed(self, button: str) -> None:
        """One more accepted use of a sealed button (铅封按钮), named by its command."""
        self.sealed[button] = self.sealed.get(button, 0) + 1

    def sealed_uses(self) -> dict[str, int]:
        """The sealed buttons' counters (铅封计数): command -> accepted uses in this world, such as
        ``{'release': 2, 'guide': 1}``; a button not used yet is absent. They survive a ``restart``, like the counters
        on the console."""
        return dict(self.sealed)

    def alarm_views(self) -> list[AlarmView]:
        """Active alarms: the interlocking's, then the world's."""
        world = [AlarmView(f"world:{k}", "world", "", text, None) for k, text in self.alarms.items()]
        return [*self.view.alarms(), *world]

    def alarm_texts(self) -> list[str]:
        return [a.text for a in self.alarm_views()]

    def event_texts(self) -> list[str]:
        merged = sorted([*self.view.events(), *self.events], key=lambda e: e.t)
        return [f"{e.t:9.2f} {e.kind:8} {e.text}" for e in merged]

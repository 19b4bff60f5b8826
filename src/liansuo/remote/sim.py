"""A seat of the classroom server as the console reads a simulation (:class:`~tui.consolesim.ConsoleSim`).

The station, its rules and its interlocking table are loaded here from the welcome's ``station`` (they hold no
secret); the state comes only from the server's snapshots (:class:`~simulation.snapshot.SnapshotView`). ``step``
takes the newest snapshot: the server runs the clock. ``command`` sends a line to the seat and waits for the answer.

Fail-safe: while the connection is down the console does not go on showing the last state as if it were live. It
shows what a CBI display shows when it has lost its inputs: every section occupied (red), every lamp dark, every
turnout without indication, no route; an alarm says why, and every command is refused with the reason.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from liansuo.classroom.snapshot import SnapshotView
from liansuo.interlocking.io import MAX_EVENTS, Event, Result
from liansuo.interlocking.table.build import InterlockingTable, build_table
from liansuo.remote.link import ServerLink, Unlinked
from liansuo.rules import RuleSet, load_rules
from liansuo.simulation.language import Language
from liansuo.simulation.sim import LANGUAGE, Simulation
from liansuo.simulation.view import AlarmView, TrainView
from liansuo.stations.loader import load, load_text
from liansuo.stations.station import Station

LOST = "connection to the classroom server lost, reconnecting"
ENDED = "connection to the classroom server ended"
NOT_IN = "not logged in to the classroom yet"


@dataclass(frozen=True)
class Doors:
    """A platform's screen doors as a snapshot tells them."""

    state: str  # closed, open or bypass

    @property
    def pdqcj(self) -> bool:
        return self.state == "bypass"

    @property
    def is_open(self) -> bool:
        return self.state == "open"


@dataclass(frozen=True)
class FaultText:
    """A fault as the instructor's snapshot tells it."""

    text: str

    def describe(self) -> str:
        return self.text


class LiveView(SnapshotView):
    """A snapshot's answers, with the events of every snapshot of the seat shown received so far (newest last)."""

    def __init__(self, station_id: str, data: dict[str, Any], log: Callable[[], deque[Event]]) -> None:
        super().__init__(station_id, data)
        self._log = log

    def events(self) -> deque[Event]:
        return self._log()


class RemoteField:
    """The field as the console draws it, from one snapshot."""

    def __init__(self, view: SnapshotView) -> None:
        self._lit = view.lit
        self.doors = {k: Doors(v) for k, v in view.doors.items()}
        self.faults = {i: FaultText(f) for i, f in enumerate(view.faults)}

    def lit_lamps(self, signal: str) -> set[str]:
        return set(self._lit.get(signal, ()))


def load_station(source: dict[str, Any], rules: RuleSet) -> Station:
    """The station a welcome names: bundled (its name), or the file's text."""
    text = source.get("text")
    if isinstance(text, str):
        return load_text(text, f"{source.get('name', 'station')}.yaml", rules=rules)
    return load(str(source["name"]), rules=rules)


def dark(station: Station, t: float, why: str = LOST) -> dict[str, Any]:
    """The snapshot of a station whose inputs are lost: sections occupied, turnouts without indication, lamps dark,
    no route, doors not shown closed and locked."""
    return {
        "t": t,
        "sections": {s: [True, False] for s in station.sections},
        "turnouts": [{"id": t, "position": None, "locked": True, "why": LOST, "mark": "", "moving": False}
                     for t in station.turnouts],
        "signals": [{"id": s, "aspect": "", "route": None, "closed": False, "lamp_dark": False, "red_dark": False,
                     "filament": False, "flasher": False} for s in station.signals],
        "lit": {},
        "routes": [],
        "doors": {f"{p.id}:{d.side.value}": "open" for p in station.model.platforms for d in p.screen_doors},
        "lines": {lk.id: None for lk in station.model.links},
        "trains": [],
        "alarms": [{"key": "link", "kind": "link", "element": "", "text": why, "t": None}],
        "events": [],
    }


class RemoteSimulation:
    """One seat of the classroom, read from its snapshots and operated through the server."""

    language: Language[Simulation] = LANGUAGE  # for completion: the same words the server's simulation reads

    def __init__(self, link: ServerLink | Unlinked) -> None:
        self.link = link
        self.rules: RuleSet = load_rules()
        self.station: Station = load_station(dict(link.welcome.get("station") or {}), self.rules)
        self.table: InterlockingTable = build_table(self.station, self.rules)
        self.cycle_s = float(link.welcome.get("cycle_s", 0.25))
        self.last_result: Result | None = None
        self.events: deque[Event] = deque()  # the world's: a snapshot's events are all in the view's log
        self.parked: dict[str, object] = {}
        self.paused = False
        self.speed = 1.0
        self.live = False  # showing the server's state (False: the fail-safe picture, or nothing received yet)
        self.seat = link.seat
        self._logs: dict[int, deque[Event]] = {}  # each seat's events, kept while the instructor watches another
        self._show(dark(self.station, 0.0, LOST if isinstance(link, ServerLink) else NOT_IN))
        self.live = False

    def attach(self, link: ServerLink) -> None:
        """Logged in: the seat's state from now on comes through ``link``."""
        self.link, self.seat = link, link.seat

    def log(self, seat: int) -> deque[Event]:
        """The events of ``seat`` received so far (newest last)."""
        return self._logs.setdefault(seat, deque(maxlen=MAX_EVENTS))

    @property
    def t(self) -> float:
        return self.view.t

    def _show(self, data: dict[str, Any]) -> None:
        self.view = LiveView(self.station.id, data, lambda: self.log(self.seat))
        self.field = RemoteField(self.view)
        self.lesson: dict[str, Any] | None = data.get("exercise")  # what the trainee is told of the exercise
        self.paused = bool(data.get("paused", self.paused))
        self.speed = float(data.get("speed", self.speed))
        self.live = True

    # ---- the two things the console does ------------------------------------------------------------------------
    def step(self) -> None:
        """Show the newest snapshot (the server runs the clock); the fail-safe picture while the link is down."""
        data, seat, events = self.link.take()
        self.log(seat).extend(Event(float(t), str(k), str(x)) for t, k, x in events)
        if seat != self.seat:  # the instructor watches another seat: its state and events only from now on
            self.seat = seat
            if self.live:  # not the seat watched before's state, shown as this one's
                self._show(dark(self.station, self.t, f"waiting for the state of seat {seat}"))
                self.live = False
        if not self.link.connected:
            if self.live:
                self._show(dark(self.station, self.t))
                self.live = False
            return
        if data is not None and data.get("seat") == self.seat:
            self._show(data)

    def command(self, line: str) -> Result:
        reply = self.link.command(line, seat=self.seat if self.link.role == "instructor" else None)
        if reply.get("type") == "answer":
            result = Result(bool(reply.get("ok")), str(reply.get("message", "")))
        else:
            result = Result.refuse(str(reply.get("message", reply)))
        self.last_result = result
        return result

    # ---- what the console reads ---------------------------------------------------------------------------------
    def aspect(self, signal: str) -> str:
        return self.view.aspect(signal)

    def section_state(self, section: str) -> str:
        return self.view.section(section).state

    def turnout_state(self, turnout: str) -> tuple[str | None, bool]:
        tv = self.view.turnout(turnout)
        return tv.position, tv.locked

    def turnout_mark(self, turnout: str) -> str:
        return self.view.turnout(turnout).mark

    def train_views(self) -> list[TrainView]:
        return list(self.view.trains)

    def alarm_views(self) -> list[AlarmView]:
        return list(self.view.alarms())

    def sealed_uses(self) -> dict[str, int]:
        return dict(self.view.sealed)

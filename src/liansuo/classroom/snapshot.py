"""A simulation's state as a console shows it, as JSON: what the classroom server sends its clients.

A snapshot holds what a console draws (sections, turnouts, lamps, routes, doors, block lines, trains, alarms) and
the events since the client's last one. It is made for a role (:mod:`.roles`): a trainee's leaves out what the CBI
display would not show (faults injected, trains placed, vehicles that shunt no track circuit), so no client of a
trainee's seat ever receives them. :class:`SnapshotView` reads one back with the query API's own records
(:mod:`.view`), so a console draws a remote simulation as it draws a local one.
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import asdict
from typing import Any

from liansuo.classroom.roles import INSTRUCTOR, TRAINEE_WORLD_EVENTS
from liansuo.interlocking.io import Event
from liansuo.simulation.sim import Simulation
from liansuo.simulation.unknown import require
from liansuo.simulation.view import AlarmView, CabView, RouteView, SectionView, SignalView, TrainView, TurnoutView

SCHEMA = 1


class EventCursor:
    """Where a client's event stream stands: the events of the interlocking and of the world it has been sent."""

    def __init__(self) -> None:
        self._last: dict[int, Event | None] = {}

    def fresh(self, sim: Simulation, role: str) -> list[Event]:
        return self.fresh_from(sim.view.events(), sim.events, role)

    def fresh_from(self, interlocking: Sequence[Event], world: Sequence[Event], role: str) -> list[Event]:
        """The events of the two logs (the interlocking's, the world's; live sequences, newest last) not read yet,
        in time order; of the world's, a trainee's only alarms and power."""
        out: list[Event] = []
        for i, dq in enumerate((interlocking, world)):
            last = self._last.get(i)
            got: list[Event] = []
            for e in reversed(dq):
                if e is last:
                    break
                got.append(e)
            if dq:
                self._last[i] = dq[-1]
            if i == 1 and role != INSTRUCTOR:
                got = [e for e in got if e.kind in TRAINEE_WORLD_EVENTS]
            out += reversed(got)
        out.sort(key=lambda e: e.t)
        return out


def snapshot(sim: Simulation, role: str, cursor: EventCursor) -> dict[str, Any]:
    """The state of ``sim`` as ``role`` may see it, with the events since ``cursor`` (which it moves on)."""
    view, st = sim.view, sim.station
    trains = [tv for tv in sim.train_views() if role == INSTRUCTOR or tv.sections]
    return {
        "schema": SCHEMA,
        "t": sim.t,
        "sections": {s.id: [s.occupied, s.locked] for s in view.sections(list(st.sections))},
        "turnouts": [asdict(t) for t in view.turnouts()],
        "signals": [asdict(s) for s in view.signals()],
        "lit": {s: sorted(sim.field.lit_lamps(s)) for s in st.signals},
        "routes": [asdict(r) for r in view.routes()],
        "doors": {k: ("bypass" if d.pdqcj else "open" if d.is_open else "closed") for k, d in sim.field.doors.items()},
        "lines": {lk.id: view.block_line(lk.id) for lk in st.model.links},
        "trains": [asdict(tv) for tv in trains],
        "alarms": [asdict(a) for a in sim.alarm_views()],
        "sealed": sim.sealed_uses(),
        "waiting": {r.signal: why for r in view.routes() if (why := view.waiting(r.signal))},
        "faults": [f.describe() for f in sim.field.faults.values()] if role == INSTRUCTOR else [],
        "events": [[e.t, e.kind, e.text] for e in cursor.fresh(sim, role)],
    }


class SnapshotView:
    """The query API's questions (those a console asks) answered from a snapshot."""

    def __init__(self, station_id: str, data: dict[str, Any]) -> None:
        self._station = station_id
        self.t = float(data["t"])
        self._sections = {k: SectionView(k, bool(v[0]), bool(v[1])) for k, v in data["sections"].items()}
        self._turnouts = {d["id"]: TurnoutView(**d) for d in data["turnouts"]}
        self._signals = {d["id"]: SignalView(**d) for d in data["signals"]}
        self.lit = {k: set(v) for k, v in data["lit"].items()}
        self._routes = [RouteView(**{**d, "sections": tuple(d["sections"])}) for d in data["routes"]]
        self.doors: dict[str, str] = dict(data["doors"])
        self.lines: dict[str, str | None] = dict(data["lines"])
        self.trains = [_train(d) for d in data["trains"]]
        self.alarm_list = [AlarmView(**d) for d in data["alarms"]]
        self.new_events = [Event(float(t), str(k), str(x)) for t, k, x in data["events"]]
        self.sealed: dict[str, int] = {str(k): int(v) for k, v in data.get("sealed", {}).items()}
        self._waiting: dict[str, str] = dict(data.get("waiting", {}))
        self.faults: list[str] = [str(f) for f in data.get("faults", [])]

    def waiting(self, signal: str) -> str:
        """Why ``signal`` stays red over its route, as the server's interlocking said ('' if it does not wait)."""
        require("signal", signal, self._signals, self._station)
        return self._waiting.get(signal, "")

    def aspect(self, signal: str) -> str:
        require("signal", signal, self._signals, self._station)
        return self._signals[signal].aspect

    def signals(self) -> tuple[SignalView, ...]:
        return tuple(self._signals.values())

    def signal(self, signal: str) -> SignalView:
        require("signal", signal, self._signals, self._station)
        return self._signals[signal]

    def routes(self) -> tuple[RouteView, ...]:
        return tuple(self._routes)

    def route_of(self, signal: str) -> RouteView | None:
        return next((r for r in self._routes if r.signal == signal), None)

    def turnout(self, turnout: str) -> TurnoutView:
        require("turnout", turnout, self._turnouts, self._station)
        return self._turnouts[turnout]

    def turnouts(self) -> tuple[TurnoutView, ...]:
        return tuple(self._turnouts.values())

    def section(self, section: str) -> SectionView:
        require("section", section, self._sections, self._station)
        return self._sections[section]

    def sections(self, ids: Sequence[str]) -> tuple[SectionView, ...]:
        return tuple(self.section(s) for s in ids)

    def block_line(self, link: str) -> str | None:
        require("line", link, self.lines, self._station)
        return self.lines[link]

    def alarms(self) -> tuple[AlarmView, ...]:
        return tuple(self.alarm_list)


def _train(d: dict[str, Any]) -> TrainView:
    return TrainView(**{**d, "sections": tuple(d["sections"]), "cab": CabView(**d["cab"])})

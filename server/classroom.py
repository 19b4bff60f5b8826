"""The classroom: one simulation per trainee seat, their clocks, and who may do what to them.

Everything here is synchronous and knows nothing of the network (:mod:`.websocket` carries messages to and from
it). A seat's clock runs at ``speed`` times the wall clock the server hands to :meth:`Classroom.advance`; the
simulation itself never reads the wall clock.
"""

from __future__ import annotations

import secrets
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from liansuo.interlocking.io import Result
from liansuo.simulation.roles import INSTRUCTOR, refusal
from liansuo.simulation.sim import Simulation
from liansuo.simulation.snapshot import EventCursor, snapshot
from liansuo.stations.library import bundled

MAX_STEPS = 400  # cycles one seat may catch up in one advance: a stalled server does not freeze on its return


@dataclass
class Desk:
    """A simulation and its clock: a seat's own, or one a team of seats shares."""

    sim: Simulation
    paused: bool = False
    speed: float = 1.0
    debt: float = 0.0


@dataclass
class Seat:
    number: int
    desk: Desk
    trainee: str = ""
    token: str = ""  # held by the client that took the seat; a reconnect shows it to take the seat back
    connected: bool = False
    refused: int = 0  # the trainee's refused commands
    log: list[tuple[float, str, str, bool, str]] = field(default_factory=list)  # (t, who, line, ok, answer)

    @property
    def sim(self) -> Simulation:
        return self.desk.sim

    def summary(self) -> dict[str, Any]:
        """What the instructor's dashboard shows of this seat."""
        d = self.desk
        return {"seat": self.number, "station": d.sim.station.id, "trainee": self.trainee,
                "connected": self.connected, "t": d.sim.t, "paused": d.paused, "speed": d.speed,
                "alarms": len(d.sim.alarm_views()), "refused": self.refused,
                "commands": sum(w != INSTRUCTOR for _, w, *_ in self.log)}


class SeatError(ValueError):
    """A request for a seat that cannot be granted; the message says why."""


class Classroom:
    def __init__(self, station: str, seats: int, *, cycle_s: float = 0.25, shared: bool = False) -> None:
        """``seats`` seats of ``station``: each with a simulation of its own, or all at one (``shared``: a team
        exercise, where every seat operates the same station and its clock)."""
        if not 1 <= seats <= 64:
            raise SeatError(f"a classroom has 1 to 64 seats, not {seats}")
        self.station_ref = station
        self.cycle_s = cycle_s
        self.shared = shared
        team = Desk(Simulation(station, cycle_s=cycle_s)) if shared else None
        self.seats = {n: Seat(n, team or Desk(Simulation(station, cycle_s=cycle_s))) for n in range(1, seats + 1)}

    def desks(self, seats: list[int] | None = None) -> list[Desk]:
        """The desks of these seats (of all seats for None), each once."""
        out: list[Desk] = []
        for n in self.seats if seats is None else seats:
            d = self.seat(n).desk
            if all(d is not o for o in out):
                out.append(d)
        return out

    # ---- what a client sees -------------------------------------------------------------------------------------
    def station_source(self) -> dict[str, str]:
        """How a client loads the station to draw it: a bundled name, or the file's text (a station file holds no
        secret: the faults are not in it)."""
        if self.station_ref in bundled():
            return {"name": self.station_ref}
        return {"name": Path(self.station_ref).stem, "text": Path(self.station_ref).read_text(encoding="utf-8")}

    def snapshot(self, seat: int, role: str, cursor: EventCursor) -> dict[str, Any]:
        s = self.seat(seat)
        data = snapshot(s.sim, role, cursor)
        data.update(type="snapshot", seat=seat, paused=s.desk.paused, speed=s.desk.speed)
        return data

    def summaries(self) -> list[dict[str, Any]]:
        return [s.summary() for s in self.seats.values()]

    # ---- seats ----------------------------------------------------------------------------------------------------
    def seat(self, number: int) -> Seat:
        s = self.seats.get(number)
        if s is None:
            raise SeatError(f"there is no seat {number}: this classroom has seats 1 to {len(self.seats)}")
        return s

    def take(self, number: int, trainee: str, token: str | None) -> str:
        """Give seat ``number`` to a client; the token it must show to take the seat back after a disconnect."""
        s = self.seat(number)
        if s.token and token != s.token:
            if s.connected:
                raise SeatError(f"seat {number} is taken by {s.trainee or 'another trainee'}")
            if s.trainee and trainee and trainee != s.trainee:
                raise SeatError(f"seat {number} belongs to {s.trainee}, who may come back to it")
        if not s.token or token != s.token:
            s.token = secrets.token_hex(16)
        s.trainee = trainee or s.trainee
        s.connected = True
        return s.token

    def leave(self, number: int, token: str) -> None:
        s = self.seats.get(number)
        if s is not None and s.token == token:
            s.connected = False

    # ---- commands and the clock ---------------------------------------------------------------------------------
    def command(self, seat: int, role: str, line: str) -> Result:
        """Send one line to a seat's simulation for ``role``: a trainee's instructor command is refused and changes
        nothing; ``run`` is the server's clock, never a client's."""
        s = self.seat(seat)
        no = refusal(role, line)
        if no is None and line.split("#", 1)[0].split()[:1] == ["run"]:
            no = Result.refuse("the classroom's clock runs on the server: pause, run or change its speed instead")
        result = no if no is not None else s.sim.command(line)
        if role != INSTRUCTOR and not result.ok:
            s.refused += 1
        s.log.append((s.sim.t, role, line, result.ok, result.message))
        return result

    def set_clock(self, seats: list[int], *, paused: bool | None = None, speed: float | None = None) -> None:
        if speed is not None and not 0.1 <= speed <= 64:
            raise SeatError(f"a speed is 0.1 to 64 times real time, not {speed:g}")
        for d in self.desks(seats):
            if paused is not None:
                d.paused = paused
            if speed is not None:
                d.speed = speed

    def reset(self, seats: list[int]) -> None:
        """A fresh simulation of the station on each seat's desk; the seat keeps its trainee."""
        for d in self.desks(seats):
            d.sim.close()
            d.sim, d.debt = Simulation(self.station_ref, cycle_s=self.cycle_s), 0.0
        for s in self.seats.values():
            if any(s.desk is d for d in self.desks(seats)):
                s.refused, s.log = 0, []

    def advance(self, wall_s: float) -> None:
        """Run every desk's clock on by ``wall_s`` seconds of the wall clock, at its speed."""
        for d in self.desks():
            if d.paused:
                continue
            d.debt += wall_s * d.speed
            n = min(int(d.debt / d.sim.cycle_s), MAX_STEPS)
            d.debt = min(d.debt - n * d.sim.cycle_s, d.sim.cycle_s)
            for _ in range(n):
                d.sim.step()

    def close(self) -> None:
        for d in self.desks():
            d.sim.close()

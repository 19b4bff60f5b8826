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
class Seat:
    number: int
    sim: Simulation
    trainee: str = ""
    token: str = ""  # held by the client that took the seat; a reconnect shows it to take the seat back
    connected: bool = False
    paused: bool = False
    speed: float = 1.0
    debt: float = 0.0
    refused: int = 0  # the trainee's refused commands
    log: list[tuple[float, str, str, bool, str]] = field(default_factory=list)  # (t, who, line, ok, answer)

    def summary(self) -> dict[str, Any]:
        """What the instructor's dashboard shows of this seat."""
        alarms = self.sim.alarm_views()
        return {"seat": self.number, "station": self.sim.station.id, "trainee": self.trainee,
                "connected": self.connected, "t": self.sim.t, "paused": self.paused, "speed": self.speed,
                "alarms": len(alarms), "refused": self.refused, "commands": sum(w != INSTRUCTOR for _, w, *_ in
                                                                                self.log)}


class SeatError(ValueError):
    """A request for a seat that cannot be granted; the message says why."""


class Classroom:
    def __init__(self, station: str, seats: int, *, cycle_s: float = 0.25) -> None:
        if not 1 <= seats <= 64:
            raise SeatError(f"a classroom has 1 to 64 seats, not {seats}")
        self.station_ref = station
        self.cycle_s = cycle_s
        self.seats = {n: Seat(n, Simulation(station, cycle_s=cycle_s)) for n in range(1, seats + 1)}

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
        data.update(type="snapshot", seat=seat, paused=s.paused, speed=s.speed)
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
        for n in seats:
            s = self.seat(n)
            if paused is not None:
                s.paused = paused
            if speed is not None:
                s.speed = speed

    def reset(self, seats: list[int]) -> None:
        """A fresh simulation of the station on each seat; the seat keeps its trainee."""
        for n in seats:
            s = self.seat(n)
            s.sim.close()
            s.sim = Simulation(self.station_ref, cycle_s=self.cycle_s)
            s.debt, s.refused, s.log = 0.0, 0, []

    def advance(self, wall_s: float) -> None:
        """Run every seat's clock on by ``wall_s`` seconds of the wall clock, at its speed."""
        for s in self.seats.values():
            if s.paused:
                continue
            s.debt += wall_s * s.speed
            n = min(int(s.debt / s.sim.cycle_s), MAX_STEPS)
            s.debt = min(s.debt - n * s.sim.cycle_s, s.sim.cycle_s)
            for _ in range(n):
                s.sim.step()

    def close(self) -> None:
        for s in self.seats.values():
            s.sim.close()

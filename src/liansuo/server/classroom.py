"""The classroom: one simulation per trainee seat, their clocks, and who may do what to them.

Everything here is synchronous and knows nothing of the network (:mod:`.websocket` carries messages to and from
it). A seat's clock runs at ``speed`` times the wall clock the server hands to :meth:`Classroom.advance`; the
simulation itself never reads the wall clock.
"""

from __future__ import annotations

import hmac
import re
import secrets
import sys
import traceback
import unicodedata
from collections import deque
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

from liansuo.classroom.assessment import Assessment, ExerciseSetupError
from liansuo.classroom.exercise import DIFFICULTIES, bundled_exercises, exercises_for, parse_exercise
from liansuo.classroom.report import write_report
from liansuo.classroom.roles import INSTRUCTOR, command_word, is_typo, refusal
from liansuo.classroom.snapshot import EventCursor, snapshot
from liansuo.interlocking.io import Result
from liansuo.kit.source import StationError
from liansuo.simulation.sim import Simulation
from liansuo.stations.library import bundled

MAX_STEPS = 400  # cycles one seat may catch up in one advance: a stalled server does not freeze on its return
MAX_LINE = 500  # characters in one command line: the longest the language needs is under 100
LOG_LINES = 1000  # a seat keeps its newest commands and answers, no more: a trainee's flood takes no memory
NOT_SHOWN = frozenset({"Cc", "Cf", "Cs", "Co", "Cn", "Zl", "Zp"})  # controls, format (bidi), line breaks, unassigned

LogEntry = tuple[float, str, str, bool, str]  # (t, who, line, ok, answer)


@dataclass
class Desk:
    """A simulation and its clock: a seat's own, or one a team of seats shares."""

    sim: Simulation
    paused: bool = False
    speed: float = 1.0
    debt: float = 0.0
    assessment: Assessment | None = None  # the exercise being worked at this desk, scored
    reported: list[Path] = field(default_factory=list)  # the reports written when it ended
    broken: str = ""  # why the desk's clock was stopped by an internal error ('' while it is sound)
    runs: int = 0  # the simulations the desk has had since the first: each starts its clock at 0 again
    run_why: str = ""  # why the newest one started


@dataclass
class Seat:
    number: int
    desk: Desk
    trainee: str = ""
    token: str = ""  # held by the client that took the seat; only it takes the seat back, until the seat is freed
    holders: int = 0  # the connections open with the token (a reconnect may come before the old one is seen gone)
    refused: int = 0  # the trainee's refused commands
    commands: int = 0  # the trainee's commands
    log: deque[LogEntry] = field(default_factory=lambda: deque(maxlen=LOG_LINES))  # the newest LOG_LINES

    @property
    def sim(self) -> Simulation:
        return self.desk.sim

    @property
    def connected(self) -> bool:
        return self.holders > 0

    def summary(self) -> dict[str, Any]:
        """What the instructor's dashboard shows of this seat."""
        d = self.desk
        progress = None if d.assessment is None else d.assessment.progress()
        return {"seat": self.number, "station": d.sim.station.id, "trainee": self.trainee,
                "connected": self.connected, "t": d.sim.t, "paused": d.paused, "speed": d.speed,
                "alarms": len(d.sim.alarm_views()), "refused": self.refused,
                "commands": self.commands,
                "exercise": None if d.assessment is None else d.assessment.exercise.name,
                "progress": progress, "score": None if progress is None else progress["score"],
                "reports": [str(p) for p in d.reported], "broken": d.broken}

    def briefing(self) -> dict[str, Any] | None:
        """What the trainee at this seat is told of the exercise, and how it stands (no fault is named)."""
        a = self.desk.assessment
        if a is None:
            return None
        ex, p = a.exercise, a.progress()
        return {"title": ex.title, "briefing": ex.briefing, "time_left_s": p["time_left_s"],
                "goals": [{"description": g.description, "met": at is not None}
                          for g, at in zip(ex.goals, a.goal_met_at, strict=True)],
                "finished": p["finished"], "ended": p["ended"], "score": p["score"] if p["finished"] else None}


class SeatError(ValueError):
    """A request for a seat that cannot be granted; the message says why."""


class Classroom:
    def __init__(self, station: str, seats: int, *, cycle_s: float = 0.25, shared: bool = False,
                 reports: Path | None = None, exercise_dirs: tuple[Path, ...] = ()) -> None:
        """``seats`` seats of ``station``: each with a simulation of its own, or all at one (``shared``: a team
        exercise, where every seat operates the same station and its clock). Reports of exercises go to
        ``reports`` (``liansuo-reports`` in the working directory by default); exercises are the bundled ones and
        those in ``exercise_dirs``."""
        if not 1 <= seats <= 64:
            raise SeatError(f"a classroom has 1 to 64 seats, not {seats}")
        self.station_ref = station
        self.cycle_s = cycle_s
        self.shared = shared
        self.reports = reports or Path("liansuo-reports")
        self.exercise_dirs = exercise_dirs
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
        data.update(type="snapshot", seat=seat, paused=s.desk.paused, speed=s.desk.speed, exercise=s.briefing(),
                    run={"n": s.desk.runs, "why": s.desk.run_why})
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
        """Give seat ``number`` to a client: a free seat to anyone, a taken one (connected or not) only to the client
        showing its token, never for a name. Returns the token, which takes the seat back after a disconnect."""
        s = self.seat(number)
        name = trainee_name(trainee)
        if s.token:
            if token is None or not hmac.compare_digest(token.encode(), s.token.encode()):
                if s.connected:
                    raise SeatError(f"seat {number} is taken: choose a free seat")
                raise SeatError(f"seat {number} is held for its trainee, who takes it back with the seat's token: "
                                "choose a free seat, or ask the instructor to free this one")
        else:
            s.token, s.trainee = secrets.token_hex(16), name
        s.holders += 1
        return s.token

    def leave(self, number: int, token: str) -> None:
        """A connection that held seat ``number`` with ``token`` closed (the seat stays its trainee's)."""
        s = self.seats.get(number)
        if s is not None and s.token and s.token == token:
            s.holders = max(0, s.holders - 1)

    def holds(self, number: int, token: str) -> bool:
        """Whether ``token`` still holds seat ``number`` (the instructor may have freed it)."""
        s = self.seats.get(number)
        return s is not None and bool(s.token) and hmac.compare_digest(token.encode(), s.token.encode())

    def free(self, seats: list[int]) -> None:
        """The instructor frees these seats: token and trainee cleared, so that a new trainee may sit (their station
        and exercise stay as they are: reset them for a fresh one). Whoever held them holds them no more."""
        for n in seats:
            self.seat(n)
        for n in seats:
            s = self.seats[n]
            s.token, s.trainee, s.holders = "", "", 0

    # ---- commands and the clock ---------------------------------------------------------------------------------
    def command(self, seat: int, role: str, line: str) -> Result:
        """Send one line to a seat's simulation for ``role``: a trainee's instructor command is refused and changes
        nothing; ``run`` is the server's clock, never a client's."""
        s = self.seat(seat)
        if len(line) > MAX_LINE:
            no: Result | None = Result.refuse(f"a command line is at most {MAX_LINE} characters, not {len(line)}: "
                                              "send one command a line")
            line = line[:60] + "…"
        else:
            no = refusal(role, line)
        if no is None and command_word(line) == "run":  # as the language reads it: 'run' 60s is run too
            no = Result.refuse("the classroom's clock runs on the server: pause, run or change its speed instead")
        result = no if no is not None else s.sim.command(line)
        if role != INSTRUCTOR:
            s.commands += 1
            s.refused += not result.ok and not is_typo(line)  # a typo is not a refused command
        a = s.desk.assessment
        if role != INSTRUCTOR and a is not None and not a.finished:
            a.record(line, result)
            self._report_if_ended(s.desk)
        s.log.append((s.sim.t, role, line, result.ok, result.message[:MAX_LINE]))
        return result

    def set_clock(self, seats: list[int], *, paused: bool | None = None, speed: float | None = None) -> None:
        if speed is not None and not 0.1 <= speed <= 64:
            raise SeatError(f"a speed is 0.1 to 64 times real time, not {speed:g}")
        broken = [n for n in seats if self.seat(n).desk.broken and paused is False]
        if broken:
            raise SeatError(f"seat {broken[0]} was {self.seat(broken[0]).desk.broken}: reset it to run it again")
        for d in self.desks(seats):
            if paused is not None:
                d.paused = paused
            if speed is not None:
                d.speed = speed

    def reset(self, seats: list[int]) -> None:
        """A fresh simulation of the station on each seat's desk, without exercise; the seat keeps its trainee."""
        for d in self.desks(seats):
            self._fresh(d, Simulation(self.station_ref, cycle_s=self.cycle_s), "reset by the instructor")

    def _fresh(self, d: Desk, sim: Simulation, why: str) -> None:
        d.sim.close()
        d.sim, d.debt, d.assessment, d.reported, d.broken = sim, 0.0, None, [], ""
        d.runs, d.run_why = d.runs + 1, why
        for s in self.seats.values():
            if s.desk is d:
                s.refused, s.commands = 0, 0
                s.log.clear()

    # ---- exercises --------------------------------------------------------------------------------------------
    def exercise_names(self) -> list[str]:
        return sorted({p.stem for p in self.exercise_files()})

    def exercise_files(self) -> list[Path]:
        return [*bundled_exercises(), *(p for d in self.exercise_dirs for p in sorted(d.glob("*.yaml")))]

    def station_exercises(self) -> list[str]:
        """The names of the exercises for this classroom's station (those the instructor may start here); a name in
        an ``--exercise-dir`` stands for the bundled exercise of that name."""
        files = {p.stem: p for p in self.exercise_files()}
        here = self.seat(min(self.seats)).sim.station.id
        return sorted(p.stem for p in exercises_for(here, files.values()))

    def start_exercise(self, seats: list[int], name: str, *, difficulty: int | None = None,
                       seed: int | None = None) -> str:
        """Start exercise ``name`` afresh on these seats' desks: a new simulation, its setup and faults, and the
        scoring. With ``seed`` every desk draws the same faults (a fair comparison); without, each its own."""
        path = next((p for p in reversed(self.exercise_files()) if p.stem == name), None)
        if path is None:
            raise SeatError(f"no exercise '{name}' on this server; there are: {', '.join(self.exercise_names())}")
        try:
            ex = parse_exercise(path)
        except StationError as exc:
            raise SeatError(f"exercise '{name}' cannot be read: {exc.diagnostics[0] if exc.diagnostics else exc}"
                            ) from None
        if difficulty is not None and difficulty not in DIFFICULTIES:
            raise SeatError(f"difficulty is 1 (easy), 2 (medium) or 3 (hard), not {difficulty}")
        here = self.seat(min(self.seats)).sim.station.id
        sims: list[Simulation] = []
        made: list[tuple[Desk, Assessment]] = []
        try:  # every desk's new simulation is made before any desk changes: a refusal changes nothing
            for d in self.desks(seats):
                sim = Simulation(ex.station_ref(), cycle_s=self.cycle_s)
                sims.append(sim)
                if sim.station.id != here:
                    raise SeatError(f"exercise '{name}' is for station {sim.station.id}; this classroom serves "
                                    f"{here}: start 'liansuo serve {ex.station}' for it")
                who = [s for s in self.seats.values() if s.desk is d]
                made.append((d, Assessment(ex, sim, seed=secrets.randbelow(10**6) if seed is None else seed,
                                           trainee=", ".join(s.trainee for s in who if s.trainee),
                                           seat=", ".join(str(s.number) for s in who), difficulty=difficulty)))
        except (SeatError, ExerciseSetupError, StationError) as exc:
            for sim in sims:
                sim.close()
            raise SeatError(str(exc)) from None
        for d, a in made:
            self._fresh(d, a.sim, f"exercise '{ex.title}' started")
            d.assessment = a
        started = sorted(s.number for s in self.seats.values() if any(s.desk is d for d, _ in made))
        return f"exercise '{ex.title}' started on seats {', '.join(map(str, started))}"

    def stop_exercise(self, seats: list[int]) -> list[Path]:
        """End the exercise on these seats' desks now (the trainee is told), and write its reports (those already
        written stay)."""
        out: list[Path] = []
        for d in self.desks(seats):
            if d.assessment is not None:
                d.assessment.stop()
                if not d.reported:
                    d.reported = self._write(d)
                out += d.reported
        return out

    def stop_unfinished(self, why: str) -> list[Path]:
        """End every exercise still going, its report saying ``why``, and write those reports (the server stops:
        the attempts so far are kept). The paths written."""
        out: list[Path] = []
        for d in self.desks():
            if d.assessment is not None and not d.assessment.finished:
                d.assessment.stop(why)
                d.reported = self._write(d)
                out += d.reported
        return out

    def _report_if_ended(self, d: Desk) -> None:
        if d.assessment is not None and d.assessment.finished and not d.reported:
            d.reported = self._write(d)

    def _write(self, d: Desk) -> list[Path]:
        """One report per trainee at the desk (a team's desk: the team's attempt, under each name)."""
        assert d.assessment is not None
        report = d.assessment.report()
        out: list[Path] = []
        for s in self.seats.values():
            if s.desk is d:
                stem = _unused(self.reports, f"seat{s.number}-{_slug(s.trainee) or 'anonymous'}-"
                                             f"{d.assessment.exercise.name}")
                out += write_report({**report, "trainee": s.trainee, "seat": str(s.number)}, self.reports, stem)
        return out

    def advance(self, wall_s: float) -> None:
        """Run every desk's clock on by ``wall_s`` seconds of the wall clock, at its speed. A desk whose simulation
        fails is stopped (paused, with the reason in its summary; the traceback on stderr), never the others."""
        for d in self.desks():
            if d.paused:
                continue
            try:
                self._run(d, wall_s)
            except Exception:  # the other seats' classes go on
                d.paused, d.broken = True, "stopped by an internal error of its simulation (in the server's log)"
                traceback.print_exc(file=sys.stderr)

    def _run(self, d: Desk, wall_s: float) -> None:
        d.debt += wall_s * d.speed
        n = min(int(d.debt / d.sim.cycle_s), MAX_STEPS)
        d.debt = min(d.debt - n * d.sim.cycle_s, d.sim.cycle_s)
        for _ in range(n):
            d.sim.step()
        if d.assessment is not None and not d.assessment.finished:
            d.assessment.tick()
            self._report_if_ended(d)

    def close(self) -> None:
        for d in self.desks():
            d.sim.close()


def trainee_name(name: str) -> str:
    """A trainee's name as given, trimmed; refused if it holds a character that is not shown as itself (a control
    character such as ESC, a bidirectional override, a line break): names reach the instructor's screen and reports."""
    bad = next((c for c in name if unicodedata.category(c) in NOT_SHOWN), None)
    if bad is not None:
        raise SeatError(f"a trainee's name is letters, digits, spaces and punctuation, not U+{ord(bad):04X}: "
                        "give your name as you would write it")
    return name.strip()


def _slug(name: str) -> str:
    """A trainee's name as part of a file name: letters (any script) and digits, joined by '-'."""
    return "-".join(re.findall(r"\w+", name))[:40]


def _unused(folder: Path, stem: str) -> str:
    """``stem``, or ``stem-2``, ``stem-3``...: the first no report of the folder has (a second attempt keeps the
    first's report)."""
    n, out = 1, stem
    while (folder / f"{out}.json").exists():
        n += 1
        out = f"{stem}-{n}"
    return out

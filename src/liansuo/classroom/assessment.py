"""An assessment: one trainee working one exercise on one simulation, scored (docs/exercises.md).

The classroom server makes one per seat; ``liansuo exercise run`` makes one for a file of timed answers::

    a = Assessment(exercise, sim, seed=7, trainee="Li Lei", seat="3")  # sends the setup and the faults
    result = sim.command(line)            # each trainee command, as the seat sends it ...
    a.record(line, result)                # ... and its answer (refused ones count)
    sim.step(); a.tick()                  # after the clock moved: goals checked (once a simulated second)
    a.progress()                          # for the instructor's dashboard
    write_report(a.report(), folder, "li-lei")   # .json, .txt and .html (classroom/report.py)

What is judged unsafe is in :mod:`.unsafe`, the score in :mod:`.score`.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

from liansuo.classroom.exercise import DIFFICULTIES, Exercise, check_goal
from liansuo.classroom.roles import command_word, is_typo
from liansuo.classroom.score import ScoreInputs, goal_worth, score
from liansuo.classroom.unsafe import (
    RED_BAND,
    Planted,
    fault_release_cause,
    guide_cause,
    hidden_vehicle,
    planted,
    turnout_sections,
)
from liansuo.interlocking.io import Result
from liansuo.simulation.sim import Simulation
from liansuo.simulation.unknown import UnknownId
from liansuo.simulation.view import RouteView

CHECK_EVERY_S = 1.0  # goals are checked once a simulated second (and after each command)
KEPT = 1000  # commands, unsafe actions and diagnoses kept for the report, the first of each (the score is 0 by then)


class ExerciseSetupError(Exception):
    """The simulation refused one of the exercise's own lines (setup or a fault): the exercise is wrong."""


@dataclass(frozen=True)
class Entry:
    t: float
    line: str
    ok: bool
    answer: str


@dataclass(frozen=True)
class UnsafeAction:
    t: float
    line: str
    rule: str
    why: str


@dataclass(frozen=True)
class ExpectedFinding:
    finding: str
    fault: str
    accept: tuple[str, ...]


@dataclass(frozen=True)
class Diagnosis:
    t: float
    line: str
    correct: bool
    finding: str


def _words(line: str) -> list[str]:
    return line.split("#", 1)[0].split()


class Assessment:
    """One trainee's attempt at ``exercise`` on ``sim``: built, it sends the setup, the fixed faults and the faults
    drawn from the pool for ``seed`` (at ``difficulty``, the exercise's own by default) as the instructor."""

    def __init__(self, exercise: Exercise, sim: Simulation, *, seed: int, trainee: str = "", seat: str = "",
                 difficulty: int | None = None) -> None:
        self.exercise = exercise
        self.sim = sim
        self.seed = seed
        self.trainee = trainee
        self.seat = seat
        self.difficulty = difficulty or exercise.difficulty
        if self.difficulty not in DIFFICULTIES:
            raise ValueError(f"difficulty {self.difficulty}: give 1 (easy), 2 (medium) or 3 (hard)")
        self.drawn = exercise.drawn_faults(seed, self.difficulty)
        self.seen_occupied: set[str] = set()
        sent = [*exercise.setup, *exercise.fixed_faults, *self.drawn]
        for line in sent:
            result = sim.command(line)
            if not result.ok:
                raise ExerciseSetupError(f"{exercise.file}: '{line}' was refused: {result.message}")
            self._observe()
        self.planted: Planted = planted(sim.station, sent)
        self.findings = self._findings()
        self.start = sim.t
        self.sealed_before = sim.sealed_uses()
        self.entries: list[Entry] = []  # the first KEPT commands
        self.commands = 0  # every command recorded, kept or not
        self.refused = 0
        self.unsafe: list[UnsafeAction] = []
        self.diagnoses: list[Diagnosis] = []
        self.diagnosed_at: list[float | None] = [None] * len(self.findings)
        self.goal_met_at: list[float | None] = [None] * len(exercise.goals)
        self._met: set[int] = set()
        self._checked_at = -CHECK_EVERY_S
        self.ended = ""  # why it finished: 'goals met' or 'time limit'; '' while it goes on
        self.finished_at: float | None = None
        self._check()

    # ---- what there is to find ------------------------------------------------------------------------------
    def _findings(self) -> list[ExpectedFinding]:
        injected = [f"{f.kind} {f.target}" for f in self.planted.faults]
        out = [ExpectedFinding(s.finding or (f"fault {s.fault}" if s.fault else ""), s.fault, s.accept)
               for s in self.exercise.diagnosis if not s.fault or s.fault in injected]
        covered = {s.fault for s in self.exercise.diagnosis}
        for f in self.planted.faults:
            key = f"{f.kind} {f.target}"
            if key in covered:
                continue
            covered.add(key)
            red = f.kind in RED_BAND or (f.kind == "capacitor" and f.get("mode") == "short")
            out.append(ExpectedFinding(f"fault {key}", key, (key, f"red-band {f.target}") if red else (key,)))
        return out

    # ---- time -----------------------------------------------------------------------------------------------
    @property
    def elapsed(self) -> float:
        end = self.sim.t if self.finished_at is None else self.finished_at
        return round(end - self.start, 3)

    @property
    def finished(self) -> bool:
        return bool(self.ended)

    def _observe(self) -> None:
        """Sections the interlocking sees occupied, remembered (rule 2: left locked after a train's passage)."""
        for s in self.sim.station.sections:
            if self.sim.view.section(s).occupied:
                self.seen_occupied.add(s)

    def tick(self) -> None:
        """Call after the clock moved: the goals are checked (at most once a simulated second) and the time limit
        ends the exercise."""
        if self.finished:
            return
        self._observe()
        if self.sim.t - self._checked_at >= CHECK_EVERY_S:
            self._check()
        if not self.finished and self.sim.t - self.start >= self.exercise.time_limit:
            self._end("time limit", self.start + self.exercise.time_limit)

    def _check(self) -> None:
        self._checked_at = self.sim.t
        check = check_goal(self.sim, self.exercise, self._met)
        for i, met in enumerate(check.met):
            if met and self.goal_met_at[i] is None:
                self.goal_met_at[i] = round(self.sim.t - self.start, 3)
        self._maybe_done()

    def _maybe_done(self) -> None:
        if (self.goal_met_at and all(t is not None for t in self.goal_met_at)
                and all(t is not None for t in self.diagnosed_at)):
            self._end("goals met", self.sim.t)

    def stop(self, why: str = "stopped by the instructor") -> None:
        """End the attempt now (nothing more is recorded or scored); its report says ``why``."""
        if not self.finished:
            self._end(why, self.sim.t)

    def _end(self, why: str, at: float) -> None:
        self.ended = why
        self.finished_at = at

    # ---- the trainee's commands -------------------------------------------------------------------------------
    def record(self, line: str, result: Result) -> None:
        """One trainee command and its answer, just after it was sent (refused ones count). Once the exercise has
        ended (every goal met and every finding diagnosed, or the time limit) nothing more is recorded."""
        if self.finished or not line.split("#", 1)[0].strip():
            return
        t = round(self.sim.t - self.start, 3)
        self._observe()
        self.commands += 1
        self.refused += not result.ok and not is_typo(line)  # a typo costs nothing
        if len(self.entries) < KEPT:
            self.entries.append(Entry(t, line.strip(), result.ok, result.message))
        if result.ok:
            why = self._unsafe(line)
            if why and len(self.unsafe) < KEPT:
                self.unsafe.append(UnsafeAction(t, line.strip(), *why))
            if command_word(line) == "diagnose":
                self._diagnose(t, " ".join(_words(line)[1:]))
        self._check()

    def _unsafe(self, line: str) -> tuple[str, str] | None:
        word, args = command_word(line), _words(line)[1:]
        st, plant = self.sim.station, self.planted
        if word == "guide" and args:
            route = self._route_of(args[0])
            if not guide_cause(st, plant, args[0], None if route is None else route.sections):
                return ("guide without cause", f"nothing stops {args[0]}'s normal opening: no fault, red band or dark "
                        "lamp between it and the next signals; set the route and open the signal")
        elif word == "fault-release" and args:
            hidden = hidden_vehicle(st, plant, [args[0]])
            if hidden:
                return ("over a hidden vehicle", f"{args[0]} released with a vehicle in it: {hidden}")
            if not fault_release_cause(st, plant, args[0], self.seen_occupied):
                return ("section fault release without cause", f"no fault touches {args[0]} and no train left it "
                        "locked: the route holding it was still needed")
        elif word in ("route", "shunt") and args:
            route = self._route_of(args[0])
            hidden = hidden_vehicle(st, plant, route.sections if route is not None else [])
            if hidden:
                return ("over a hidden vehicle", f"route {route.id if route else ''} set over it: {hidden}")
        elif word == "throw" and args and (args[0] in st.turnouts or args[0] in st.pairs):
            hidden = hidden_vehicle(st, plant, sorted(turnout_sections(st, args[0])))
            if hidden:
                return ("over a hidden vehicle", f"turnout {args[0]} thrown: {hidden}")
        return None

    def _route_of(self, signal: str) -> RouteView | None:
        """The route the interlocking holds from ``signal`` (its sections, as locked), if any."""
        try:
            return self.sim.view.route_of(signal)
        except UnknownId:
            return None

    def _diagnose(self, t: float, said: str) -> None:
        for i, f in enumerate(self.findings):
            if said in f.accept:
                if self.diagnosed_at[i] is None:
                    self.diagnosed_at[i] = t
                if len(self.diagnoses) < KEPT:
                    self.diagnoses.append(Diagnosis(t, said, True, f.finding))
                return
        if len(self.diagnoses) < KEPT:
            self.diagnoses.append(Diagnosis(t, said, False, ""))

    # ---- results ----------------------------------------------------------------------------------------------
    def _inputs(self) -> ScoreInputs:
        goals = tuple((g.points, at) for g, at in zip(self.exercise.goals, self.goal_met_at, strict=True))
        wrong = sum(not d.correct for d in self.diagnoses)
        return ScoreInputs(goals, tuple(self.diagnosed_at), self.refused, len(self.unsafe), wrong,
                           self.exercise.time_limit)

    def _score(self) -> dict[str, float]:
        return score(self.exercise.scoring, self._inputs())

    def sealed_uses(self) -> dict[str, int]:
        """The sealed buttons the trainee used (铅封计数 since the exercise began; the setup's are not counted)."""
        now = self.sim.sealed_uses()
        return {k: n - self.sealed_before.get(k, 0) for k, n in now.items() if n > self.sealed_before.get(k, 0)}

    def progress(self) -> dict[str, Any]:
        """The state of play, for the instructor's dashboard."""
        met = sum(t is not None for t in self.goal_met_at)
        return {"elapsed_s": self.elapsed, "time_left_s": round(max(0.0, self.exercise.time_limit - self.elapsed), 3),
                "goals_met": met, "goals": len(self.goal_met_at),
                "diagnosed": sum(t is not None for t in self.diagnosed_at), "findings": len(self.findings),
                "refused": self.refused, "unsafe": len(self.unsafe),
                "score": self._score()["total"], "finished": self.finished, "ended": self.ended}

    def report(self) -> dict[str, Any]:
        """Everything about the attempt, JSON-able (docs/exercises.md, "Report")."""
        ex = self.exercise
        return {
            "trainee": self.trainee, "seat": self.seat,
            "exercise": {"name": ex.name, "title": ex.title, "file": ex.file},
            "station": self.sim.station.id, "difficulty": self.difficulty, "seed": self.seed,
            "faults": {"setup": [line for line in ex.setup if command_word(line) == "fault"],
                       "fixed": list(ex.fixed_faults), "drawn": list(self.drawn), "pool": len(ex.pool)},
            "time_limit_s": ex.time_limit, "elapsed_s": self.elapsed, "finished": self.finished,
            "ended": self.ended or "stopped before the end",
            "commands": [{"t": e.t, "command": e.line, "ok": e.ok, "answer": e.answer} for e in self.entries],
            "commands_not_kept": self.commands - len(self.entries),
            "refused": self.refused,
            "unsafe": [{"t": u.t, "command": u.line, "rule": u.rule, "why": u.why} for u in self.unsafe],
            "findings": [{"finding": f.finding, "fault": f.fault, "accept": list(f.accept), "diagnosed_at": at}
                         for f, at in zip(self.findings, self.diagnosed_at, strict=True)],
            "diagnoses": [{"t": d.t, "diagnosis": d.line, "correct": d.correct, "finding": d.finding}
                          for d in self.diagnoses],
            # points: the goal's weight among the goals (the exercise's); worth: its share of the score's goals part
            "goals": [{"description": g.description, "expect": list(g.expect), "points": g.points, "worth": worth,
                       "met_at": at}
                      for g, at, worth in zip(ex.goals, self.goal_met_at, goal_worth(ex.scoring, self._inputs()),
                                              strict=True)],
            "all_goals_met": bool(self.goal_met_at) and all(t is not None for t in self.goal_met_at),
            "sealed_uses": self.sealed_uses(),
            "score": self._score(),
        }

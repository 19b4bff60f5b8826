"""The exercise file (:mod:`.exercise`, docs/exercises.md) as a pydantic model: what the loader validates with and
``liansuo schema exercise`` writes as a JSON Schema. It accepts exactly what the loader accepts; that every setup,
fault and diagnosis line names a command of the language is checked by the loader after it.

Every key added for assessment (``briefing``, ``difficulty``, ``faults``, ``goals``, ``diagnosis``, ``time_limit``,
``scoring``) is optional, so an exercise written for the console alone (``description``, ``setup``, ``goal``) stays
valid.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, field_validator, model_validator

from liansuo.simulation.timeparse import parse_duration

Command = Annotated[str, Field(description="one command of the command language (docs/commands.md)")]
FaultLine = Annotated[str, Field(description="a fault command sent as the instructor: 'fault broken-rail IG', "
                                             "'fault filament X lamp=U', or any other command (occupy, axles ...)")]
ExpectLine = Annotated[str, Field(description="an expect line, the word 'expect' may be left out: "
                                              "'section IG occupied', 'signal X UU'")]
DiagnosisLine = Annotated[str, Field(description="what the trainee registers: 'KIND ELEMENT' as in 'diagnose KIND "
                                                 "ELEMENT', e.g. 'broken-rail IG', 'filament X'")]
DURATION_PATTERN = r"^\s*\d+(\.\d+)?\s*(ms|sec|s|min|m|h)?\s*$"
LONGEST_S = 4 * 3600.0  # an exercise longer than a lesson is a mistake


def seconds_of(value: object, what: str) -> float:
    """A duration as text (``10min``) or plain seconds, in seconds; ValueError with what to write."""
    if isinstance(value, bool) or not isinstance(value, str | int | float):
        raise ValueError("write a duration: 30s, 3min, 1h or plain seconds")
    seconds = parse_duration(str(value))
    if not 0 < seconds <= LONGEST_S:
        raise ValueError(f"{what} must be more than 0 and at most 4h, not '{value}'")
    return seconds


DURATION_INPUT = Annotated[str, Field(pattern=DURATION_PATTERN)] | Annotated[float, Field(gt=0, le=LONGEST_S)]


class _File(BaseModel):
    """Strict: no key but those listed, no value of another type taken for the one asked."""

    model_config = ConfigDict(extra="forbid", strict=True)


class Goal(_File):
    """What counts as done: every expect line holds at once."""

    description: Any = Field("", description="what counts as done, as the trainee reads it (text)")
    expect: list[ExpectLine] = Field([], description="expect lines checked together; they change nothing")
    points: float = Field(10, gt=0, le=100, description="this goal's weight among the goals (default 10); the goals "
                                                         "together are worth scoring.goals")


class FaultDraw(_File):
    """How many faults are drawn from the pool at each difficulty."""

    easy: int = Field(1, ge=0, le=20, description="faults drawn at difficulty 1")
    medium: int = Field(1, ge=0, le=20, description="faults drawn at difficulty 2")
    hard: int = Field(2, ge=0, le=20, description="faults drawn at difficulty 3")


class Faults(_File):
    """The faults of an exercise: always injected, and drawn at random from a pool."""

    fixed: list[FaultLine] = Field([], description="fault lines always injected, after the setup")
    pool: list[FaultLine] = Field([], description="fault lines to draw from (reproducibly, from the seed)")
    draw: int | FaultDraw = Field(1, description="how many to draw from the pool: a number, or one per difficulty "
                                            "({easy: 1, medium: 1, hard: 2})")

    @field_validator("draw")
    @classmethod
    def _count(cls, value: int | FaultDraw) -> int | FaultDraw:
        if isinstance(value, int) and not 0 <= value <= 20:
            raise ValueError("draw from 0 to 20 faults")
        return value


class FindingEntry(_File):
    """One thing the trainee must find and register with 'diagnose KIND ELEMENT'."""

    fault: str = Field("", description="the injected fault this finding is about, 'KIND TARGET' (e.g. 'broken-rail "
                                       "IG'); the finding counts only when that fault was injected (drawn). Empty: "
                                       "always counts (e.g. a vehicle hidden in a dead zone placed by the setup)")
    finding: Any = Field("", description="what there is to find, for the report (text)")
    accept: list[DiagnosisLine] = Field(min_length=1, description="the diagnoses that count as correct")


class Scoring(_File):
    """Points of the score (100 at most; docs/exercises.md gives the formula)."""

    goals: float = Field(60, ge=0, le=100, description="what all goals met are worth")
    diagnosis: float = Field(30, ge=0, le=100, description="what every finding diagnosed in time is worth (given to "
                                                           "the goals when there is nothing to find)")
    time: float = Field(10, ge=0, le=100, description="for meeting every goal by 'par'; falls to 0 at the time limit")
    par: float | None = Field(None, description="meeting every goal by then earns all the time points (default: "
                                                "half the time limit)")
    diagnose_within: float = Field(120, description="a finding diagnosed by then earns its full share; later it "
                                                    "falls to half at the time limit")
    refused: float = Field(2, ge=0, le=100, description="points lost per refused command")
    unsafe: float = Field(15, ge=0, le=100, description="points lost per unsafe action")
    wrong_diagnosis: float = Field(5, ge=0, le=100, description="points lost per wrong diagnosis")

    @field_validator("par", "diagnose_within", mode="before", json_schema_input_type=DURATION_INPUT)
    @classmethod
    def _duration(cls, value: object) -> float | None:
        return None if value is None else seconds_of(value, "a duration")

    @model_validator(mode="after")
    def _hundred(self) -> Scoring:
        if self.goals + self.diagnosis + self.time > 100:
            raise ValueError("goals, diagnosis and time together are worth at most 100 points")
        return self


class ExerciseFile(_File):
    """A lesson an instructor loads into the operator console (liansuo tui --exercise NAME|FILE), or an assessment
    (liansuo exercise run, the classroom server)."""

    model_config = ConfigDict(title="liansuo exercise")

    title: str = Field(min_length=1, description="the lesson's title, shown in the instructor panel")
    station: str = Field(min_length=1, description="a bundled station name or the path of a station file, relative "
                                                   "to this file")
    briefing: Any = Field("", description="what the trainee is told (text)")
    description: Any = Field("", description="the old name of 'briefing'")
    difficulty: int = Field(1, ge=1, le=3, description="1 easy, 2 medium, 3 hard: how many pool faults are drawn")
    time_limit: float = Field(600, description="the time the trainee has, in simulated time: 10min, 600s (default "
                                               "10min)")
    setup: list[Command] = Field([], description="commands sent when the exercise is loaded: faults, occupancy, "
                                                 "trains, time")
    faults: Faults = Field(Faults(), description="faults injected after the setup: fixed ones and a draw from a pool")
    goal: Goal | None = Field(None, description="what counts as done (one goal); empty for a lesson with no goal")
    goals: list[Goal] = Field([], description="what counts as done, goal by goal; each is met once its expect lines "
                                              "all hold")
    diagnosis: list[FindingEntry] = Field([], description="what the trainee must find; every injected fault without a "
                                                     "finding here is found by 'diagnose KIND TARGET'")
    scoring: Scoring = Field(Scoring(), description="the points of the score")

    @field_validator("goal", mode="before")
    @classmethod
    def _no_goal(cls, value: object) -> object:
        """An empty goal (null, '', {}) is no goal."""
        return value or None

    @field_validator("time_limit", mode="before", json_schema_input_type=DURATION_INPUT)
    @classmethod
    def _limit(cls, value: object) -> float:
        return seconds_of(value, "time_limit")

    @model_validator(mode="after")
    def _one_goal_key(self) -> ExerciseFile:
        if self.goal is not None and self.goals:
            raise ValueError("give either 'goal' (one) or 'goals' (a list), not both")
        if self.briefing and self.description:
            raise ValueError("give either 'briefing' or its old name 'description', not both")
        return self

"""The exercise file (:mod:`.exercise`, docs/console.md "Exercises") as a pydantic model: what the loader validates
with and ``liansuo schema exercise`` writes as a JSON Schema. It accepts exactly what the loader accepts; that every
setup line names a command of the language is checked by the loader after it."""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, field_validator

Command = Annotated[str, Field(description="one command of the command language (docs/commands.md)")]
ExpectLine = Annotated[str, Field(description="an expect line, the word 'expect' may be left out: "
                                              "'section IG occupied', 'signal X UU'")]


class _File(BaseModel):
    """Strict: no key but those listed, no value of another type taken for the one asked."""

    model_config = ConfigDict(extra="forbid", strict=True)


class Goal(_File):
    """What counts as done: every expect line holds at once."""

    description: Any = Field("", description="what counts as done, as the trainee reads it (text)")
    expect: list[ExpectLine] = Field([], description="expect lines checked together; they change nothing")


class ExerciseFile(_File):
    """A lesson an instructor loads into the operator console (liansuo tui --exercise NAME|FILE)."""

    model_config = ConfigDict(title="liansuo exercise")

    title: str = Field(min_length=1, description="the lesson's title, shown in the instructor panel")
    station: str = Field(min_length=1, description="a bundled station name or the path of a station file, relative "
                                                   "to this file")
    description: Any = Field("", description="what the trainee is told (text)")
    setup: list[Command] = Field([], description="commands sent when the exercise is loaded: faults, occupancy, "
                                                 "trains, time")
    goal: Goal | None = Field(None, description="what counts as done; empty for a lesson with no goal")

    @field_validator("goal", mode="before")
    @classmethod
    def _no_goal(cls, value: object) -> object:
        """An empty goal (null, '', {}) is no goal."""
        return value or None

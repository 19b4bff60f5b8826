"""The file formats of proving as pydantic models: route-test scripts (``liansuo test``, :mod:`.scripts`) and
scenarios (``liansuo run``, :mod:`.scenario`).

Each model accepts exactly what its loader accepts and is what the loader validates with; ``liansuo schema script``
and ``liansuo schema scenario`` write them as JSON Schemas for editors. What a schema cannot say is checked by the
loader after it: that every step names a command of the language.
"""

from __future__ import annotations

from typing import Annotated, Any

from pydantic import BaseModel, ConfigDict, Field, field_validator

from liansuo.simulation.timeparse import parse_duration
from liansuo.stations import limits

Step = Annotated[str, Field(description="one command of the command language (docs/commands.md), e.g. 'route X XI', "
                                        "'run 2s', 'expect signal X U'")]
STATION = "a bundled station name (liansuo stations) or the path of a station file, relative to this file"
DURATION_PATTERN = r"^\s*\d+(\.\d+)?\s*(ms|sec|s|min|m|h)?\s*$"


class _File(BaseModel):
    """Strict: no key but those listed, no value of another type taken for the one asked (no "1" for 1)."""

    model_config = ConfigDict(extra="forbid", strict=True)


class ScriptTestModel(_File):
    """One test of a script, run on a fresh simulation."""

    name: str = Field(description="what the test shows; liansuo test -k TEXT selects by it")
    steps: list[Step] = Field(description="commands run in order; a refused command fails the test unless the next "
                                          "step is 'expect refused ...'")


class ScriptFile(_File):
    """A route-test script: ``liansuo test FILE``, or collected by pytest (docs/commands.md, "Test scripts")."""

    model_config = ConfigDict(title="liansuo test script")

    station: str = Field(description=STATION)
    tests: list[ScriptTestModel] = Field(min_length=1, description="the tests, each run on a fresh simulation")
    cycle_ms: float = Field(250, ge=10, le=2000, description="the interlocking's cycle in milliseconds")
    safety: bool = Field(False, description="run the independent safety oracle every cycle (docs/safety.md)")


class ScenarioFile(_File):
    """A scenario: ``liansuo run FILE`` runs it headless and prints the event log (docs/trains.md, "Scenarios")."""

    model_config = ConfigDict(title="liansuo scenario")

    station: str = Field(description=STATION)
    description: Any = Field("", description="what the scenario shows (text)")
    steps: list[Step] = Field(min_length=1, description="commands run in order; a refused one stops the run")
    until: float | None = Field(None, description="keep running to this simulated time after the last step: "
                                                  "30s, 3min, 250ms, 1h or plain seconds")

    @field_validator("until", mode="before", json_schema_input_type=Annotated[str, Field(pattern=DURATION_PATTERN)]
                     | Annotated[float, Field(ge=0, le=limits.SCENARIO.high)])
    @classmethod
    def _duration(cls, value: object) -> float:
        """A duration as text or plain seconds, in seconds."""
        if isinstance(value, bool) or not isinstance(value, str | int | float):
            raise ValueError("write a duration: 30s, 3min, 250ms, 1h or plain seconds")
        seconds = parse_duration(str(value))
        why = limits.SCENARIO.problem("until", seconds, str(value))
        if why:
            raise ValueError(why)
        return seconds

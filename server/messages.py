"""The messages a client sends the classroom server, as pydantic models: anything else is answered with an error
message and changes nothing (docs/classroom.md, "The protocol")."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, TypeAdapter

Seats = Literal["all"] | list[Annotated[int, Field(ge=1, le=64)]]


class _Message(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)


class Hello(_Message):
    type: Literal["hello"]
    role: Literal["trainee", "instructor"]
    seat: int | None = Field(None, ge=1, le=64, description="the trainee's seat")
    name: str = Field("", max_length=64, description="the trainee's name, for the report")
    token: str | None = Field(None, max_length=64, description="the seat's token, to take it back after a disconnect")
    password: str | None = Field(None, max_length=256, description="the instructor's password")


class Command(_Message):
    type: Literal["command"]
    id: int = Field(ge=0, le=2**53)
    line: str = Field(max_length=2000)
    seat: int | None = Field(None, ge=1, le=64, description="the instructor's target seat; a trainee's is its own")


class Watch(_Message):
    type: Literal["watch"]
    seat: int = Field(ge=1, le=64)


class Clock(_Message):
    type: Literal["clock"]
    seats: Seats
    action: Literal["pause", "run"] | None = None
    speed: float | None = Field(None, allow_inf_nan=False)


class Reset(_Message):
    type: Literal["reset"]
    seats: Seats


Message = Annotated[Hello | Command | Watch | Clock | Reset, Field(discriminator="type")]
MESSAGE: TypeAdapter[Hello | Command | Watch | Clock | Reset] = TypeAdapter(Message)


def problem(exc: Exception) -> str:
    """A validation error in one line: where, and what is wrong."""
    errors = getattr(exc, "errors", None)
    if callable(errors):
        first = errors()[0]
        where = ".".join(str(x) for x in first.get("loc", ())) or "message"
        return f"{where}: {first.get('msg', 'invalid')}"
    return str(exc)

"""The messages a client sends the classroom server, as pydantic models: anything else is answered with an error
message and changes nothing (docs/classroom.md, "The protocol")."""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, TypeAdapter

Seats = Literal["all"] | list[Annotated[int, Field(ge=1, le=64)]]


class _Message(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)


class HelloMessage(_Message):
    type: Literal["hello"]
    role: Literal["trainee", "instructor"]
    seat: int | None = Field(None, ge=1, le=64, description="the trainee's seat")
    name: str = Field("", max_length=64, description="the trainee's name, for the report")
    token: str | None = Field(None, max_length=64, description="the seat's token, to take it back after a disconnect")
    password: str | None = Field(None, max_length=256, description="the instructor's password")


class LobbyMessage(_Message):
    """Instead of a hello: what a login screen shows before anyone logs in (the station, the seats); then the
    server closes the connection."""

    type: Literal["lobby"]


class CommandMessage(_Message):
    type: Literal["command"]
    id: int = Field(ge=0, le=2**53)
    line: str = Field(description="one line of the command language; past 500 characters it is refused")
    seat: int | None = Field(None, ge=1, le=64, description="the instructor's target seat; a trainee's is its own")


class WatchMessage(_Message):
    type: Literal["watch"]
    seat: int = Field(ge=1, le=64)


class ClockMessage(_Message):
    type: Literal["clock"]
    seats: Seats
    action: Literal["pause", "run"] | None = None
    speed: float | None = Field(None, allow_inf_nan=False)


class ResetMessage(_Message):
    type: Literal["reset"]
    seats: Seats


class FreeMessage(_Message):
    """The instructor frees seats: their tokens and trainees are cleared, a new trainee may sit."""

    type: Literal["free"]
    seats: Seats


class ExerciseMessage(_Message):
    type: Literal["exercise"]
    seats: Seats
    name: str = Field(max_length=200, description="a bundled exercise, or one in the server's --exercise-dir")
    difficulty: int | None = Field(None, ge=1, le=3, description="1 easy, 2 medium, 3 hard; else the exercise's own")
    seed: int | None = Field(None, ge=0, le=2**31, description="the same seed draws the same faults on every seat")


class StopMessage(_Message):
    type: Literal["stop"]
    seats: Seats


ClientMessage = (HelloMessage | LobbyMessage | CommandMessage | WatchMessage | ClockMessage | ResetMessage
                 | ExerciseMessage | StopMessage | FreeMessage)
Message = Annotated[ClientMessage, Field(discriminator="type")]
MESSAGE: TypeAdapter[ClientMessage] = TypeAdapter(Message)


def problem(exc: Exception) -> str:
    """A validation error in one line: where, and what is wrong."""
    errors = getattr(exc, "errors", None)
    if callable(errors):
        first = errors()[0]
        where = ".".join(str(x) for x in first.get("loc", ())) or "message"
        return f"{where}: {first.get('msg', 'invalid')}"
    return str(exc)

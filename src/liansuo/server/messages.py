"""The messages a client sends the classroom server, as pydantic models: anything else is answered with an error
message and changes nothing (docs/classroom.md, "The protocol")."""

from __future__ import annotations

import json
from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, TypeAdapter

MAX_ID = 2**53  # the largest integer every JSON reader keeps exact
Seats = Literal["all"] | list[Annotated[int, Field(ge=1, le=64)]]


class _Message(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True)

    id: int | None = Field(None, ge=0, le=MAX_ID, description="the client's name for the message: every reply to it "
                                                             "carries the same id")


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


def message_id(raw: str | bytes) -> int | None:
    """The ``id`` of a message that did not validate, when it has a valid one: its error reply carries it too."""
    try:
        data = json.loads(raw)
    except ValueError:
        return None
    ident = data.get("id") if isinstance(data, dict) else None
    return ident if type(ident) is int and 0 <= ident <= MAX_ID else None


def problem(exc: Exception) -> str:
    """A validation error in one line: where, and what is wrong."""
    errors = getattr(exc, "errors", None)
    if callable(errors):
        first = errors()[0]
        where = ".".join(str(x) for x in first.get("loc", ())) or "message"
        return f"{where}: {first.get('msg', 'invalid')}"
    return str(exc)

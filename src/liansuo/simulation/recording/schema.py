"""The records of a session recording (:mod:`.recorder`, docs/console.md "Recording and replay") as pydantic
models, and the limits a recording is read within.

A recording is JSON lines: one record a line, told apart by its ``k``. The loader (:mod:`.file`) validates
each line with :data:`RECORD` straight from its JSON text (pydantic's own parser: no NaN, no infinity, no nesting
deeper than it allows, no invalid UTF-8), strict (a whole number where one is asked, no text for a number), and then
checks what a single record cannot say: their order, their numbering and the time of each.
"""

from __future__ import annotations

from typing import Annotated, Literal

from pydantic import BaseModel, ConfigDict, Field, TypeAdapter, field_validator

from liansuo.kit.filekind import RECORDING_FORMAT
from liansuo.simulation.language import MAX_LINE_CHARS as MAX_LINE_CHARS_OF_A_COMMAND

FORMAT = RECORDING_FORMAT  # the header's "format": how kit/filekind.py tells a recording from other files
VERSION = 2  # 2: the station's digest, its path relative to the recording, commands numbered (cmd "i", end "cmds")

# ---- limits ---------------------------------------------------------------------------------------------------------
# The longest recording replayed, in cycles. Quiet cycles are not written, so the file's size says nothing of how
# long a replay takes: the cycle count does. A console session is at most a shift (8 h); a day at the default
# 250 ms cycle leaves room, and re-simulates in about 15 s on jiaopei (a minute on a hub).
MAX_CYCLES = 345_600
# The cycle, as a test script's cycle_ms allows (proving/fileschemas.py): 10 ms to 2 s.
MIN_CYCLE_S = 0.01
MAX_CYCLE_S = 2.0
# The largest file read. A day of a busy console (a change every cycle, ~150 bytes each) is about 50 MB.
MAX_BYTES = 128 * 1024 * 1024
# The longest line: the init record of a hub station (every relay and output once) is a few hundred kilobytes.
MAX_LINE_CHARS = 8 * 1024 * 1024
# A station reference: a bundled name or a path (PATH_MAX on Linux).
MAX_STATION_CHARS = 4096
# An element id, an aspect or a state in a record; a station's ids are far shorter.
MAX_ID_CHARS = 200
# A command line and its answer, as the console's command bar or a script sends them: a line past the language's
# limit is recorded cut one character past it, which the language refuses in the same words on replay.
MAX_COMMAND_CHARS = MAX_LINE_CHARS_OF_A_COMMAND + 1
MAX_ANSWER_CHARS = 100_000
# Diagnostics listed for one file before the rest are left out.
MAX_ERRORS = 20

Id = Annotated[str, Field(min_length=1, max_length=MAX_ID_CHARS)]
Value = Annotated[str, Field(max_length=MAX_ID_CHARS)]
Cycle = Annotated[int, Field(ge=0, le=MAX_CYCLES, description="the number of cycles run before this record")]
# Simulated time: a billion seconds (some 30 years) is more than any session.
MAX_TIME_S = 1e9
Time = Annotated[float, Field(ge=0, le=MAX_TIME_S, description="simulated time, in seconds")]


class _Record(BaseModel):
    """Strict: no key but those listed, no value of another type taken for the one asked, numbers finite."""

    model_config = ConfigDict(extra="forbid", strict=True, allow_inf_nan=False, populate_by_name=True)


class InputsRecord(_Record):
    """Relay inputs of the interlocking: all of them in ``init``, what changed in ``cyc`` and ``chg``."""

    gj: dict[Id, bool] = Field(default_factory=dict, description="track relays: true when the section is clear")
    ind: dict[Id, Value | None] = Field(default_factory=dict,
                                        description="turnout indications: normal, reverse or null")
    dj: dict[Id, list[Id]] = Field(default_factory=dict, description="signal -> the lamps proven (DJ up)")
    pd: dict[Id, tuple[bool, bool]] = Field(default_factory=dict, description="platform:side -> [PDKJ, PDQCJ]")


class OutputsRecord(_Record):
    """Outputs of the interlocking, and the section states the console shows."""

    sig: dict[Id, Value] = Field(default_factory=dict, description="aspects")
    drv: dict[Id, Value | None] = Field(default_factory=dict, description="turnout drives")
    sec: dict[Id, Value] = Field(default_factory=dict, description="section states")


class HeaderRecord(_Record):
    """Line 1: what the recording is and the station it was made on."""

    k: Literal["header"]
    format: Literal["liansuo-recording"]
    version: Literal[2]
    station: str = Field(min_length=1, max_length=MAX_STATION_CHARS,
                         description="a bundled station name, or the station file's path relative to the recording")
    station_id: Id = Field(description="the station's id, compared with the station replayed on")
    station_sha256: str = Field(pattern=r"^[0-9a-f]{64}$",
                                description="SHA-256 of the station file, compared with the station replayed on")
    cycle_s: float = Field(ge=MIN_CYCLE_S, le=MAX_CYCLE_S, description="the interlocking's cycle, seconds")
    t0: Time = Field(description="simulated time when the recording started")

    @field_validator("station_sha256", mode="before")
    @classmethod
    def _digest_given(cls, value: object) -> object:
        if value == "":  # an empty digest would let any file of the station's id stand in for it
            raise ValueError("station_sha256 is empty: a recording carries the SHA-256 of its station's file, which "
                             "the replay checks; record the session again")
        return value


class InitRecord(_Record):
    """Line 2: every relay input and output when the recording started."""

    k: Literal["init"]
    n: Literal[0]
    t: Time
    in_: InputsRecord = Field(alias="in")
    out: OutputsRecord


class CmdRecord(_Record):
    """A command and its answer, in the order sent; ``i`` numbers them from 1, so none can go missing unseen."""

    k: Literal["cmd"]
    i: int = Field(ge=1, description="the command's number, from 1")
    n: Cycle
    t: Time
    line: str = Field(max_length=MAX_COMMAND_CHARS)
    ok: bool
    msg: str = Field(max_length=MAX_ANSWER_CHARS)
    by: str = Field(max_length=MAX_ID_CHARS, description="who sent it: trainee, instructor, exercise, console ...")


class CycRecord(_Record):
    """What a cycle changed (cycles that change nothing are not written)."""

    k: Literal["cyc"]
    n: Annotated[int, Field(ge=1, le=MAX_CYCLES)]
    t: Time
    in_: InputsRecord | None = Field(None, alias="in")
    out: OutputsRecord | None = None


class ChgRecord(_Record):
    """What the command just before it changed without a cycle (a fault, a turnout thrown ...)."""

    k: Literal["chg"]
    n: Cycle
    t: Time
    in_: InputsRecord | None = Field(None, alias="in")
    out: OutputsRecord | None = None


class EndRecord(_Record):
    """The last line: how long the session ran and how many commands it sent."""

    k: Literal["end"]
    n: Cycle
    t: Time
    cmds: int = Field(ge=0, description="the number of cmd records")


Record = HeaderRecord | InitRecord | CmdRecord | CycRecord | ChgRecord | EndRecord
RECORD: TypeAdapter[Record] = TypeAdapter(Annotated[Record, Field(discriminator="k")])
KINDS = ("header", "init", "cmd", "cyc", "chg", "end")


def state_of(record: InitRecord | CycRecord | ChgRecord) -> dict[str, dict[str, dict[str, object]]]:
    """The record's ``in`` and ``out`` as the recorder wrote them (only the groups it holds)."""
    out: dict[str, dict[str, dict[str, object]]] = {}
    for side, part in (("in", record.in_), ("out", record.out)):
        if part is not None:
            out[side] = part.model_dump(mode="json", exclude_unset=True)
    return out

"""The value types of the station file: ids, positions (metres or kilometre posts), route ids, and the numbers
with the ranges of :mod:`.limits`; each says what it accepts in its message and its JSON Schema."""

from __future__ import annotations

import re
from typing import Annotated

from pydantic import AfterValidator, BeforeValidator, Field, WithJsonSchema

from liansuo.kit.inputlimits import LIMITS
from liansuo.stations import limits

_ID_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_\-/]*$")
_KM_RE = re.compile(r"^K(\d+)\+(\d+(?:\.\d+)?)$")


def to_id(value: object) -> object:
    if isinstance(value, bool):
        return value  # rejected below with a clear message
    if isinstance(value, int):
        return str(value)
    return value


def check_length(value: str, what: str) -> None:
    if len(value) > LIMITS.max_id_chars:
        raise ValueError(f"{what} of {len(value):,} characters: an id has at most {LIMITS.max_id_chars}, as "
                         "written on the station diagram")


def _check_id(value: str) -> str:
    check_length(value, "an id")
    if not _ID_RE.fullmatch(value):  # fullmatch: '$' alone would let a line break end an id
        raise ValueError(f"'{value}' is not a valid id: use letters, digits, '-', '_' or '/', starting with a "
                         "letter or digit")
    return value


# JSON Schema: what the loader accepts (a whole number such as turnout 1 is taken as the id '1').
_ID_SCHEMA = {"anyOf": [{"type": "string", "pattern": _ID_RE.pattern, "maxLength": LIMITS.max_id_chars},
                        {"type": "integer", "minimum": 0}]}
Id = Annotated[str, BeforeValidator(to_id), AfterValidator(_check_id), WithJsonSchema(_ID_SCHEMA)]


def parse_km(text: str) -> float:
    """``K12+345.6`` -> 12345.6 metres; ``ValueError`` for another text or a post outside the range of a position
    (:data:`.limits.POSITION`), however many digits it has."""
    m = _KM_RE.fullmatch(text.strip())
    if not m:
        raise ValueError(f"'{text}' is not a position: write metres (e.g. 350.5) or a kilometre post (K12+345.6)")
    # float() of digits never overflows (it gives inf), where int() of them would, and past 4300 digits refuses
    metres = float(m.group(1)) * 1000 + float(m.group(2))
    if not limits.POSITION.holds(metres):
        raise ValueError(f"{limits.POSITION.what} must be {limits.POSITION.range_text()}")
    return metres


def whole_as_float(value: int, limit: limits.Limit) -> float:
    """A whole number read from a file as a float; one too large for a float (a position of 400 digits) is out of
    ``limit``'s range, refused with its words instead of an ``OverflowError``."""
    try:
        return float(value)
    except OverflowError:
        raise ValueError(f"{limit.what} must be {limit.range_text()}") from None


def _position(value: object) -> object:
    if isinstance(value, bool):
        raise ValueError("a position is a number of metres or a kilometre post like K12+345.6, not true/false")
    if isinstance(value, str):
        return parse_km(value)
    if isinstance(value, int):
        return whole_as_float(value, limits.POSITION)
    return value


# A position: metres along the line, or a kilometre post ``K12+345.6``.
# Every number below has its range from :mod:`.limits`, where each limit says why.
Position = Annotated[float, BeforeValidator(_position), limits.POSITION.check(), WithJsonSchema(
    {"anyOf": [{"type": "number", "minimum": limits.POSITION.low, "maximum": limits.POSITION.high},
               {"type": "string", "pattern": _KM_RE.pattern}],
     "description": "metres (down direction increasing) or a kilometre post such as K12+345.6"})]


def _metres(limit: limits.Limit) -> BeforeValidator:
    return BeforeValidator(lambda v: whole_as_float(v, limit) if type(v) is int else v)


Metres = Annotated[float, Field(gt=0)]
TrackLength = Annotated[Metres, _metres(limits.TRACK_LENGTH), limits.TRACK_LENGTH.field(),
                        limits.TRACK_LENGTH.check()]
Speed = Annotated[float, limits.SPEED.field(), limits.SPEED.check()]
Release = Annotated[float, limits.RELEASE.field(), limits.RELEASE.check()]
Coordinate = Annotated[float, limits.DIAGRAM.field(), limits.DIAGRAM.check()]
TuningArea = Annotated[Metres, _metres(limits.TUNING_AREA), limits.TUNING_AREA.field(), limits.TUNING_AREA.check()]
DeadZone = Annotated[float, limits.DEAD_ZONE.field(), limits.DEAD_ZONE.check()]
Capacitance = Annotated[float, limits.CAPACITANCE.field(), limits.CAPACITANCE.check()]
Stretch = Annotated[float, limits.STRETCH.field(), limits.STRETCH.check()]
StopWindow = Annotated[float, limits.STOP_WINDOW.field(), limits.STOP_WINDOW.check()]
SlipLength = Annotated[Metres, _metres(limits.DOUBLE_SLIP_LENGTH),
                     limits.DOUBLE_SLIP_LENGTH.field(), limits.DOUBLE_SLIP_LENGTH.check()]


_ROUTE_RE = re.compile(r"^[A-Za-z0-9][A-Za-z0-9_\-/]*(\([A-Za-z0-9_\-/,]+\))?(\+[A-Za-z0-9_\-/]+)?(/D)?$")


def _check_route_id(value: str) -> str:
    check_length(value, "a route id")
    if not _ROUTE_RE.fullmatch(value):
        raise ValueError(f"'{value}' is not a route id: routes are named START-END, with the variant buttons in "
                         "brackets (X-XI(BA1)); see 'liansuo table STATION'")
    return value


# A route of the interlocking table, as 'liansuo table' names it: START-END, START-END(VIA), START-END/D, and
# START-END+OVERLAP_END for a route with an alternative overlap.
RouteId = Annotated[str, AfterValidator(_check_route_id), WithJsonSchema({"type": "string",
                                                                           "pattern": _ROUTE_RE.pattern,
                                                                           "maxLength": LIMITS.max_id_chars})]

"""The station file format (pydantic v2, strict: unknown keys are errors).

One file describes one station. Positions are metres along the line from the station origin, increasing in the down
direction (下行), or kilometre posts such as ``K12+345.6`` (= 12345.6 m). Ids are those of the
station diagram (站场图): signals ``X``, ``SI``, ``D3``; turnouts ``1``, ``3``; sections ``IG``, ``1DG``, ``IAG``.
"""

from __future__ import annotations

import re
from enum import StrEnum
from typing import Annotated, Literal

from pydantic import AfterValidator, BaseModel, BeforeValidator, ConfigDict, Field, WithJsonSchema

from liansuo.stations import limits
from liansuo.stations.values import (
    Capacitance,
    Coordinate,
    DeadZone,
    Id,
    Position,
    Release,
    RouteId,
    SlipLength,
    Speed,
    StopWindow,
    Stretch,
    TrackLength,
    TuningArea,
    to_id,
)


class Strict(BaseModel):
    model_config = ConfigDict(extra="forbid", strict=True, frozen=True, allow_inf_nan=False)


class Direction(StrEnum):
    """下行 down trains run towards increasing positions (enter at the X end); 上行 up the other way."""

    down = "down"
    up = "up"


class Name(Strict):
    """Display name, kept apart from the id so a station rename is a data-only change."""

    zh: str = Field(min_length=1)
    en: str = Field(min_length=1)


class Draw(Strict):
    """Optional schematic coordinates (columns, rows) for the console's station diagram."""

    x: Coordinate
    y: Coordinate


class EndKind(StrEnum):
    buffer = "buffer"  # 车挡
    boundary = "boundary"  # 站界 / line continues to a neighbour station


class End(Strict):
    """A buffer stop or the boundary where the line leaves the station model."""

    id: Id
    kind: EndKind
    at: Position
    draw: Draw | None = None


class JointKind(StrEnum):
    insulated = "insulated"  # 绝缘节
    electrical = "electrical"  # 电气绝缘节 (ZPW-2000A tuning area)


class Joint(Strict):
    """An insulated or electrical joint separating two track-circuit sections.

    ``at`` is the first rail's joint; ``at2`` the second rail's where they are staggered (错开): the stretch between
    them is a dead zone (死区段) where a wheelset shunts nothing.
    """

    id: Id
    at: Position
    at2: Position | None = None
    kind: JointKind = JointKind.insulated
    tuning_area_m: TuningArea | None = None
    dead_zone_m: DeadZone | None = None
    draw: Draw | None = None


class Machine(StrEnum):
    ZD6 = "ZD6"
    ZDJ9 = "ZDJ9"
    S700K = "S700K"


class Drive(Strict):
    """A driven turnout (带动道岔): when a route sets the turnout that names it to ``when``, ``turnout`` is moved to
    ``position`` with the route and proven there before the signal opens, although the route does not run over it."""

    turnout: Id
    position: Literal["normal", "reverse"]
    when: Literal["normal", "reverse"]


class Turnout(Strict):
    """A turnout (道岔): its point leg on one side, normal (定位) and reverse (反位) legs on the other."""

    id: Id
    at: Position
    number: Annotated[int, Field(ge=6, le=62)]
    machine: Machine
    pair: Id | None = None  # crossover pair moved by one command, e.g. '1/3' (双动道岔)
    trailable: bool = True
    diverging_speed_kmh: Annotated[float, Field(gt=0, le=250)] | None = None  # 侧向允许速度, when not the number's
    drives: list[Drive] = Field(default_factory=list)  # 带动道岔 that are not its crossover partner
    draw: Draw | None = None


class Track(Strict):
    """A piece of track between two nodes (end, joint or turnout leg such as ``1.normal``)."""

    id: Id
    start: str = Field(alias="from")
    end: str = Field(alias="to")
    section: Id
    length: TrackLength | None = None
    row: Coordinate | None = None  # schematic row, 0 = the main line

    model_config = ConfigDict(extra="forbid", strict=True, frozen=True, populate_by_name=True,
                              allow_inf_nan=False)


class CircuitType(StrEnum):
    phase25hz = "25hz"  # 97型 25 Hz 相敏轨道电路
    zpw2000a = "zpw2000a"  # ZPW-2000A 无绝缘移频
    axle_counter = "axle_counter"  # 计轴: counting heads at its ends; clear when as many axles left as entered


class SectionRole(StrEnum):
    station_track = "station_track"  # 股道
    throat = "throat"  # turnout and other sections of the throat (咽喉区)
    approach = "approach"  # 接近区段
    departure = "departure"  # 离去区段
    block = "block"  # automatic block section (闭塞分区)
    spur = "spur"  # 尽头线


class LineClass(StrEnum):
    """Which ZPW-2000A a section has: its design minimum ballast and standard capacitors (docs/zpw2000a.md)."""

    conventional = "conventional"  # 普速: relay-coded, ballast from 1.0 ohm*km, 55/50/46/40 uF about every 100 m
    passenger = "passenger"  # 客专: communication-coded, ballast from 2.0 ohm*km, 25 uF every 60/80 m (station 100 m)


class Capacitors(Strict):
    """Compensation capacitors (补偿电容): explicit positions (metres from the section's lower end), a count placed
    by the standard rule, or ``rule: standard`` (about every 100 m, half a spacing at the ends, only over 300 m)."""

    count: Annotated[int, Field(ge=0, le=60)] | None = None
    positions: Annotated[list[Annotated[float, Field(ge=0, le=limits.ZPW_SECTION.high)]],
                         Field(max_length=60)] | None = None  # within the section: stations/checks.py
    rule: Literal["standard"] | None = None
    capacitance_uF: Capacitance | None = None


_CARRIER_RE = re.compile(r"^(1700|2000|2300|2600)-(1|2)$")


def _check_carrier(value: str) -> str:
    if not _CARRIER_RE.fullmatch(value):
        raise ValueError(f"'{value}' is not a ZPW-2000A carrier: use 1700, 2000, 2300 or 2600 with -1 or -2, "
                         "e.g. '2300-1'")
    return value


Carrier = Annotated[str, BeforeValidator(to_id), AfterValidator(_check_carrier),
                    WithJsonSchema({"type": "string", "pattern": _CARRIER_RE.pattern})]


class Section(Strict):
    """A track-circuit section (轨道电路区段)."""

    id: Id
    type: CircuitType
    role: SectionRole = SectionRole.throat
    carrier: Carrier | None = None
    coded: bool = False  # 电码化: carries cab-signal codes
    capacitors: Capacitors | None = None
    line_class: LineClass | None = None  # ZPW-2000A only; none given: conventional
    speed_kmh: Speed | None = None
    safety_line: bool = False  # a safety line (安全线): a spur that isolates the end of a receiving track
    name: str | None = None


class SignalKind(StrEnum):
    home = "home"  # 进站
    starting = "starting"  # 出站
    route = "route"  # 进路
    shunting = "shunting"  # 调车
    block = "block"  # 通过 (automatic block)


class Lamp(StrEnum):
    L = "L"  # green
    U = "U"  # yellow
    U2 = "U2"  # second yellow
    H = "H"  # red
    B = "B"  # moon-white
    A = "A"  # blue
    L2 = "L2"  # second green (LL)


def _each_lamp_once(lamps: list[Lamp]) -> list[Lamp]:
    twice = next((lamp for i, lamp in enumerate(lamps) if lamp in lamps[:i]), None)
    if twice is not None:
        raise ValueError(f"lamp {twice.value} is listed twice: a signal has each lamp once")
    return lamps


# A signal's lamps, each once (the lamp circuits have one filament pair per lamp).
Lamps = Annotated[list[Lamp], Field(min_length=1, json_schema_extra={"uniqueItems": True}),
                  AfterValidator(_each_lamp_once)]


class Button(StrEnum):
    train = "train"  # 列车按钮 LA
    shunt = "shunt"  # 调车按钮 DA


class Signal(Strict):
    """A colour-light signal standing at a joint (or end), governing movements in ``direction``."""

    id: Id
    kind: SignalKind
    at: Id
    direction: Direction
    lamps: Lamps
    usu: bool = False  # may show the flashing yellow USU (needs a U and a U2 lamp)
    flasher: Literal["relay", "electronic"] = "electronic"  # USU flasher: classic RC relay (SNJ/SNJJ) or electronic
    buttons: list[Button] = Field(default_factory=list)
    release_s: Release | None = None  # manual release delay override
    approach: list[Id] | None = None  # override of the approach section(s) (接近区段)
    draw: Draw | None = None


class StandaloneButton(Strict):
    """A button not on a signal: a departure end (发车口) or a variant button (变通按钮)."""

    id: Id
    at: Id  # a joint, an end, or for variant buttons a track
    kind: Literal["exit", "variant", "end"]
    direction: Direction | None = None


class FoulingPoint(Strict):
    """A fouling point (警冲标): where two tracks that part at a turnout come so close that a vehicle on one fouls
    the other. Give its ``turnout`` and the two ``tracks`` it stands between (one reached from the normal leg, one
    from the reverse leg), or, in the older short form, only the ``track`` it stands by."""

    id: Id
    at: Position
    turnout: Id | None = None
    tracks: Annotated[list[Id], Field(min_length=2, max_length=2)] | None = None  # [normal side, reverse side]
    track: Id | None = None


class MarkerKind(StrEnum):
    sanding = "sanding"  # 上砂点: depot speed limit over it
    washing = "washing"  # 洗车点
    one_stop = "one-stop"  # 一度停车点: every movement stops here once
    balise = "balise"  # 应答器: odometry correction
    rfid = "rfid"  # RFID tag: odometry correction in the depot
    stop = "stop"  # 停车标: the stopping point of a platform or a depot track


class Marker(Strict):
    """A trackside point that trains and their drivers see (not the interlocking)."""

    id: Id
    kind: MarkerKind
    track: Id
    at: Position
    length_m: Stretch = 0.0  # for sanding / washing stretches
    speed_kmh: Speed | None = None  # speed limit over it, where it has one


class Side(StrEnum):
    left = "left"
    right = "right"


class ScreenDoors(Strict):
    """Platform screen doors (站台门) on one side of a platform track; ``side`` is seen facing the down direction."""

    side: Side
    doors: Annotated[int, Field(ge=1, le=64)] = 8


class Platform(Strict):
    id: Id
    section: Id
    screen_doors: list[ScreenDoors] = Field(default_factory=list)
    stop_window_m: StopWindow = 0.5
    name: str | None = None


class LinkKind(StrEnum):
    semi_auto_64d = "64d"  # 64D 半自动闭塞
    automatic = "automatic"  # 自动闭塞
    station = "station"  # 自动站间闭塞: the whole line is one block section, proven clear by axle counters


class Link(Strict):
    """A block link to a neighbour station (区间闭塞).

    On a station-to-station block line (``kind: station``, 自动站间闭塞) the line between the two stations is one
    block section, proven clear by its track-clear device (axle counters: sections of ``type: axle_counter``).
    Setting a departure route blocks the line for our train; it restores by itself once the line is clear again.

    On an automatic block line the running direction follows from its sections: approach sections (``role:
    approach``) carry trains towards the station, departure sections away from it. ``bidirectional: true`` says the
    line may be worked the other way after a direction change (改方, 双向自动闭塞); a departure against the running
    direction of a line that is not bidirectional is refused.
    """

    id: Id
    kind: LinkKind
    end: Id  # the boundary end the link leaves from
    neighbour: Name
    sections: list[Id] = Field(default_factory=list)  # block/departure sections, nearest first
    bidirectional: bool = False


class Diamond(Strict):
    """A diamond crossing (菱形交叉): two tracks that cross at grade, such as the two diagonals in the middle of a
    scissors crossover (交叉渡线). No movement passes from one track to the other, but a movement on either
    occupies the crossing, so two movements may never use both at once."""

    id: Id
    tracks: list[Id] = Field(min_length=2, max_length=2)
    at: Position | None = None  # where the tracks cross (optional; checked against both tracks when given)


# the turnouts of one slip road: [low-end turnout, high-end turnout]
SlipRoad = Annotated[list[Id], Field(min_length=2, max_length=2)]


class DoubleSlip(Strict):
    """A double slip (复式交分道岔): two tracks crossing at grade with both slip roads, so a movement from either
    end of either track may leave by either track at the far end. Its four ends are four turnouts, numbered as two
    crossover pairs (双动道岔), one pair per slip road: ``slips: [[21, 23], [25, 27]]`` joins 21 to 23 and 25 to 27
    by the slip roads, while the straight roads 21-27 and 25-23 cross in the middle. The loader expands it into
    those turnouts, four inner tracks and the diamond of the straight roads (stations/doubleslip.py)."""

    id: Id
    at: Position  # the centre, where the two straight roads cross
    length: SlipLength  # from the low-end turnouts (at - length/2) to the high-end ones (at + length/2)
    number: Annotated[int, Field(ge=6, le=62)]
    machine: Machine
    section: Id  # the track-circuit section it lies in, with the tracks at its four points
    slips: Annotated[list[SlipRoad], Field(min_length=2, max_length=2)]
    diverging_speed_kmh: Annotated[float, Field(gt=0, le=250)] | None = None  # over the slip roads


class TurnoutPosition(StrEnum):
    normal = "normal"
    reverse = "reverse"


class ProtectionOverride(Strict):
    route: RouteId
    turnout: Id
    position: TurnoutPosition


class EnemyOverride(Strict):
    """Two routes the topology does not make enemies that must never be locked together (an added 敌对进路, for
    example a receiving route against a shunting route beyond a falling gradient)."""

    route: RouteId
    enemy: RouteId
    why: str = Field(default="named in the station file", min_length=1)


class FoulingOverride(Strict):
    """A section a route must find clear although the topology does not say so (an added track condition, 侵限
    区段): a siding whose vehicles foul the route where no fouling point is drawn, say."""

    route: RouteId
    section: Id


class Overrides(Strict):
    """What topology alone cannot decide: extra protection turnouts, added enemies and track conditions, routes that
    must not exist."""

    protection: list[ProtectionOverride] = Field(default_factory=list)
    remove_protection: list[ProtectionOverride] = Field(default_factory=list)
    enemies: list[EnemyOverride] = Field(default_factory=list)
    fouling: list[FoulingOverride] = Field(default_factory=list)
    forbid: list[RouteId] = Field(default_factory=list)


class TurnoutAt(Strict):
    turnout: Id
    position: TurnoutPosition


class Overlap(Strict):
    """An overlap (延续进路) beyond the end signal of receiving routes, where the file asks for one (e.g. a falling
    gradient over 6 per mille beyond the track): its sections and turnouts are locked with the route and released
    ``release_s`` after the train occupies the receiving track (by default the rule set's ``overlap_release_s``).

    Several entries for one end signal are alternative overlaps (变更延续进路): each names the button it ends at
    (``end``, the overlap's end button, 延续进路终端按钮); the first is the basic overlap, set when the operator presses
    no overlap button, the others are chosen by pressing their end button after the route's end button."""

    end_signal: Id
    end: Id | None = None  # the overlap's end button (a signal or button); required for alternatives
    sections: list[Id] = Field(min_length=1)
    turnouts: list[TurnoutAt] = Field(default_factory=list)
    release_s: Release | None = None


class Grade(Strict):
    """One stretch of the station's longitudinal profile (纵断面): its gradient in per mille, positive where the line
    rises towards increasing positions (the down direction)."""

    start: Position = Field(alias="from")
    end: Position = Field(alias="to")
    per_mille: Annotated[float, Field(ge=-60, le=60)]

    model_config = ConfigDict(extra="forbid", strict=True, frozen=True, populate_by_name=True,
                              allow_inf_nan=False)


class StationFile(Strict):
    """The whole station description."""

    id: Id
    name: Name
    description: str = ""
    line: Literal["single", "double"] = "single"
    line_speed_kmh: Speed = 120.0
    emu: bool = False  # EMUs call here: fouling-point clearance 5 m
    ends: list[End] = Field(min_length=1, max_length=limits.STATION_ITEMS["ends"])
    joints: list[Joint] = Field(default_factory=list, max_length=limits.STATION_ITEMS["joints"])
    turnouts: list[Turnout] = Field(default_factory=list, max_length=limits.STATION_ITEMS["turnouts"])
    tracks: list[Track] = Field(min_length=1, max_length=limits.STATION_ITEMS["tracks"])
    sections: list[Section] = Field(min_length=1, max_length=limits.STATION_ITEMS["sections"])
    signals: list[Signal] = Field(default_factory=list, max_length=limits.STATION_ITEMS["signals"])
    buttons: list[StandaloneButton] = Field(default_factory=list, max_length=limits.STATION_ITEMS["buttons"])
    fouling_points: list[FoulingPoint] = Field(default_factory=list, max_length=limits.STATION_ITEMS["fouling_points"])
    diamonds: list[Diamond] = Field(default_factory=list, max_length=limits.STATION_ITEMS["diamonds"])
    double_slips: list[DoubleSlip] = Field(default_factory=list, max_length=limits.STATION_ITEMS["double_slips"])
    profile: list[Grade] = Field(default_factory=list, max_length=limits.STATION_ITEMS["profile"])
    markers: list[Marker] = Field(default_factory=list, max_length=limits.STATION_ITEMS["markers"])
    platforms: list[Platform] = Field(default_factory=list, max_length=limits.STATION_ITEMS["platforms"])
    links: list[Link] = Field(default_factory=list, max_length=limits.STATION_ITEMS["links"])
    overlaps: list[Overlap] = Field(default_factory=list, max_length=limits.STATION_ITEMS["overlaps"])
    overrides: Overrides = Field(default_factory=Overrides)

"""The interlocking's own memory: routes in progress, turnout locks, signal flags."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from .table import Route


class RouteStage(StrEnum):
    """Route lifecycle of one real CBI: selected -> turnouts moving -> locked -> open -> in use -> released."""

    setting = "setting"  # selected; turnouts being moved into position
    locked = "locked"  # turnouts in position and locked; signal closed (not yet opened, or closed abnormally)
    open = "open"  # signal open
    in_use = "in_use"  # a train has entered; sections release one by one behind it
    time_release = "time_release"  # manual time release counting down (总人解 / 区故解 delay)


@dataclass
class RouteState:
    route: Route
    stage: RouteStage
    since: float
    guide: bool = False  # opened as a guide route (HB)
    opened_once: bool = False  # the signal has been open at least once (approach locking applies)
    needs_reopen: bool = False  # closed abnormally; only 'reopen' opens it again
    entered: bool = False  # the first section has been occupied
    released: list[bool] = field(default_factory=list)
    was_occupied: list[bool] = field(default_factory=list)
    release_at: float | None = None  # when a time release completes
    close_reason: str = ""
    overlap_locked: bool = False
    overlap_release_at: float | None = None
    guide_approach_seen: bool = False

    def __post_init__(self) -> None:
        n = len(self.route.sections)
        self.released = [False] * n
        self.was_occupied = [False] * n

    @property
    def id(self) -> str:
        return self.route.id


@dataclass
class TurnoutState:
    id: str
    section: str
    trailable: bool = True
    locks: set[str] = field(default_factory=set)  # route ids (or 'overlap:ROUTE') holding it
    single_locked: bool = False  # 单锁
    single_blocked: bool = False  # 单封
    guide_locked: bool = False  # 引导总锁闭
    target: str | None = None  # position being driven to
    queued: bool = False
    move_started: float | None = None
    no_indication_since: float | None = None
    squeeze_alarmed: bool = False


@dataclass
class SignalState:
    id: str
    aspect: str
    route: str | None = None  # route whose signal this is, while set
    red_dark: bool = False

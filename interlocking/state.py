"""The interlocking's own memory of routes in progress, turnout moves and signals. Locks are the ledger's
(:mod:`.locks`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from .route import Route, RouteTurnout, RunOn


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
    run_on: RunOn | None = None  # the way a shunting movement runs on past the end, chosen when set
    guide: bool = False  # opened as a guide route (HB)
    opened_once: bool = False  # the signal has been open at least once (approach locking applies)
    needs_reopen: bool = False  # closed abnormally; only 'reopen' opens it again
    entered: bool = False  # the first section has been occupied
    released: list[bool] = field(default_factory=list)
    was_occupied: list[bool] = field(default_factory=list)
    release_at: float | None = None  # when a time release completes
    close_reason: str = ""
    overlap_release_at: float | None = None
    guide_first_clear: bool = False  # under a guide aspect: the first section was clear when it opened
    guide_approach_seen: bool = False

    def __post_init__(self) -> None:
        n = len(self.sections)
        self.released = [False] * n
        self.was_occupied = [False] * n

    @property
    def id(self) -> str:
        return self.route.id

    @property
    def sections(self) -> tuple[str, ...]:
        """The route's sections, then the sections it runs on over."""
        if self.run_on is None:
            return self.route.sections
        return self.route.sections + tuple(s for s in self.run_on.sections if s not in self.route.sections)

    @property
    def turnouts(self) -> tuple[RouteTurnout, ...]:
        """Route, protection and driven turnouts, with those of the run-on (not the overlap's)."""
        if self.run_on is None:
            return self.route.turnouts
        have = {t.id for t in self.route.turnouts}
        return self.route.turnouts + tuple(t for t in self.run_on.turnouts if t.id not in have)

    @property
    def all_turnouts(self) -> tuple[RouteTurnout, ...]:
        return self.turnouts + self.route.overlap_turnouts


@dataclass
class TurnoutState:
    """What the interlocking remembers of one turnout's moves (its locks are in the ledger)."""

    id: str
    section: str
    trailable: bool = True
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

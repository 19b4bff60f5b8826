"""The interlocking's own memory of routes in progress, turnout moves and signals. Locks are the ledger's
(:mod:`.locks`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum

from .route import Route, RouteTurnout, RunOn


class RouteStage(StrEnum):
    """The stages of a route in one real CBI (the state machine is :mod:`.lifecycle`)."""

    setting = "setting"  # selected; turnouts being moved into position
    locked = "locked"  # turnouts in position and locked; the signal not yet given
    open = "open"  # the signal shows a proceed aspect
    guide = "guide"  # the signal shows the guide aspect (引导), the route's track circuits not checked
    closed = "closed"  # the signal was given and closed again (abnormally, or an unused guide aspect): 'reopen'
    in_use = "in_use"  # a train has entered; sections release one by one behind it
    time_release = "time_release"  # manual time release counting down (总人解 / 区故解 delay)


@dataclass
class RouteState:
    route: Route
    stage: RouteStage
    since: float
    run_on: RunOn | None = None  # the way a shunting movement runs on past the end, chosen when set
    entered: bool = False  # the first section has been occupied
    released: list[bool] = field(default_factory=list)
    was_occupied: list[bool] = field(default_factory=list)
    release_at: float | None = None  # when a time release completes
    overlap_release_at: float | None = None  # when the overlap releases, once the train reached the route's end
    guide_first_clear: bool = False  # under a guide aspect: the first section was clear when it opened
    guide_approach_seen: bool = False  # under a guide aspect: the guided train has been seen approaching

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
class GuideOnly:
    """A guide aspect given without a route, over a throat under guide total lock (引导总锁闭)."""

    since: float
    approach_seen: bool = False


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
    """What the interlocking remembers of one signal (its aspect is in the outputs, its route in ``by_signal``)."""

    id: str
    red_dark: bool = False  # the stop lamp is dark (both filaments): red lamp transfer to the signal in rear

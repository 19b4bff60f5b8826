"""The interlocking's own memory of routes in progress, turnout moves and signals. Locks are the ledger's
(:mod:`.locks`)."""

from __future__ import annotations

from dataclasses import dataclass, field
from enum import StrEnum
from typing import ClassVar, Protocol

from liansuo.interlocking.io import Changes
from liansuo.interlocking.table.route import Route, RouteTurnout, RunOn


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
    guide_first_clear: bool = True  # the first section was clear when the signal was last given (always for a
    # main aspect; under a guide aspect, not when it is the red band the guide is for)
    guide_approach_seen: bool = False  # under a guide aspect: the guided train has been seen approaching
    # section index -> when its section fault release (区故解) completes, given ahead of the movement in the route
    fault_release_at: dict[int, float] = field(default_factory=dict)
    guide_route: bool = False  # a guide route (引导进路锁闭): locked without its track circuits, opens only HB
    overlap_released: bool = False  # its overlap was released by section fault release before the signal was given
    # what the last cycle of its stage read (RouteMemo), so that a cycle in which none of it changed skips it
    memo: RouteMemo | None = field(default=None, repr=False, compare=False)

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


class RouteMemo(Protocol):
    """What the handler of one stage of a route read when it last ran and changed nothing it would not change again
    (:meth:`~.memos.Memos.unchanged`): ``holds`` when nothing of it changed in ``cycle``, the cycle after
    ``cycle`` it was taken or last held through. Each kind knows the one ``stage`` it serves."""

    stage: ClassVar[RouteStage]
    cycle: int

    def holds(self, rs: RouteState, cycle: int, changes: Changes) -> bool: ...


class ReleaseMemo:
    """What the release check of a route in use (:meth:`~.lifecycle.RouteLifecycle._sequential_release`) left
    behind: its sections' release and occupation marks, the overlap timer and the run-on, and every section whose
    track relay it read. That check changes nothing when run again on the same marks and the same relays, so while
    these hold and none of ``watched`` changed it need not run; ``cycle`` is the last cycle it held through, since
    only the relays that changed in the cycle after it are known."""

    __slots__ = ("cycle", "overlap_release_at", "released", "route", "run_on", "was_occupied", "watched")
    stage: ClassVar[RouteStage] = RouteStage.in_use

    def __init__(self, rs: RouteState, cycle: int, watched: frozenset[str]) -> None:
        self.cycle = cycle
        self.route = rs.route
        self.run_on = rs.run_on
        self.released = list(rs.released)
        self.was_occupied = list(rs.was_occupied)
        self.overlap_release_at = rs.overlap_release_at
        self.watched = watched

    def holds(self, rs: RouteState, cycle: int, changes: Changes) -> bool:
        """Nothing the check reads changed since it last ran: its marks, and the track relays it watches."""
        return (self.cycle == cycle - 1 and not rs.fault_release_at and self.watched.isdisjoint(changes.tracks)
                and rs.released == self.released
                and rs.was_occupied == self.was_occupied and rs.overlap_release_at == self.overlap_release_at
                and rs.run_on is self.run_on and rs.route is self.route)


@dataclass(frozen=True)
class Reads:
    """What a route's supervision reads of the relays, by name: its sections (with approach, fouling, overlap, line
    and liaison sections), its turnouts (with the overlap's), its own and the next signal, its screen doors. The same
    for a route and run-on whenever it is set, so worked out once (``RouteLifecycle.reads``)."""

    sections: frozenset[str]
    turnouts: frozenset[str]
    signals: frozenset[str]
    doors: frozenset[str]


class SettingMemo:
    """A route setting whose turnouts were not all in position at ``cycle``
    (:meth:`~.lifecycle.RouteLifecycle._setting` reads nothing but their indications): while none of ``turnouts``
    changed its indication since, they still are not."""

    __slots__ = ("cycle", "route", "run_on", "turnouts")
    stage: ClassVar[RouteStage] = RouteStage.setting

    def __init__(self, rs: RouteState, cycle: int, reads: Reads) -> None:
        self.cycle = cycle
        self.route = rs.route
        self.run_on = rs.run_on
        self.turnouts = reads.turnouts

    def holds(self, rs: RouteState, cycle: int, changes: Changes) -> bool:
        return (self.cycle == cycle - 1 and self.turnouts.isdisjoint(changes.turnouts) and rs.route is self.route
                and rs.run_on is self.run_on)


class OpenMemo:
    """What the supervision of an open signal (:meth:`~.lifecycle.RouteLifecycle._keep_open`) read at ``cycle`` when
    it found every condition holding and the aspect it wanted proven (no lamp dark, so no alarm raised): the relays
    of its sections, turnouts, signals and screen doors; the lock ledger's version; the aspects of its own and of the
    next signal; the route set from the next signal; its line's liaison state; the USU flasher verdict; its own
    release marks. Looking again on the same of all these finds the same and changes nothing, so while they hold it
    need not look (``Core.open_blocker`` and ``Core.wanted_aspect`` read nothing else)."""

    __slots__ = ("aspect", "cycle", "end_aspect", "ledger", "liaison", "onward", "onward_run_on", "reads", "route",
                 "run_on", "usu_failed")
    stage: ClassVar[RouteStage] = RouteStage.open

    def __init__(self, rs: RouteState, cycle: int, reads: Reads, *, ledger: int, aspect: str | None,
                 end_aspect: str | None, onward: RouteState | None, liaison: tuple[object, ...],
                 usu_failed: bool) -> None:
        self.cycle = cycle
        self.route = rs.route
        self.run_on = rs.run_on
        self.reads = reads
        self.ledger = ledger
        self.aspect = aspect
        self.end_aspect = end_aspect
        self.onward = onward
        self.onward_run_on = onward.run_on if onward is not None else None
        self.liaison = liaison
        self.usu_failed = usu_failed

    def holds(self, rs: RouteState, cycle: int, changes: Changes) -> bool:
        """None of the relays the supervision reads changed in ``cycle`` (the cycle after the memo's), the route and
        its run-on are the same, nothing entered it and nothing of it released. The interlocking's own state (locks,
        aspects, the onward route, the line) is compared by :meth:`~.memos.Memos._open_unchanged`."""
        reads = self.reads
        return (self.cycle == cycle - 1 and rs.route is self.route and rs.run_on is self.run_on and not rs.entered
                and not any(rs.released) and reads.sections.isdisjoint(changes.tracks)
                and reads.turnouts.isdisjoint(changes.turnouts) and reads.signals.isdisjoint(changes.signals)
                and reads.doors.isdisjoint(changes.doors))


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

    def move_timed_out(self, now: float, timeout_s: float) -> bool:
        """A move under way for longer than ``timeout_s`` (13 s + 3 s) without its indication."""
        return self.move_started is not None and now - self.move_started > timeout_s

    def squeeze_due(self, now: float, squeeze_s: float) -> bool:
        """Without indication for ``squeeze_s`` (the squeeze alarm, 挤岔), counted from the start if never seen."""
        since = self.no_indication_since if self.no_indication_since is not None else 0.0
        return now - since >= squeeze_s


@dataclass
class SignalState:
    """What the interlocking remembers of one signal (its aspect is in the outputs, its route in ``by_signal``)."""

    id: str
    red_dark: bool = False  # the stop lamp is dark (both filaments): red lamp transfer to the signal in rear

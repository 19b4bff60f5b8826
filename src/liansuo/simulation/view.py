"""The query API: what the trains, the console and every other front end read of the interlocking, as typed records.

The interlocking's inner state (route states, the lock ledger, turnout supervision, alarms) is read here and
nowhere else in the world or above it, so a change inside the interlocking is adapted in this one module. Its relay
interface (:class:`~interlocking.io.RelayBoard` in, :class:`~interlocking.io.Outputs` out) is the contract with the
field and is handed on as it is.

Records are frozen: each is the state of one element at the moment it was asked for. :class:`InterlockingView` is the
live reader the world keeps (``World.view``), renewed when the interlocking restarts. A question about an id the
station does not have raises :class:`~simulation.unknown.UnknownId` (a ``KeyError``) naming the kind, the id and the
closest ids; a known element in its rest state answers as such ('' aspect, route 'released', no cab code).
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence
from dataclasses import dataclass

from liansuo.interlocking.cbi import Interlocking
from liansuo.interlocking.io import Event, Outputs, RelayBoard
from liansuo.interlocking.locks import Hold
from liansuo.interlocking.state import RouteStage, RouteState
from liansuo.simulation.unknown import require

# alarm kinds of the interlocking that concern a signal (the console marks its name)
SIGNAL_ALARMS = frozenset({"closed", "lamp", "red", "filament", "flasher"})


@dataclass(frozen=True)
class RouteView:
    """A route the interlocking holds (selected, locked, open, in use or counting down a release)."""

    id: str
    signal: str
    kind: str  # "train" or "shunt"
    state: str  # setting, locked, open, guide, closed, in_use, time_release: the words of 'expect route'
    sections: tuple[str, ...]  # the sections it locks, with those it runs on over
    guide: bool  # showing the guide aspect (HB, 引导)
    release_at: float | None  # when a manual time release (总人解) or fault-release delay completes


@dataclass(frozen=True)
class SignalView:
    id: str
    aspect: str  # the commanded aspect code (L, U, H, B, A ...), '' if none
    route: str | None  # the route whose signal this is, while one is set
    closed: bool  # closed abnormally (the reason is in the alarm)
    lamp_dark: bool  # a lamp of the commanded aspect is dark
    red_dark: bool  # the stop lamp is dark (both filaments)
    filament: bool  # a main filament broken, the lamp on its backup
    flasher: bool  # the USU flasher failed

    @property
    def alarmed(self) -> bool:
        return self.closed or self.lamp_dark or self.red_dark or self.filament or self.flasher


@dataclass(frozen=True)
class TurnoutView:
    id: str
    position: str | None  # indicated position, None without indication
    locked: bool  # may not move: a route, overlap, single lock, guide total lock, power-up, or a locked section
    why: str  # why it may not move, in a signaller's words ('' when it may)
    mark: str  # what the console marks: 'blocked' (单封), 'locked' (单锁), 'guide' (引导总锁闭) or ''
    moving: bool  # being driven

    @property
    def indicated(self) -> bool:
        return self.position is not None


@dataclass(frozen=True)
class SectionView:
    id: str
    occupied: bool  # its track relay is down (a train, a fault, or nothing reported yet)
    locked: bool  # locked by a route, an overlap, a fouling check or the power-up lock

    @property
    def state(self) -> str:
        """'occupied', 'locked' or 'free', as the console paints it and 'expect section' checks it."""
        return "occupied" if self.occupied else "locked" if self.locked else "free"


@dataclass(frozen=True)
class AlarmView:
    """An active alarm, of the interlocking or of the world (a derailment, a turnout squeezed by a train)."""

    key: str  # what acknowledges it
    kind: str  # closed, lamp, red, filament, flasher, move, squeeze, spad, ... or 'world'
    element: str  # the signal or turnout it concerns ('' for the world's)
    text: str
    t: float | None  # when it was raised; None where the world keeps no time


@dataclass(frozen=True)
class CabView:
    """A train's cab signal (机车信号): ``state`` none (no code to read), code, lost (掉码, under the carrier's
    minimum current) or wrong-carrier (串码, in a long dead zone), the section under the leading wheelset, the
    low-frequency code and carrier read, the code current (mA) where the ZPW-2000A model gives one, and whether the
    ATP is braking the train (an emergency stop from ``atp`` until released)."""

    state: str = "none"
    section: str | None = None
    code: str | None = None
    carrier: str | None = None
    level_mA: float | None = None
    atp_braking: bool = False


NO_CAB = CabView()


@dataclass(frozen=True)
class TrainView:
    """What a front end shows of a train: its name, the sections its wheelsets shunt, speed and direction, and where
    its head is. A train whose head has run out over the station's boundary has no position in the station: it is
    ``leaving`` while its rear is still in, then ``left`` (it is then no longer among the trains in the yard)."""

    name: str
    sections: tuple[str, ...]  # () once it has left
    speed_kmh: float
    direction: str  # "down" or "up"
    mode: str  # "manual", "signal", "auto"
    head_track: str | None  # the track of the leading wheelset; None once the head is beyond the boundary
    head_m: float | None  # position of the leading wheelset along the line; None once beyond the boundary
    state: str = "running"  # running, derailed, leaving (head beyond the boundary, rear still in), left
    cab: CabView = NO_CAB  # the cab signal

    @property
    def left(self) -> bool:
        """The whole train has run out of the station."""
        return self.state == "left"


class InterlockingView:
    """Typed questions to one interlocking."""

    def __init__(self, interlocking: Interlocking) -> None:
        self._il = interlocking
        core = interlocking.core
        st = core.station
        self._station = st.id
        self._signals = core.signals
        self._turnouts = core.turnouts
        self._sections = st.sections
        self._routes = core.table.routes
        self._lines = frozenset(lk.id for lk in st.model.links)
        self._doors = frozenset(k for keys in core.platform_doors.values() for k in keys)

    # ---- the relay interface ----------------------------------------------------------------------------------
    @property
    def inputs(self) -> RelayBoard:
        """The relay states the field reports (what the interlocking sees)."""
        return self._il.board

    @property
    def outputs(self) -> Outputs:
        """What the interlocking drives: turnouts, aspects, doors, cab codes, line pulses."""
        return self._il.out

    # ---- signals ------------------------------------------------------------------------------------------------
    def aspect(self, signal: str) -> str:
        """The signal's commanded aspect code ('' while it commands none)."""
        require("signal", signal, self._signals, self._station)
        return self._il.out.signals.get(signal, "")

    def aspects(self) -> Mapping[str, str]:
        """Every signal's commanded aspect (a live mapping: it follows the interlocking)."""
        return self._il.out.signals

    def signal(self, signal: str) -> SignalView:
        require("signal", signal, self._signals, self._station)
        return self._signal(signal, self._signal_alarms().get(signal, set()))

    def signals(self) -> tuple[SignalView, ...]:
        """Every signal, in station order."""
        alarms = self._signal_alarms()
        return tuple(self._signal(s, alarms.get(s, set())) for s in self._il.core.signals)

    def _signal(self, signal: str, kinds: set[str]) -> SignalView:
        return SignalView(signal, self.aspect(signal), self._il.by_signal.get(signal), "closed" in kinds,
                          "lamp" in kinds, "red" in kinds, "filament" in kinds, "flasher" in kinds)

    def _signal_alarms(self) -> dict[str, set[str]]:
        out: dict[str, set[str]] = {}
        for a in self.alarms():
            if a.kind in SIGNAL_ALARMS:
                out.setdefault(a.element, set()).add(a.kind)
        return out

    # ---- routes -------------------------------------------------------------------------------------------------
    def route(self, route_id: str) -> RouteView | None:
        """The route of the table with this id, None while the interlocking does not hold it."""
        require("route", route_id, self._routes, self._station)
        rs = self._il.routes.get(route_id)
        return None if rs is None else _route(rs)

    def route_of(self, signal: str) -> RouteView | None:
        """The route set from ``signal``, if any."""
        require("signal", signal, self._signals, self._station)
        rid = self._il.by_signal.get(signal)
        return None if rid is None else self.route(rid)

    def routes(self) -> tuple[RouteView, ...]:
        """Every route the interlocking holds, in order of selection."""
        return tuple(_route(rs) for rs in self._il.routes.values())

    def waiting(self, signal: str) -> str:
        """Why ``signal`` is at stop over the route set from it, in a signaller's words: the first of the
        interlocking's opening conditions not met ('block line XL has not been accepted ... (64D: idle)', 'screen
        doors P3:right are not closed and locked ...', 'turnout 5 is moving: ...'); '' with no route set, with
        the signal open, or once a train is in the route."""
        require("signal", signal, self._signals, self._station)
        rid = self._il.by_signal.get(signal)
        rs = None if rid is None else self._il.routes.get(rid)
        return "" if rs is None else self._il.core.waiting(rs)

    def route_state(self, route_id: str) -> str:
        """The route's state word, 'released' while the interlocking does not hold it."""
        require("route", route_id, self._routes, self._station)
        rs = self._il.routes.get(route_id)
        return "released" if rs is None else rs.stage.value

    # ---- turnouts and sections ----------------------------------------------------------------------------------
    def turnout(self, turnout: str) -> TurnoutView:
        require("turnout", turnout, self._turnouts, self._station)
        il = self._il
        locks = il.locks.turnout_locks(turnout)
        holds = {lk.hold for lk, _, _ in locks}
        mark = ("blocked" if turnout in il.locks.blocked else "locked" if Hold.single in holds
                else "guide" if Hold.guide in holds else "")
        return TurnoutView(turnout, il.board.indication(turnout), bool(locks),
                           il.locks.why_turnout(turnout) if locks else "", mark, turnout in il.core.moving)

    def driving(self) -> bool:
        """The interlocking drives a turnout now or has moves waiting in its queue (a move ends when the turnout
        indicates its position, or fails at the rules' ``turnout_timeout_s``)."""
        core = self._il.core
        return bool(core.moving or core.queue)

    def turnout_locked(self, turnout: str) -> bool:
        """``turnout(turnout).locked`` alone: cheaper, for readers that ask it of many turnouts every cycle."""
        require("turnout", turnout, self._turnouts, self._station)
        return self._il.locks.turnout_locked(turnout)

    def turnouts(self) -> tuple[TurnoutView, ...]:
        """Every turnout, in station order."""
        return tuple(self.turnout(t) for t in self._il.core.turnouts)

    def section(self, section: str) -> SectionView:
        require("section", section, self._sections, self._station)
        return SectionView(section, not self._il.board.clear(section), self._il.locks.section_locked(section))

    def sections(self, ids: Sequence[str]) -> tuple[SectionView, ...]:
        return tuple(self.section(s) for s in ids)

    # ---- doors, lines, codes ------------------------------------------------------------------------------------
    def doors_safe(self, key: str) -> bool:
        """The screen doors ``platform:side`` are proven closed and locked (PDKJ), or bypassed (PDQCJ)."""
        require("platform door", key, self._doors, self._station)
        return self._il.board.doors_safe(key)

    def line_outbound(self, link: str) -> bool:
        """The direction circuit of an automatic line is set for our departures (改方)."""
        require("line", link, self._lines, self._station)
        return self._il.out.line_direction.get(link) == "outbound"

    def block_line(self, link: str) -> str | None:
        """The state of a 64D block line (idle, requested, ...) or of a station-block line (idle, outbound,
        departed, inbound, arriving); None for an automatic-block line, which has neither."""
        require("line", link, self._lines, self._station)
        bl = self._il.core.links.get(link)
        if bl is not None:
            return bl.state.value
        sl = self._il.core.station_links.get(link)
        return None if sl is None else sl.state.value

    def cab_code(self, section: str) -> str | None:
        """The low-frequency code a coded section carries, None when it carries none."""
        require("section", section, self._sections, self._station)
        return self._il.out.cab_codes.get(section)

    # ---- alarms and events --------------------------------------------------------------------------------------
    def alarms(self) -> tuple[AlarmView, ...]:
        """The interlocking's active alarms, oldest first."""
        return tuple(AlarmView(a.key, a.kind, a.element, a.text, a.t) for a in self._il.alarms.values())

    def events(self) -> Sequence[Event]:
        """The interlocking's event log (a live sequence, newest last)."""
        return self._il.events


def _route(rs: RouteState) -> RouteView:
    r = rs.route
    return RouteView(r.id, r.signal, r.kind, rs.stage.value, rs.sections, rs.stage is RouteStage.guide,
                     rs.release_at)

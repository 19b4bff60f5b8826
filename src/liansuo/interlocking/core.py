"""The interlocking's core: its state, its inputs, its turnouts and the conditions a signal needs.

The core reads the relay board (inputs that changed since the last cycle), supervises the turnouts and their move
queue, supervises lamps and the flasher, and answers what keeps a signal closed (:meth:`Core.open_blocker`). It never
reads the wall clock (the cycle is given the simulated time) and never sees trains: only track relays. Routes move
through their stages in :mod:`.lifecycle`; every lock is in the ledger (:mod:`.locks`); :class:`~.cbi.Interlocking`
runs the cycle. Work per cycle is proportional to what is in progress (active routes, moving turnouts, changed
inputs), not to the size of the station.
"""

from __future__ import annotations

from collections import deque
from collections.abc import Iterable

from liansuo.interlocking.aspects import downgrade, is_open, onward_allows_usu, select_aspect
from liansuo.interlocking.autoblock import cab_codes
from liansuo.interlocking.block64d import BlockLink, line_pulses_in, line_tracks_changed
from liansuo.interlocking.index import Index, guide_area
from liansuo.interlocking.io import MAX_EVENTS, Alarm, Changes, DoorCommand, Event, Outputs, RelayBoard
from liansuo.interlocking.locks import Hold, LockLedger
from liansuo.interlocking.state import GuideOnly, RouteStage, RouteState, SignalState, TurnoutState
from liansuo.interlocking.stationblock import StationBlockLink
from liansuo.interlocking.table.route import InterlockingTable, Route
from liansuo.rules import RuleSet, load_rules
from liansuo.stations.station import Station


class Core:
    """One station's interlocking state. ``locked_at_start``: the state after power-up (上电): every section locked
    and every signal closed until the operator's power-up release."""

    def __init__(self, table: InterlockingTable, rules: RuleSet | None = None, cycle_s: float = 0.25, *,
                 locked_at_start: bool = False, now: float = 0.0) -> None:
        self.table = table
        self.station: Station = table.station
        self.rules = rules or load_rules()
        self.cycle_s = cycle_s
        self.board = RelayBoard()
        self.out = Outputs()
        self.now = now  # moved only by tick()
        self.cycles = 0
        # the relays that changed, as the last cycle took them: what the routes' memos (lifecycle) are checked against
        self.changes = Changes(set(), set(), set(), set(), {}, False)
        self.routes: dict[str, RouteState] = {}  # active routes in order of selection
        self.by_signal: dict[str, str] = {}
        st = self.station
        index = self.index = st.derived(Index)  # read only: shared by every core of the station
        self.locks = LockLedger(st.turnout_section, st.pairs)
        self.overlap_pending: dict[str, float | None] = {}  # route -> when its overlap releases (after the route)
        self.turnouts = {t: TurnoutState(t, section, trailable) for t, section, trailable in index.turnouts}
        self.signals = {sig: SignalState(sig) for sig in index.stop}
        for sig, stop in index.stop.items():
            self.out.set_aspect(sig, stop)
        self.links = {link: BlockLink(link, section) for link, section in index.links}
        self.auto_links = index.auto_links
        self.station_links = {link: StationBlockLink(link, sections) for link, sections in index.station_links}
        self.axle_resets_used = 0  # the sealed axle-counter reset button's counter (计轴复零)
        self.line_out: set[str] = set()  # automatic lines whose direction is changed for our departures (改方)
        self.queue: deque[str] = deque()
        self.moving: set[str] = set()
        self.no_indication: set[str] = set(st.turnouts)  # fail-safe: nothing reported yet
        self.usu_failed: set[str] = set()  # flasher check failed while showing USU: UU until the route releases
        self.guide_only: dict[str, GuideOnly] = {}  # guide aspect without a route (throat under guide total lock)
        self.events: deque[Event] = deque(maxlen=MAX_EVENTS)
        self.logged = 0  # events logged so far (the deque keeps the last MAX_EVENTS)
        self.alarms: dict[str, Alarm] = {}
        self.entry_section = index.entry_section
        self.signal_by_entry = index.signal_by_entry
        self.platform_doors = index.platform_doors
        self._guide_areas: dict[str, tuple[frozenset[str], frozenset[str]]] = {}  # home signal -> guide_area
        self._door_sections: dict[str, tuple[str, ...]] = {}  # route id -> door_sections(route)
        self.autoblock = index.autoblock
        self.codes_dirty = True
        self.blocks_dirty = False  # the automatic block signals must be evaluated again (a line's direction changed)
        for key in (k for keys in self.platform_doors.values() for k in keys):
            self.out.doors.setdefault(key, DoorCommand())
        self.power_up_locked = locked_at_start
        if locked_at_start:
            for name in index.interlocked:
                self.locks.lock_section(name, Hold.power_up)
            self.event("power", "interlocking started: every section locked until the power-up release (上电解锁)")

    # ---- bookkeeping --------------------------------------------------------------------------------------------
    def event(self, kind: str, text: str) -> None:
        self.events.append(Event(self.now, kind, text))
        self.logged += 1

    def alarm(self, kind: str, element: str, text: str, *, detail: str = "") -> None:
        """Raise an alarm of ``kind`` (closed, lamp, red, filament, flasher, move, squeeze, spad) on a signal or
        turnout; ``detail`` tells apart alarms of one kind on one element (the aspect of a lamp alarm, the time of a
        SPAD). Raised once: an alarm already active stays as it is."""
        key = Alarm.key_of(kind, element, detail)
        if key not in self.alarms:
            self.alarms[key] = Alarm(kind, element, self.now, text, detail)
            self.event("alarm", text)

    def clear_alarm(self, kind: str, element: str) -> None:
        key = Alarm.key_of(kind, element)
        self.alarms.pop(key, None)

    def clear(self, section: str) -> bool:
        return self.board.clear(section)

    # ---- what the outputs after the routes follow ---------------------------------------------------------------
    def routes_changed(self) -> None:
        """A route was selected, moved stage, released a section or ended, or a signal it gives closed: the cab
        codes are worked out again at the end of the cycle (``give_outputs``)."""
        self.codes_dirty = True

    def line_direction_changed(self) -> None:
        """A line's running direction changed (改方): the cab codes and the automatic block signals follow."""
        self.codes_dirty = self.blocks_dirty = True

    # ---- the cycle: inputs before the routes, outputs after them ----------------------------------------------
    def tick(self, t: float, cycles: int = 1) -> None:
        """The clock, and the one place it moves: ``cycles`` more cycles have run, the last at ``t``."""
        self.now = t
        self.cycles += cycles

    def take_inputs(self, t: float) -> Changes:
        self.tick(t)
        # aspects set since the last cycle's chain update (by operator commands: cancel, reopen, guide) still have to
        # reach the automatic block signals in rear
        commanded = bool(self.out.changed_signals)
        self.out.changed_signals.clear()  # from here on: what this cycle changed
        self.out.changed_turnouts.clear()
        self.changes = Changes(*self.board.take_changes(), commanded)
        return self.changes

    def apply_inputs(self, ch: Changes) -> None:
        """The 64D and station-block lines, turnout indications, lamp proving and the turnout move queue."""
        for link, msgs in ch.pulses.items():
            line_pulses_in(self.links, link, msgs, self.event)
        if ch.tracks and self.links:
            line_tracks_changed(self.links, ch.tracks, self.clear, self.send, self.event)
        for sl in self.station_links.values():
            departing = any(rs.route.exit_link == sl.id and rs.stage is not RouteStage.setting
                            for rs in self.routes.values())
            sl.step(departing, self.clear, ch.pulses.get(sl.id, ()), self.send, self.event)
        for t_id in ch.turnouts:
            if self.board.indication(t_id) is None:
                if t_id not in self.no_indication:
                    self.no_indication.add(t_id)
                    self.turnouts[t_id].no_indication_since = self.now
            else:
                self.no_indication.discard(t_id)
                ts = self.turnouts[t_id]
                ts.no_indication_since = None
                if ts.squeeze_alarmed:
                    ts.squeeze_alarmed = False
                    self.clear_alarm("squeeze", t_id)
        for sig in ch.signals:
            self._lamp_alarms(sig)
        self._supervise_turnouts()

    def give_outputs(self, ch: Changes) -> Outputs:
        """The automatic block signals and the cab codes, after the routes have moved."""
        if self.autoblock.signals and (ch.tracks or ch.signals or ch.commanded or self.out.changed_signals
                                       or self.blocks_dirty):
            self.blocks_dirty = False
            dark = {s for s, ss in self.signals.items() if ss.red_dark}
            self.autoblock.update(self.out, self.clear, self.proven, dark, self.line_out)
        if self.codes_dirty or self.out.changed_signals:
            self.codes_dirty = False
            self.out.cab_codes = cab_codes(self.station, self.rules, self.routes.values(), self.out.signals)
        return self.out

    def _lamp_alarms(self, signal: str) -> None:
        """Flasher (SNJ/SNJJ), filament, lamp and red-lamp supervision of one signal whose proving relays changed."""
        usu, stop, stop_lamp = self.index.lamp_check[signal]
        if usu:
            if self.board.flasher_ok(signal):
                if signal not in self.usu_failed:
                    self.clear_alarm("flasher", signal)
            else:
                self.usu_failed.add(signal)
                self.alarm("flasher", signal, f"signal {signal}: USU flasher failed (SNJ/SNJJ down); USU "
                           "degrades to UU")
        if self.board.filament_alarm.get(signal, False):
            self.alarm("filament", signal, f"signal {signal}: main filament broken (主丝断丝), lamp on its backup "
                       "filament or dark")
        else:
            self.clear_alarm("filament", signal)
        for key, alarm in list(self.alarms.items()):  # an aspect's lamps all proven again: its lamp alarm is over
            if alarm.kind == "lamp" and alarm.element == signal and not self._dark(signal, alarm.detail):
                del self.alarms[key]
        if stop_lamp:  # the red (or blue) lamp is named as the stop aspect it shows
            dark = not self.board.lamp_ok(signal, stop)
            if dark != self.signals[signal].red_dark:
                self.signals[signal].red_dark = dark
                if dark:
                    self.alarm("red", signal, f"signal {signal}: {stop} lamp dark (both filaments)")
                else:
                    self.clear_alarm("red", signal)

    # ---- turnouts -------------------------------------------------------------------------------------------
    def _supervise_turnouts(self) -> None:
        # in the order of their ids, not of a set's hashing, so that the events and alarms of one cycle come in the
        # same order in every run (a set of strings iterates differently from one process to the next)
        for t_id in sorted(self.moving):
            ts = self.turnouts[t_id]
            if not self.clear(ts.section) and self.board.indication(t_id) != ts.target:
                # a movement entered the turnout's section during the move: stop driving it, so the machine is
                # never started again under the movement (the turnout stays without indication: fail-safe)
                self.moving.discard(t_id)
                self.out.drive(t_id, None)
                self.alarm("move", t_id, f"turnout {t_id}: drive to {ts.target} stopped, section {ts.section} "
                           "became occupied during the move")
                ts.target = None
                ts.move_started = None
                continue
            if ts.target is not None and self.board.indication(t_id) == ts.target:
                self.moving.discard(t_id)
                self.out.drive(t_id, None)
                self.event("turnout", f"turnout {t_id} in {ts.target}")
                ts.target = None
                ts.move_started = None
                self.clear_alarm("move", t_id)
            elif ts.move_timed_out(self.now, self.rules.turnout_timeout_s):
                self.moving.discard(t_id)
                self.out.drive(t_id, None)
                self.alarm("move", t_id, f"turnout {t_id} did not reach {ts.target} within "
                           f"{self.rules.turnout_timeout_s:g} s (no indication)")
                ts.target = None
                ts.move_started = None
        while self.queue and len(self.moving) < self.rules.turnout_concurrency:
            t_id = self.queue.popleft()
            ts = self.turnouts[t_id]
            ts.queued = False
            if ts.target is None:
                continue
            if self.board.indication(t_id) == ts.target:
                ts.target = None
                continue
            if not self.clear(ts.section):
                # a movement reached the turnout while its move waited in the queue: never drive under it
                self.event("turnout", f"turnout {t_id} not moved to {ts.target}: section {ts.section} is occupied")
                ts.target = None
                continue
            self.moving.add(t_id)
            ts.move_started = self.now
            self.out.drive(t_id, ts.target)
        for ts in self.squeeze_watched():
            if ts.squeeze_due(self.now, self.rules.squeeze_alarm_s):
                ts.squeeze_alarmed = True
                self.alarm("squeeze", ts.id, f"turnout {ts.id} squeezed (挤岔): no indication for "
                           f"{self.rules.squeeze_alarm_s:g} s")

    def squeeze_watched(self) -> list[TurnoutState]:
        """Turnouts without indication that the squeeze alarm watches: trailable, not moving or waiting to move,
        not alarmed yet."""
        out = []
        for t_id in sorted(self.no_indication):  # the alarms in the same order in every run
            ts = self.turnouts[t_id]
            if not (t_id in self.moving or ts.queued or ts.squeeze_alarmed or not ts.trailable):
                out.append(ts)
        return out

    def request_move(self, turnout: str, position: str) -> None:
        """Queue a move of ``turnout`` (and its crossover partner) to ``position``."""
        for t_id in self.pair_members(turnout):
            ts = self.turnouts[t_id]
            if self.board.indication(t_id) == position and t_id not in self.moving:
                continue
            ts.target = position
            if t_id in self.moving:
                ts.move_started = self.now
                self.out.drive(t_id, position)
            elif not ts.queued:
                ts.queued = True
                self.queue.append(t_id)

    def pair_members(self, turnout: str) -> list[str]:
        pair = self.station.turnouts[turnout].pair
        return list(self.station.pairs[pair]) if pair else [turnout]

    # ---- what a signal needs (开放信号的条件) -------------------------------------------------------------------
    def checked_sections(self, rs: RouteState) -> tuple[str, ...]:
        """Every section that must be clear for the signal: route and run-on, fouling, overlap."""
        r = rs.route
        return rs.sections + tuple(f.section for f in r.fouling) + r.overlap_sections

    def open_blocker(self, rs: RouteState, *, guide: bool = False, sections: bool = True) -> str:
        """Why the signal of ``rs`` may not open (or stay open); '' when every condition holds. ``sections=False``
        excuses the occupied stretch of the route's sections from its first one on (a shunting consist passing its
        open signal occupies them), but no section beyond a clear one, nor the fouling and overlap sections."""
        r = rs.route
        if any(rs.released):
            released = [s for i, s in enumerate(rs.sections) if rs.released[i]]
            return f"section {released[0]} of route {r.id} has been released: the route is no longer locked"
        if rs.overlap_released and not guide:
            return f"the overlap of route {r.id} has been released: the route is no longer locked"
        own = len(rs.turnouts)  # the route's own turnouts come first and must be locked by it; the overlap's after
        indication, held_by = self.board.indication, self.locks.held_by
        for i, t in enumerate(rs.all_turnouts):
            ind = indication(t.id)
            if ind != t.position:  # a StrEnum: equal to its value
                what = "has no indication" if ind is None else f"is {ind}"
                return f"turnout {t.id} {what}, the route needs it {t.position.value}"
            if i < own and not held_by(t.id, rs.id):
                return f"turnout {t.id} is not locked in route {r.id}"
        if not guide:
            skip = 0
            if not sections:
                while skip < len(rs.sections) and not self.clear(rs.sections[skip]):
                    skip += 1
            clear = self.board.clear
            for s in self.checked_sections(rs)[skip:]:
                if not clear(s):
                    return f"section {s} is occupied"
        blocker = self.liaison_blocker(r)
        if blocker:
            return blocker
        aspect = self.wanted_aspect(rs) if not guide else self.rules.aspects.guide
        if not is_open(aspect):
            return self._why_closed(rs)
        shown = self.proven(r.signal, aspect)
        if not is_open(shown) or (guide and shown != self.rules.aspects.guide):
            return f"a lamp of signal {r.signal} for {aspect} is dark"
        return ""

    def waiting(self, rs: RouteState) -> str:
        """Why the signal of a route the interlocking holds is at stop, in a signaller's words: the first condition
        not met (:meth:`open_blocker`'s, in its order), or what the route waits for before those are judged. '' when
        the signal is open or the route is past waiting (in use, releasing). Reads only: nothing changes."""
        stage, signal = rs.stage, rs.route.signal
        if stage is RouteStage.setting:
            for t in rs.all_turnouts:
                ind = self.board.indication(t.id)
                if ind != t.position:
                    doing = "is moving" if t.id in self.moving else "has no indication" if ind is None else "is"
                    return f"turnout {t.id} {doing}{f' {ind}' if doing == 'is' else ''}: the route needs it " \
                        f"{t.position.value}"
            return ""
        if stage is RouteStage.locked:
            return self.open_blocker(rs)
        if stage is RouteStage.closed:
            why = self.open_blocker(rs)
            return why or f"signal {signal} was closed: the conditions are back, reopen it (重开, 'reopen {signal}')"
        return ""

    def liaison_blocker(self, r: Route) -> str:
        why = self.line_against(r.signal)
        if why:
            return why
        if r.exit_link in self.links:
            link = self.links[r.exit_link]
            if link.state.value != "permitted":
                return f"block line {link.id} has not been accepted by the neighbour station (64D: {link.state.value})"
            if not self.clear(link.departure_section):
                return f"departure section {link.departure_section} is occupied"
        if r.exit_link in self.station_links:
            why = self.station_links[r.exit_link].blocker(self.clear)
            if why:
                return why
        if r.exit_link in self.auto_links:
            why = self.against_running(r.exit_link)
            if why:
                return why
            if self._clear_blocks(r.exit_link) == 0:
                return f"departure section {self.auto_links[r.exit_link][0]} is occupied"
        occupied = [sec for sec in r.line_sections if not self.clear(sec)]
        if occupied:
            return f"line section {occupied[0]} is occupied (no block system is described for this line)"
        why = self.doors_blocker(self.door_sections(r))
        if why:
            return why
        if r.end_signal is not None and self.signals[r.end_signal].red_dark:
            return f"the red lamp of {r.end_signal} is dark (红灯转移): {r.signal} must stay closed"
        return ""

    def against_running(self, link: str) -> str:
        """Why a departure onto automatic line ``link`` may not go: it runs towards this station and its direction
        has not been changed (改方); '' when it may."""
        if self.station.link_running(link) != "inbound" or link in self.line_out:
            return ""
        lk = next(x for x in self.station.model.links if x.id == link)
        if not lk.bidirectional:
            return (f"line {link} runs towards this station and is not bidirectional: no departure against its "
                    "running direction")
        return (f"line {link} runs towards this station: change its direction for departures first (改方, "
                f"'line-direction {link} out')")

    def doors_blocker(self, sections: Iterable[str]) -> str:
        """Why screen doors at these platform tracks keep a signal closed; '' when none does."""
        for sec in sections:
            for key in self.platform_doors.get(sec, ()):
                if not self.board.doors_safe(key):
                    return f"screen doors {key} are not closed and locked (and not bypassed)"
        return ""

    def guide_area(self, signal: str) -> tuple[frozenset[str], frozenset[str]]:
        """Where a guided train may go from ``signal`` under guide total lock, where the interlocking does not know
        the way (a turnout may have been trailed through): the sections of the throat the signal leads into, and
        the tracks that border it (station tracks, spurs, the lines), whichever way its turnouts lie."""
        area = self._guide_areas.get(signal)
        if area is None:
            area = self._guide_areas[signal] = guide_area(self.station, signal)
        return area

    def guide_only_doors(self, signal: str) -> list[str]:
        """The platform tracks a guided train may reach from ``signal`` under guide total lock: every platform track
        that borders the throat the signal leads into (:meth:`guide_area`)."""
        return sorted(s for s in self.guide_area(signal)[1] if s in self.platform_doors)

    def guide_only_meets(self, signal: str, sections: Iterable[str], leads_into: str | None) -> bool:
        """Would a route over ``sections`` (entering ``leads_into`` at sight) run into the train guided from
        ``signal`` under guide total lock: into the throat it is guided over, or onto a track that borders it."""
        throat, border = self.guide_area(signal)
        return not throat.isdisjoint(sections) or not border.isdisjoint(sections) or leads_into in border

    def line_against(self, signal: str) -> str:
        """Why no movement may be received past ``signal``: the line it comes from has been set for departures
        from this station (改方); '' when none is."""
        link = self.index.receives_from.get(signal)
        if link is not None and link in self.line_out:
            return (f"line {link} is set for departures from this station (改方): signal {signal} receives no "
                    f"train from it; 'line-direction {link} in' first")
        return ""

    def door_sections(self, r: Route) -> tuple[str, ...]:
        """The platform tracks with screen doors the route runs over or starts from (the station's, so kept)."""
        done = self._door_sections.get(r.id)
        if done is not None:
            return done
        out = [s for s in r.sections if s in self.platform_doors]
        rear = self.station.signal_rear_track(r.signal)
        if rear is not None:
            sec = self.station.tracks[rear].section
            if sec in self.platform_doors and sec not in out:
                out.append(sec)
        self._door_sections[r.id] = tuple(out)
        return self._door_sections[r.id]

    def _clear_blocks(self, link: str) -> int:
        """Clear block sections ahead of a departure, as many as the automatic block's aspects can tell apart."""
        sections = self.auto_links[link]
        most = len(self.rules.aspects.automatic_block) - 1
        if link in self.line_out:  # worked against its running direction: the whole line is one block
            return most if all(self.clear(s) for s in sections) else 0
        n = 0
        for s in sections[:most]:
            if not self.clear(s):
                break
            n += 1
        return n

    def _why_closed(self, rs: RouteState) -> str:
        r = rs.route
        if r.category == "departure" and r.exit_link in self.auto_links:
            return f"no clear block section beyond {r.signal}"
        return f"signal {r.signal} has no proceed aspect for route {r.id}"

    def wanted_aspect(self, rs: RouteState) -> str:
        r = rs.route
        next_aspect = self.out.signals.get(r.end_signal, "") if r.end_signal else ""
        clear_blocks = self._clear_blocks(r.exit_link) if r.exit_link in self.auto_links else None
        onward = self.route_of(r.end_signal) if r.end_signal else None
        usu_ready = (bool(r.end_signal) and is_open(next_aspect) and self.board.flasher_ok(r.signal)
                     and r.signal not in self.usu_failed and onward is not None
                     and onward_allows_usu(self.station, onward.turnouts, self.rules))
        return select_aspect(self.station, r, next_aspect, clear_blocks, usu_ready, self.rules)

    def route_of(self, signal: str) -> RouteState | None:
        rid = self.by_signal.get(signal)
        return self.routes.get(rid) if rid else None

    def _dark(self, signal: str, aspect: str) -> set[str]:
        """The lamps of ``aspect`` on ``signal`` not proven (and ``flasher`` for a flashing aspect whose flasher
        failed): what keeps the aspect from showing."""
        dark = {lamp for lamp in self.rules.lamps.get(aspect, []) if not self.board.lamp_ok(signal, lamp)}
        if aspect in self.rules.aspects.flashing and not self.board.flasher_ok(signal):
            dark.add("flasher")
        return dark

    def proven(self, signal: str, aspect: str) -> str:
        """The aspect after lamp proving: never more permissive than ``aspect``. A lamp alarm raised here ends when
        the signal's lamp proving changes and the aspect's lamps are all proven again (:meth:`_lamp_alarms`)."""
        dark = self._dark(signal, aspect)
        if not dark:
            return aspect
        shown = downgrade(aspect, dark, self.rules)
        self.alarm("lamp", signal, f"signal {signal}: lamp(s) {', '.join(sorted(dark))} dark for {aspect}; showing "
                   f"{shown}", detail=aspect)
        return shown

    def send(self, link: str, pulse: str) -> None:
        self.out.line_out.setdefault(link, set()).add(pulse)

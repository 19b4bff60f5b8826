"""Operator commands of the CBI console (操作表示机). Each returns a :class:`Result`; a refusal says why in a
signaller's terms. A command checks what it may do on the interlocking's core and changes a route's stage only
through the route lifecycle (:mod:`.lifecycle`); the routes then progress cycle by cycle."""

from __future__ import annotations

from liansuo.interlocking.aspects import stop_aspect
from liansuo.interlocking.core import INTERLOCKED, Core
from liansuo.interlocking.io import Result
from liansuo.interlocking.lifecycle import RouteLifecycle
from liansuo.interlocking.locks import Hold
from liansuo.interlocking.state import RouteStage, RouteState
from liansuo.interlocking.table.route import Condition, Kind, Route, RunOn
from liansuo.stations.schema import Button, SignalKind

_KIND_WORD = {"train": "train", "shunt": "shunting"}


class Operator:
    """The operator's commands on one interlocking: its ``core`` (state and conditions) and its route
    ``lifecycle``."""

    def __init__(self, core: Core, lifecycle: RouteLifecycle) -> None:
        self.il = core
        self.lifecycle = lifecycle

    # ---- route setting ----------------------------------------------------------------------------------------
    def set_route(self, kind: Kind, start: str, end: str, via: tuple[str, ...] = ()) -> Result:
        """Select a route by its start, optional variant and end buttons (列车/调车进路); an overlap's end button
        pressed after the end button chooses that alternative overlap (变更延续进路)."""
        st = self.il.station
        known = set(st.signals) | set(st.buttons)
        for b in (start, end, *via):
            if b not in known:
                return Result.refuse(f"there is no signal or button '{b}' at {st.id}")
        if start not in st.signals:
            return Result.refuse(f"'{start}' cannot start a route: routes start at a signal's button")
        button = Button.train if kind == "train" else Button.shunt
        if button not in st.signals[start].buttons:
            other = "shunt" if kind == "train" else "route"
            return Result.refuse(f"signal {start} has no {_KIND_WORD[kind]} button; use '{other} {start} ...'")
        r, why = self._find(kind, start, end, via)
        if r is None:
            return Result.refuse(why)
        run_on, why = self.choose_run_on(r)
        if not why:
            why = self.route_blocker(r, run_on)
        if why:
            return Result.refuse(why)
        self.lifecycle.select(RouteState(r, RouteStage.setting, self.il.now, run_on=run_on))
        return Result.accept(f"route {r.id} selected")

    def _find(self, kind: Kind, start: str, end: str, via: tuple[str, ...]) -> tuple[Route | None, str]:
        """The route the buttons select, or why there is none."""
        r = self.il.table.by_buttons(kind, start, end, via)
        if r is None and via:  # the last button may be an overlap's end button
            r = self.il.table.by_buttons(kind, start, via[-1], via[:-1], overlap=end)
        if r is not None:
            return r, ""
        options = sorted(x.id for x in self.il.table.routes.values() if x.kind == kind and x.start == start)
        return None, (f"no {_KIND_WORD[kind]} route from {start} to {end}" + (" via " + ",".join(via) if via else "")
                      + (f"; routes from {start}: {', '.join(options)}" if options else ""))

    def choose_run_on(self, r: Route) -> tuple[RunOn | None, str]:
        """The way a shunting movement runs on past the end of ``r``, as the turnouts beyond lie; or why it cannot
        be told (a turnout beyond without indication)."""
        if not r.run_on:
            return None, ""
        lies = {t: self.il.board.indication(t) for ro in r.run_on for t, _ in ro.when}
        ro = r.run_on_for(lies)
        if ro is not None:
            return ro, ""
        lost = sorted(t for t, pos in lies.items() if pos is None)
        return None, (f"turnout {lost[0] if lost else '?'} beyond {r.end} has no indication: a shunting movement "
                      f"running on past {r.end} could go either way")

    def route_blocker(self, r: Route, run_on: RunOn | None = None, *, guide: bool = False) -> str:
        """Why ``r`` (running on over ``run_on``) may not be set now; '' when it may. ``guide``: a guide route
        (引导进路锁闭), locked without looking at the occupancy of its sections (a track circuit of it is faulty);
        everything else is checked as for any route."""
        if self.il.power_up_locked:
            return "the station is locked since the interlocking started (上电锁闭): give the power-up release first"
        if r.signal in self.il.by_signal:
            return f"signal {r.signal} already has route {self.il.by_signal[r.signal]} set"
        why = self.il.line_against(r.signal)
        if why:
            return why
        leads_into = run_on.leads_into if run_on else r.leads_into
        for sig in self.il.guide_only:
            if self.il.guide_only_meets(sig, [*r.sections, *(run_on.sections if run_on else ())], leads_into):
                return (f"the guide aspect of {sig} is lit under guide total lock (引导总锁闭): no route into its "
                        "throat or onto a track it leads to until it closes")
        if r.exit_link in self.il.auto_links:
            why = self.il.against_running(r.exit_link)
            if why:
                return why
        for other, rs in self.il.routes.items():
            why = r.conflicts.get(other) or self._conditional(r, rs)
            held = self._still_conflicts(rs, r, run_on) if why else ""
            if held:
                return f"conflicting route {other} is locked ({held})"
        sections = list(r.sections) + (list(run_on.sections) if run_on else []) + list(r.overlap_sections)
        for s in [*sections, *(f.section for f in r.fouling)]:
            for lk in self.il.locks.section_locks(s):
                if lk.hold is Hold.fouling and s not in sections:
                    continue  # several routes may check the same fouling section
                if lk.hold is Hold.overlap and self._continues(lk.holder, r, s):
                    continue  # the onward route of a through movement runs over the overlap (held or timing)
                if lk.hold is Hold.route and self._continues(r.id, self.il.table.routes.get(lk.holder), s):
                    continue  # the departure of a through movement is set first: its route covers our overlap
                if lk.hold is Hold.power_up:
                    return self.route_blocker_power_up(s)
                return f"section {s} is locked {lk.words()}"
            if not guide and not self.il.clear(s):
                return f"section {s} is occupied"
        turnouts = r.all_turnouts + (run_on.turnouts if run_on else ())
        for t in turnouts:
            if t.id in self.il.locks.blocked:
                return f"turnout {t.id} is single-blocked (单封)"
            for member in self.il.pair_members(t.id):
                if self.il.board.indication(member) == t.position.value:
                    continue
                why = self.il.locks.why_turnout(member)
                if why and not self._driven_there(member, t.position.value) and not self._beside_overlap(member, r):
                    return f"{why}; the route needs it {t.position.value}"
                if not self.il.clear(self.il.turnouts[member].section):
                    return f"turnout {member} cannot move: section {self.il.turnouts[member].section} is occupied"
        return ""

    def _driven_there(self, turnout: str, position: str) -> bool:
        """Every lock on ``turnout`` is held by a route (or its overlap) that is driving it to ``position`` itself: a
        compatible route (a through movement over an overlap, say) may then wait for it there."""
        locks = self.il.locks.turnout_locks(turnout)
        for lk, _, partner in locks:
            rs = self.il.routes.get(lk.holder)
            if lk.hold not in (Hold.route, Hold.overlap) or rs is None:
                return False
            wanted = {x.id: x.position.value for x in rs.route.all_turnouts}
            if wanted.get(partner or turnout, wanted.get(turnout)) != position:
                return False
        return bool(locks)

    def _beside_overlap(self, turnout: str, r: Route) -> bool:
        """Every lock on ``turnout`` comes from an overlap section of a route that ``r`` continues (a through
        movement), and that overlap does not run over the turnout: the onward route may move it (as its flank
        protection, say), since the overlap's way does not depend on it."""
        locks = self.il.locks.turnout_locks(turnout)
        for lk, via, partner in locks:
            first = self.il.table.routes.get(lk.holder)
            if lk.hold is not Hold.overlap or not via or first is None or not self._continues(first.id, r, via):
                return False
            if any(x.id in (turnout, partner) for x in first.overlap_turnouts):
                return False
        return bool(locks)

    def route_blocker_power_up(self, section: str) -> str:
        return f"section {section} is locked since the interlocking started (上电锁闭): give the power-up release first"

    def _conditional(self, r: Route, rs: RouteState) -> str:
        """The reason ``r`` conflicts with active route ``rs`` under the turnout positions as they are, if it does
        only under some positions (a run-on past a signal of the other direction)."""
        for cond, why in r.conditional.get(rs.id, ()):
            if self._holds(cond):
                return why
        return ""

    def _holds(self, cond: Condition) -> bool:
        """The turnouts lie as ``cond`` says (or cannot be told: fail-safe, it holds)."""
        return all(self.il.board.indication(t) in (p.value, None) for t, p in cond)

    def _continues(self, rid: str, r: Route | None, section: str) -> bool:
        """``r`` continues route ``rid`` (set, or its overlap still timing) from its end signal in the same direction,
        and ``section`` is in ``rid``'s overlap: a through movement, which is no enemy in either order of setting."""
        first = self.il.table.routes.get(rid)
        return (first is not None and r is not None and r.signal == first.end_signal
                and r.direction is first.direction and section in first.overlap_sections
                and section not in first.sections)

    def _still_conflicts(self, rs: RouteState, r: Route, run_on: RunOn | None) -> str:
        """What the active route ``rs`` still holds that ``r`` needs, in a signaller's words; '' when nothing.
        Sections released behind a train are free for the next route, as in a real CBI, even while the rest of the
        train's route is still locked. An enemy that leads head-on onto a track stays one while it holds (or leads
        into) that track."""
        held = {s for i, s in enumerate(rs.sections) if not rs.released[i]}
        wanted = set(r.all_sections) | (set(run_on.sections) if run_on else set())
        overlap = set() if rs.overlap_released else set(rs.route.overlap_sections)
        shared = sorted(wanted & (held | {f.section for f in rs.route.fouling} | overlap))
        if shared:
            return f"section {shared[0]}"
        if rs.id in r.added_enemies and held:
            return f"an enemy the station file adds: {r.conflicts[rs.id].removeprefix('added in the station file: ')}"
        track = r.head_on.get(rs.id)
        if track is not None:
            theirs = rs.run_on.leads_into if rs.run_on else rs.route.leads_into
            if track in held or (theirs == track and bool(held)):
                return f"both lead onto {track} from opposite ends"
        need = {t.id: t.position for t in r.all_turnouts + (run_on.turnouts if run_on else ())}
        for t in rs.all_turnouts:
            if t.id in need and need[t.id] is not t.position and rs.id in self.il.locks.holders(t.id):
                return f"turnout {t.id} {t.position.value}/{need[t.id].value}"
        crossings = self.il.station.crossings
        for track_id in rs.route.path.tracks:
            diamonds = [d for d, _ in crossings.get(track_id, ()) if d in r.diamonds]
            if diamonds and self.il.station.tracks[track_id].section in held:
                return f"diamond {diamonds[0]}"
        return ""

    def _need_route(self, signal: str) -> tuple[RouteState | None, str]:
        if signal not in self.il.station.signals:
            return None, f"there is no signal '{signal}' at {self.il.station.id}"
        rs = self.il.route_of(signal)
        if rs is None:
            return None, f"no route is set from signal {signal}"
        return rs, ""

    # ---- cancel, manual release, section fault release, reopen ----------------------------------------------
    def cancel(self, signal: str) -> Result:
        """总取消: cancel a route at once while its approach section is clear."""
        if signal in self.il.guide_only:
            self.lifecycle.close_guide_only(signal)
            return Result.accept(f"guide aspect of {signal} cancelled")
        rs, why = self._releasable(signal)
        if rs is None:
            return Result.refuse(why)
        if self.lifecycle.approach_locked(rs):
            occupied = self.lifecycle.approaching(rs.route)
            own = set(occupied) <= set(rs.route.approach)
            where = (f"approach section {', '.join(occupied)} is occupied" if own else
                     f"a train is coming to {signal} through the route in rear (in {', '.join(occupied)})")
            return Result.refuse(f"{where}: route {rs.id} is approach-locked (接近锁闭); use 'release {signal}' "
                                 "(manual time release)")
        self.lifecycle.close_if_open(rs, "route cancelled")
        self.lifecycle.finish(rs, all_sections=True)
        self.il.event("route", f"route {rs.id} cancelled")
        return Result.accept(f"route {rs.id} cancelled")

    def _releasable(self, signal: str) -> tuple[RouteState | None, str]:
        """The route of ``signal`` if it may be cancelled or released by hand, or why not."""
        rs, why = self._need_route(signal)
        if rs is None:
            return None, why
        if rs.stage is RouteStage.in_use:
            return None, (f"a train has entered route {rs.id}: it releases section by section; use "
                          "fault-release for a section that stays locked")
        if rs.stage is RouteStage.time_release:
            left = (rs.release_at or self.il.now) - self.il.now
            return None, f"route {rs.id} is already being released by manual time release ({left:.0f} s left)"
        return rs, ""

    def release(self, signal: str) -> Result:
        """总人解: close the signal and release after 180 s (train) / 30 s (shunting), everything still checked."""
        rs, why = self._releasable(signal)
        if rs is None:
            return Result.refuse(why)
        if not self.lifecycle.approach_locked(rs):
            self.lifecycle.close_if_open(rs, "route released")
            self.lifecycle.finish(rs, all_sections=True)
            return Result.accept(f"route {rs.id} released at once: no train is approaching")
        delay = self.release_delay(rs.route)
        self.lifecycle.start_time_release(rs, delay, "manual time release")
        self.il.event("route", f"manual time release of {rs.id}: {delay:g} s")
        return Result.accept(f"route {rs.id} releases in {delay:g} s unless a train enters")

    def release_delay(self, r: Route) -> float:
        sig = self.il.station.signals[r.signal]
        if sig.release_s is not None:
            return sig.release_s
        return self.il.rules.release_s["shunt" if r.kind == "shunt" else "train"]

    def fault_release(self, section: str) -> Result:
        """区故解: release one locked, clear section (never a station track)."""
        st = self.il.station
        if section not in st.sections:
            return Result.refuse(f"there is no section '{section}' at {st.id}")
        if st.is_station_track(section):
            return Result.refuse(f"section {section} is a station track: section fault release is not allowed on "
                                 "a station track (股道)")
        locks = self.il.locks.section_locks(section)
        if any(lk.hold is Hold.power_up for lk in locks):
            return Result.refuse(f"section {section} is locked since the interlocking started (上电锁闭): give the "
                                 "power-up release")
        routes = [lk.holder for lk in locks if lk.hold is Hold.route and lk.holder in self.il.routes]
        overlaps = [lk.holder for lk in locks if lk.hold is Hold.overlap]
        if not routes and not overlaps:
            fouled = [lk.holder for lk in locks if lk.hold is Hold.fouling]
            if fouled:
                return Result.refuse(f"section {section} is held only as a fouling section of route {fouled[0]}: it is "
                                     "released with that route")
            return Result.refuse(f"section {section} is not locked")
        if not self.il.clear(section):
            return Result.refuse(f"section {section} is occupied: only a clear section can be released")
        if not routes:
            return self._fault_release_overlap(section, overlaps[0])
        rs = self.il.routes[routes[0]]
        if rs.stage in (RouteStage.open, RouteStage.guide):
            return Result.refuse(f"signal {rs.route.signal} is open over {section}: close it first (cancel)")
        if self._counting_down(rs):
            return self._timing(rs, section)
        if self.lifecycle.approach_locked(rs) and not rs.entered:
            return self._fault_release_delayed(rs, section)
        i = rs.sections.index(section)
        if rs.entered and self._ahead_of_movement(rs, i):
            if i in rs.fault_release_at:
                return Result.refuse(f"section {section} ({rs.id}) is already being released "
                                     f"({rs.fault_release_at[i] - self.il.now:.0f} s left)")
            delay = self._fault_delay(rs.route)
            rs.fault_release_at[i] = self.il.now + delay
            self.il.event("route", f"section fault release of {section} ahead of the movement in {rs.id}: "
                          f"{delay:g} s")
            return Result.accept(f"section {section} ({rs.id}) releases in {delay:g} s unless the movement "
                                 "reaches it: it is still on its way")
        self.il.event("release", f"section {section} released by section fault release")
        if self.lifecycle.release_by_fault(rs, i):
            return Result.accept(f"section {section} released; route {rs.id} released with its track "
                                 f"{rs.sections[-1]}")
        return Result.accept(f"section {section} released")

    def _ahead_of_movement(self, rs: RouteState, i: int) -> bool:
        """Section ``i`` of a route in use lies ahead of a movement still on its way to it: the movement has not
        reached it or anything beyond it, and stands in the route before it or in its approach."""
        if any(rs.was_occupied[i:]):
            return False
        clear = self.il.clear
        return any(not clear(s) for s in rs.sections[:i]) or any(not clear(s) for s in rs.route.approach)

    def _fault_delay(self, r: Route) -> float:
        rules = self.il.rules
        return rules.section_fault_release_s if r.kind == "train" else rules.release_s["shunt"]

    def _fault_release_delayed(self, rs: RouteState, section: str) -> Result:
        """A section fault release with a train approaching the closed signal: the route releases after the delay,
        everything still checked, unless the train enters (as a manual time release)."""
        delay = self._fault_delay(rs.route)
        self.lifecycle.start_time_release(rs, delay, "section fault release")
        self.il.event("route", f"section fault release of {section} with a train approaching: {delay:g} s")
        return Result.accept(f"section {section} ({rs.id}) releases in {delay:g} s unless a train enters")

    @staticmethod
    def _counting_down(rs: RouteState) -> bool:
        return rs.stage is RouteStage.time_release and not rs.entered

    def _timing(self, rs: RouteState, section: str) -> Result:
        """A route already counting down a time release (manual, or a fault release given with a train approaching)
        keeps it to the end: the approach showing clear since may be a train that does not shunt (分路不良)."""
        left = (rs.release_at or self.il.now) - self.il.now
        return Result.refuse(f"route {rs.id} over {section} is being released by time ({left:.0f} s left): it "
                             "releases by itself; a section fault release cannot shorten it")

    def _fault_release_overlap(self, section: str, rid: str) -> Result:
        """区故解 of a section locked only as the overlap (延续进路) of route ``rid``: as for a section of the route
        itself, refused under the open signal and delayed with a train approaching or running in the route; an
        overlap timing behind a train on the receiving track is never shortened."""
        rs = self.il.routes.get(rid)
        if rs is None:
            at = self.il.overlap_pending.get(rid)
            left = f" in {at - self.il.now:.0f} s" if at is not None else ""
            return Result.refuse(f"section {section} is the overlap (延续进路) of {rid}, held for the train that "
                                 f"was received: it releases by itself{left}; a section fault release cannot "
                                 "shorten it")
        signal = rs.route.signal
        if rs.stage in (RouteStage.open, RouteStage.guide):
            return Result.refuse(f"signal {signal} is open over {section} (the overlap of {rid}): close it first "
                                 "(cancel)")
        if self._counting_down(rs):
            return self._timing(rs, section)
        if rs.entered:
            if rs.overlap_release_at is not None:
                return Result.refuse(f"section {section} is the overlap (延续进路) of {rid}: it releases by itself "
                                     f"in {rs.overlap_release_at - self.il.now:.0f} s after the train reached "
                                     f"{rs.route.sections[-1]}; a section fault release cannot shorten it")
            delay = self._fault_delay(rs.route)
            self.il.overlap_pending[rid] = self.il.now + delay
            self.il.event("route", f"section fault release of {section} (overlap of {rid}) with a train in the "
                          f"route: {delay:g} s")
            return Result.accept(f"section {section} (overlap of {rid}) releases once the route has released, and "
                                 f"not before {delay:g} s: the overlap is there for the train running in")
        if self.lifecycle.approach_locked(rs):
            return self._fault_release_delayed(rs, section)
        self.lifecycle.release_overlap(rid)
        rs.overlap_released = True
        return Result.accept(f"overlap of {rid} released; signal {signal} cannot open without it: cancel the route "
                             "and set it again")

    def reopen(self, signal: str) -> Result:
        """重复开放: reopen a signal closed abnormally, once its conditions are back."""
        rs, why = self._need_route(signal)
        if rs is None:
            return Result.refuse(why)
        if rs.stage in (RouteStage.open, RouteStage.guide):
            return Result.refuse(f"signal {signal} is already open")
        if rs.stage not in (RouteStage.locked, RouteStage.closed) or rs.entered:
            return Result.refuse(f"route {rs.id} is {rs.stage.value}: only a locked route whose signal closed "
                                 "abnormally can be reopened")
        blocker = self.il.open_blocker(rs)
        if blocker:
            return Result.refuse(f"signal {signal} cannot reopen: {blocker}")
        self.lifecycle.reopen(rs)
        return Result.accept(f"signal {signal} reopened")

    # ---- guide ------------------------------------------------------------------------------------------------
    def guide(self, signal: str, end: str | None = None, via: tuple[str, ...] = ()) -> Result:
        """引导: open HB over a set route without checking its track circuits, or over a guide-locked throat. With
        ``end`` (and variant buttons ``via``): a guide route (引导进路锁闭), selected and locked without looking at its
        track circuits, the guide aspect given once its turnouts are in position."""
        st = self.il.station
        if signal not in st.signals:
            return Result.refuse(f"there is no signal '{signal}' at {st.id}")
        sig = st.signals[signal]
        guide = self.il.rules.aspects.guide
        if sig.kind not in (SignalKind.home, SignalKind.route) or not self.il.rules.aspects.can_show(
                guide, [lamp.value for lamp in sig.lamps]):
            return Result.refuse(f"signal {signal} has no guide aspect: only home and route signals with a "
                                 "moon-white lamp show HB")
        if not self.il.board.lamp_ok(signal, stop_aspect(st, signal)):
            return Result.refuse(f"the red lamp of {signal} is dark: the guide aspect needs it lit")
        rs = self.il.route_of(signal)
        if end is not None:
            return self._guide_route(signal, end, via, rs)
        if rs is not None:
            if rs.stage not in (RouteStage.setting, RouteStage.locked, RouteStage.closed) or rs.entered:
                return Result.refuse(f"route {rs.id} is {rs.stage.value}; a guide route needs a locked route "
                                     "whose signal is closed")
            released = [s for i, s in enumerate(rs.sections) if rs.released[i]]
            if released:  # e.g. by section fault release: its turnouts are no longer locked
                return Result.refuse(f"guide refused: section {released[0]} of route {rs.id} has been released; "
                                     "cancel the route and set it again")
            blocker = self.il.open_blocker(rs, guide=True)
            if blocker.startswith(("turnout", "block", "screen", "line")):
                return Result.refuse(f"guide refused: {blocker}")
            self.lifecycle.open_guide(rs)
            return Result.accept(f"guide aspect {guide} on {signal}")
        throat = next((name for name, turnouts in self.il.table.throats.items()
                       if name == signal and all(self._guide_locked(t, name) for t in turnouts)), None)
        if throat is None:
            return Result.refuse(f"no route is set from {signal} and its throat is not under guide total lock: "
                                 f"set the route first, or 'guide-lock {signal}'")
        if self.il.power_up_locked:  # no movement authority before the operator has confirmed the station's state
            return Result.refuse("guide refused: the station is locked since the interlocking started (上电锁闭): "
                                 "give the power-up release first")
        why = self.il.line_against(signal)
        if why:
            return Result.refuse(f"guide refused: {why}")
        inside, beside = self.il.guide_area(signal)
        for sec in sorted(inside | beside):  # the way is not known: nothing may be locked where the train may go
            holders = self.il.locks.section_holders(sec)
            if holders:
                return Result.refuse(f"guide refused: section {sec}, where a train guided past {signal} may run, is "
                                     f"locked in route {holders[0]}")
        for rs in self.il.routes.values():  # nor may a shunting movement run into a track it may reach, at sight
            ro = rs.run_on
            if self.il.guide_only_meets(signal, (), ro.leads_into if ro else rs.route.leads_into):
                return Result.refuse(f"guide refused: route {rs.id} leads into a track a train guided past {signal} "
                                     "may reach")
        for other in self.il.guide_only:  # nor may another guided train, from the other end
            if self.il.guide_only_meets(other, inside | beside, None):
                return Result.refuse(f"guide refused: the guide aspect of {other} is lit under guide total lock, "
                                     f"towards the tracks {signal} leads to")
        doors = self.il.doors_blocker(self.il.guide_only_doors(signal))
        if doors:  # the way is not known: every platform track the signal leads to must have its doors safe
            return Result.refuse(f"guide refused: {doors}")
        if self.il.proven(signal, guide) != guide:
            return Result.refuse(f"guide refused: a lamp of the guide aspect {guide} of {signal} is dark")
        self.lifecycle.open_guide_only(signal)
        return Result.accept(f"guide aspect {guide} on {signal} (guide total lock)")

    def _guide_route(self, signal: str, end: str, via: tuple[str, ...], rs: RouteState | None) -> Result:
        if rs is not None:
            return Result.refuse(f"signal {signal} already has route {rs.id} set: give 'guide {signal}' over it, or "
                                 "cancel it first")
        r, why = self._find("train", signal, end, via)
        if r is None:
            return Result.refuse(f"guide refused: {why}")
        if r.category != "receiving" and self.il.station.signals[signal].kind is not SignalKind.route:
            return Result.refuse(f"guide refused: {r.id} is not a receiving route")
        why = self.route_blocker(r, guide=True)
        if why:
            return Result.refuse(f"guide refused: {why}")
        self.lifecycle.select(RouteState(r, RouteStage.setting, self.il.now, guide_route=True))
        self.il.event("route", f"guide route {r.id} selected (引导进路锁闭): its track circuits are not checked")
        return Result.accept(f"guide route {r.id} selected: {self.il.rules.aspects.guide} on {signal} once its "
                             "turnouts are in position")

    def _guide_locked(self, turnout: str, throat: str) -> bool:
        return any(lk.hold is Hold.guide and lk.holder == throat for lk, _, _ in self.il.locks.turnout_locks(turnout))

    def guide_lock(self, throat: str, lock: bool) -> Result:
        """引导总锁闭: lock (or unlock) every turnout of a throat."""
        if throat not in self.il.table.throats:
            names = ", ".join(sorted(self.il.table.throats))
            return Result.refuse(f"there is no throat '{throat}'; throats are named by their home signal: {names}")
        turnouts = self.il.table.throats[throat]
        if not lock and not any(self._guide_locked(t, throat) for t in turnouts):
            return Result.refuse(f"throat {throat} is not under guide total lock (引导总锁闭)")
        if not lock and throat in self.il.guide_only:
            return Result.refuse(f"the guide aspect of {throat} is open: cancel it before unlocking the throat")
        for t in turnouts:
            if lock:
                self.il.locks.lock_turnout(t, Hold.guide, throat)
            else:
                self.il.locks.unlock_turnout(t, Hold.guide, throat)
        word = "locked" if lock else "unlocked"
        self.il.event("turnout", f"guide total lock: throat {throat} {word} ({', '.join(turnouts)})")
        return Result.accept(f"throat {throat} {word}: turnouts {', '.join(turnouts)}")

    # ---- turnouts ---------------------------------------------------------------------------------------------
    def _turnout_ids(self, name: str) -> list[str] | None:
        if name in self.il.station.turnouts:
            return self.il.pair_members(name)
        if name in self.il.station.pairs:
            return list(self.il.station.pairs[name])
        return None

    def throw(self, name: str, position: str) -> Result:
        """单操: individual operation of a turnout (a crossover pair moves together)."""
        ids = self._turnout_ids(name)
        if ids is None:
            return Result.refuse(f"there is no turnout '{name}' at {self.il.station.id}")
        if position not in ("normal", "reverse"):
            return Result.refuse(f"a turnout goes 'normal' or 'reverse', not '{position}'")
        if all(self.il.board.indication(t) == position for t in ids):
            return Result.accept(f"turnout {name} is already {position}")
        for t in ids:
            why = self.il.locks.why_turnout(t)
            if why:
                return Result.refuse(why)
            if not self.il.clear(self.il.turnouts[t].section):
                return Result.refuse(f"turnout {t} cannot move: section {self.il.turnouts[t].section} is occupied")
        self.il.request_move(ids[0], position)
        self.il.event("turnout", f"turnout {name} to {position} (individual operation)")
        return Result.accept(f"turnout {name} moving to {position}")

    def single_lock(self, name: str, on: bool) -> Result:
        """单锁 / 单解: the turnout (and its crossover partner) may not be moved."""
        ids = self._turnout_ids(name)
        if ids is None:
            return Result.refuse(f"there is no turnout '{name}' at {self.il.station.id}")
        for t in ids:
            if on:
                self.il.locks.lock_turnout(t, Hold.single)
            else:
                self.il.locks.unlock_turnout(t, Hold.single)
        word = "single-locked (单锁)" if on else "unlocked (单解)"
        self.il.event("turnout", f"turnout {name} {word}")
        return Result.accept(f"turnout {name} {word}")

    def single_block(self, name: str, on: bool) -> Result:
        """单封 / 解封: no route through the turnout; individual operation stays allowed."""
        ids = self._turnout_ids(name)
        if ids is None:
            return Result.refuse(f"there is no turnout '{name}' at {self.il.station.id}")
        for t in ids:
            if on:
                self.il.locks.blocked.add(t)
            else:
                self.il.locks.blocked.discard(t)
        word = "single-blocked (单封)" if on else "unblocked (解封)"
        self.il.event("turnout", f"turnout {name} {word}")
        return Result.accept(f"turnout {name} {word}")

    # ---- power-up, line direction ----------------------------------------------------------------------------
    def power_up_release(self) -> Result:
        """上电解锁 (a sealed button): give back the sections locked since the interlocking started; refused while a
        section of the station shows occupied."""
        if not self.il.power_up_locked:
            return Result.refuse("there is no power-up lock to release: the interlocking is in service")
        il = self.il
        occupied = [s for s, sec in il.station.sections.items() if sec.role in INTERLOCKED and not il.clear(s)]
        if occupied:
            return Result.refuse(f"power-up release refused: section {', '.join(occupied[:6])}"
                                 f"{' ...' if len(occupied) > 6 else ''} shows occupied; every section of the station "
                                 "must show clear first (clear it, or have the track circuit repaired)")
        self.il.locks.release_all(Hold.power_up)
        self.il.power_up_locked = False
        self.il.event("power", "power-up release (上电解锁): every section released")
        return Result.accept("power-up release: the station is in service")

    def line_direction(self, link: str, direction: str) -> Result:
        """改方: set an automatic line for departures from this station ('out') or back to its running direction
        ('in'). Only a bidirectional line, clear, with no route into or out of it."""
        lk = next((x for x in self.il.station.model.links if x.id == link), None)
        if lk is None or lk.kind.value != "automatic":
            names = ", ".join(x.id for x in self.il.station.model.links if x.kind.value == "automatic") or "none"
            return Result.refuse(f"there is no automatic block line '{link}' (automatic lines: {names})")
        if direction not in ("out", "in"):
            return Result.refuse("line-direction LINE out|in")
        if self.il.station.link_running(link) != "inbound":
            return Result.refuse(f"line {link} already runs away from this station: its direction needs no change")
        if not lk.bidirectional:
            return Result.refuse(f"line {link} is not bidirectional (双向): its direction cannot be changed")
        want_out = direction == "out"
        if (link in self.il.line_out) == want_out:
            return Result.accept(f"line {link} is already set {'for departures' if want_out else 'towards us'}")
        occupied = [s for s in lk.sections if not self.il.clear(s)]
        if occupied:
            return Result.refuse(f"line {link} is not clear ({', '.join(occupied)} occupied): the direction changes "
                                 "only with the whole line clear")
        receiving = [sig for sig, line in self.il.index.receives_from.items() if line == link]
        for rs in self.il.routes.values():
            r = rs.route
            if r.exit_link == link or set(r.approach) & set(lk.sections) or r.signal in receiving:
                return Result.refuse(f"route {r.id} uses line {link}: the direction changes only with no route "
                                     "into or out of it")
        guided = [sig for sig in receiving if sig in self.il.guide_only]
        if guided:
            return Result.refuse(f"signal {guided[0]} shows the guide aspect for a train from line {link}: the "
                                 "direction changes only with no signal given for a movement on the line")
        if want_out:
            self.il.line_out.add(link)
            self.il.out.line_direction[link] = "outbound"
        else:
            self.il.line_out.discard(link)
            self.il.out.line_direction.pop(link, None)
        self.il.codes_dirty = self.il.blocks_dirty = True
        word = "set for departures from this station" if want_out else "back to its running direction"
        self.il.event("block", f"line {link} {word} (改方)")
        return Result.accept(f"line {link} {word}")

    # ---- 64D block and platform doors ------------------------------------------------------------------------
    def block_line(self, link: str, action: str) -> Result:
        bl = self.il.links.get(link)
        if bl is None:
            names = ", ".join(sorted(self.il.links)) or "none"
            return Result.refuse(f"there is no 64D block line '{link}' (64D lines: {names})")
        before = bl.state
        why, pulse = bl.operate(action, self.il.clear(bl.departure_section))
        if why:
            return Result.refuse(why)
        if pulse:
            self.il.send(link, pulse)
        self.il.event("block", f"block line {link}: {action}, {before.value} -> {bl.state.value}")
        return Result.accept(f"block line {link}: {bl.state.value}")

    def axle_reset(self, section: str) -> Result:
        """计轴复零 (a sealed button, counted): set an axle-counter section's count to zero after its disturbance.
        Refused on a track circuit, on a section that shows clear, and on one a route holds: the operator resets only
        a line confirmed clear on site, never under a movement the interlocking has authorised."""
        il = self.il
        sec = il.station.sections.get(section)
        if sec is None:
            return Result.refuse(f"there is no section '{section}' at {il.station.id}")
        if sec.type.value != "axle_counter":
            return Result.refuse(f"section {section} is a track circuit, not counted by axle counters: nothing to "
                                 "reset")
        if il.clear(section):
            return Result.refuse(f"the axle counter of {section} shows clear: nothing to reset")
        holders = il.locks.section_holders(section)
        if holders:
            return Result.refuse(f"section {section} is locked in route {holders[0]}: a counter under a route is "
                                 "never reset")
        il.out.axle_resets.add(section)
        il.axle_resets_used += 1
        il.event("block", f"axle counter {section} reset (计轴复零, sealed button, counter {il.axle_resets_used})")
        return Result.accept(f"axle counter {section} reset (sealed button 铅封, counter {il.axle_resets_used}); "
                             "confirm the line clear on site before the next train")

    def doors(self, platform: str, action: str) -> Result:
        p = next((p for p in self.il.station.model.platforms if p.id == platform), None)
        if p is None or not p.screen_doors:
            return Result.refuse(f"there is no platform with screen doors '{platform}'")
        if action not in ("open", "close"):
            return Result.refuse("doors open|close")
        if action == "open" and self.il.clear(p.section):
            return Result.refuse(f"no train at platform {platform}: section {p.section} is clear")
        for d in p.screen_doors:
            cmd = self.il.out.doors[f"{p.id}:{d.side.value}"]
            cmd.zckj = not self.il.clear(p.section)
            cmd.kmj = action == "open"
            cmd.gmj = action == "close"
        self.il.event("doors", f"platform {platform}: {action} command")
        return Result.accept(f"platform {platform} doors: {action}")

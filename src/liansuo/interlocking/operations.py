"""Operator commands of the CBI console (操作表示机). Each returns a :class:`Result`; a refusal says why in a
signaller's terms. A command checks what it may do on the interlocking's core and changes a route's stage only
through the route lifecycle (:mod:`.lifecycle`); the routes then progress cycle by cycle."""

from __future__ import annotations

from liansuo.interlocking.aspects import stop_aspect
from liansuo.interlocking.core import Core
from liansuo.interlocking.equipment import EquipmentCommands
from liansuo.interlocking.io import Result
from liansuo.interlocking.lifecycle import RouteLifecycle
from liansuo.interlocking.locks import Hold
from liansuo.interlocking.selection import KIND_WORD, Selection
from liansuo.interlocking.state import RouteStage, RouteState
from liansuo.interlocking.table.route import Kind, Route
from liansuo.stations.schema import Button, SignalKind


class Operator(EquipmentCommands):
    """The operator's commands on one interlocking: its ``core`` (state and conditions) and its route
    ``lifecycle``; the commands on routes here, those on the rest of the equipment in :mod:`.equipment`."""

    def __init__(self, core: Core, lifecycle: RouteLifecycle) -> None:
        self.core = core
        self.lifecycle = lifecycle
        self.selection = Selection(core)

    # ---- route setting ----------------------------------------------------------------------------------------
    def set_route(self, kind: Kind, start: str, end: str, via: tuple[str, ...] = ()) -> Result:
        """Select a route by its start, optional variant and end buttons (列车/调车进路); an overlap's end button
        pressed after the end button chooses that alternative overlap (变更延续进路)."""
        st = self.core.station
        known = set(st.signals) | set(st.buttons)
        for b in (start, end, *via):
            if b not in known:
                return Result.refuse(f"there is no signal or button '{b}' at {st.id}")
        if start not in st.signals:
            return Result.refuse(f"'{start}' cannot start a route: routes start at a signal's button")
        button = Button.train if kind == "train" else Button.shunt
        if button not in st.signals[start].buttons:
            other = "shunt" if kind == "train" else "route"
            return Result.refuse(f"signal {start} has no {KIND_WORD[kind]} button; use '{other} {start} ...'")
        r, why = self.selection.find(kind, start, end, via)
        if r is None:
            return Result.refuse(why)
        run_on, why = self.selection.choose_run_on(r)
        if not why:
            why = self.selection.route_blocker(r, run_on)
        if why:
            return Result.refuse(why)
        self.lifecycle.select(RouteState(r, RouteStage.setting, self.core.now, run_on=run_on))
        return Result.accept(f"route {r.id} selected")

    def _need_route(self, signal: str) -> tuple[RouteState | None, str]:
        if signal not in self.core.station.signals:
            return None, f"there is no signal '{signal}' at {self.core.station.id}"
        rs = self.core.route_of(signal)
        if rs is None:
            return None, f"no route is set from signal {signal}"
        return rs, ""

    # ---- cancel, manual release, section fault release, reopen ----------------------------------------------
    def cancel(self, signal: str) -> Result:
        """总取消: cancel a route at once while its approach section is clear."""
        if signal in self.core.guide_only:
            self.lifecycle.throat_guide.close(signal)
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
        self.core.event("route", f"route {rs.id} cancelled")
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
            left = (rs.release_at or self.core.now) - self.core.now
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
        self.core.event("route", f"manual time release of {rs.id}: {delay:g} s")
        return Result.accept(f"route {rs.id} releases in {delay:g} s unless a train enters")

    def release_delay(self, r: Route) -> float:
        sig = self.core.station.signals[r.signal]
        if sig.release_s is not None:
            return sig.release_s
        return self.core.rules.release_s["shunt" if r.kind == "shunt" else "train"]

    def fault_release(self, section: str) -> Result:
        """区故解: release one locked, clear section (never a station track)."""
        st = self.core.station
        if section not in st.sections:
            return Result.refuse(f"there is no section '{section}' at {st.id}")
        if st.is_station_track(section):
            return Result.refuse(f"section {section} is a station track: section fault release is not allowed on "
                                 "a station track (股道)")
        locks = self.core.locks.section_locks(section)
        if any(lk.hold is Hold.power_up for lk in locks):
            return Result.refuse(f"section {section} is locked since the interlocking started (上电锁闭): give the "
                                 "power-up release")
        routes = [lk.holder for lk in locks if lk.hold is Hold.route and lk.holder in self.core.routes]
        overlaps = [lk.holder for lk in locks if lk.hold is Hold.overlap]
        if not routes and not overlaps:
            fouled = [lk.holder for lk in locks if lk.hold is Hold.fouling]
            if fouled:
                return Result.refuse(f"section {section} is held only as a fouling section of route {fouled[0]}: it is "
                                     "released with that route")
            return Result.refuse(f"section {section} is not locked")
        if not self.core.clear(section):
            return Result.refuse(f"section {section} is occupied: only a clear section can be released")
        if not routes:
            return self._fault_release_overlap(section, overlaps[0])
        rs = self.core.routes[routes[0]]
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
                                     f"({rs.fault_release_at[i] - self.core.now:.0f} s left)")
            delay = self._fault_delay(rs.route)
            rs.fault_release_at[i] = self.core.now + delay
            self.core.event("route", f"section fault release of {section} ahead of the movement in {rs.id}: "
                          f"{delay:g} s")
            return Result.accept(f"section {section} ({rs.id}) releases in {delay:g} s unless the movement "
                                 "reaches it: it is still on its way")
        self.core.event("release", f"section {section} released by section fault release")
        if self.lifecycle.release_by_fault(rs, i):
            return Result.accept(f"section {section} released; route {rs.id} released with its track "
                                 f"{rs.sections[-1]}")
        return Result.accept(f"section {section} released")

    def _ahead_of_movement(self, rs: RouteState, i: int) -> bool:
        """Section ``i`` of a route in use lies ahead of a movement still on its way to it: the movement has not
        reached it or anything beyond it, and stands in the route before it or in its approach."""
        if any(rs.was_occupied[i:]):
            return False
        clear = self.core.clear
        return any(not clear(s) for s in rs.sections[:i]) or any(not clear(s) for s in rs.route.approach)

    def _fault_delay(self, r: Route) -> float:
        rules = self.core.rules
        return rules.section_fault_release_s if r.kind == "train" else rules.release_s["shunt"]

    def _fault_release_delayed(self, rs: RouteState, section: str) -> Result:
        """A section fault release with a train approaching the closed signal: the route releases after the delay,
        everything still checked, unless the train enters (as a manual time release)."""
        delay = self._fault_delay(rs.route)
        self.lifecycle.start_time_release(rs, delay, "section fault release")
        self.core.event("route", f"section fault release of {section} with a train approaching: {delay:g} s")
        return Result.accept(f"section {section} ({rs.id}) releases in {delay:g} s unless a train enters")

    @staticmethod
    def _counting_down(rs: RouteState) -> bool:
        return rs.stage is RouteStage.time_release and not rs.entered

    def _timing(self, rs: RouteState, section: str) -> Result:
        """A route already counting down a time release (manual, or a fault release given with a train approaching)
        keeps it to the end: the approach showing clear since may be a train that does not shunt (分路不良)."""
        left = (rs.release_at or self.core.now) - self.core.now
        return Result.refuse(f"route {rs.id} over {section} is being released by time ({left:.0f} s left): it "
                             "releases by itself; a section fault release cannot shorten it")

    def _fault_release_overlap(self, section: str, rid: str) -> Result:
        """区故解 of a section locked only as the overlap (延续进路) of route ``rid``: as for a section of the route
        itself, refused under the open signal and delayed with a train approaching or running in the route; an
        overlap timing behind a train on the receiving track is never shortened."""
        rs = self.core.routes.get(rid)
        if rs is None:
            at = self.core.overlap_pending.get(rid)
            left = f" in {at - self.core.now:.0f} s" if at is not None else ""
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
                                     f"in {rs.overlap_release_at - self.core.now:.0f} s after the train reached "
                                     f"{rs.route.sections[-1]}; a section fault release cannot shorten it")
            delay = self._fault_delay(rs.route)
            self.core.overlap_pending[rid] = self.core.now + delay
            self.core.event("route", f"section fault release of {section} (overlap of {rid}) with a train in the "
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
        blocker = self.core.open_blocker(rs)
        if blocker:
            return Result.refuse(f"signal {signal} cannot reopen: {blocker}")
        self.lifecycle.reopen(rs)
        return Result.accept(f"signal {signal} reopened")

    # ---- guide ------------------------------------------------------------------------------------------------
    def guide(self, signal: str, end: str | None = None, via: tuple[str, ...] = ()) -> Result:
        """引导: open HB over a set route without checking its track circuits, or over a guide-locked throat. With
        ``end`` (and variant buttons ``via``): a guide route (引导进路锁闭), selected and locked without looking at its
        track circuits, the guide aspect given once its turnouts are in position."""
        st = self.core.station
        if signal not in st.signals:
            return Result.refuse(f"there is no signal '{signal}' at {st.id}")
        sig = st.signals[signal]
        guide = self.core.rules.aspects.guide
        if sig.kind not in (SignalKind.home, SignalKind.route) or not self.core.rules.aspects.can_show(
                guide, [lamp.value for lamp in sig.lamps]):
            return Result.refuse(f"signal {signal} has no guide aspect: only home and route signals with a "
                                 "moon-white lamp show HB")
        if not self.core.board.lamp_ok(signal, stop_aspect(st, signal)):
            return Result.refuse(f"the red lamp of {signal} is dark: the guide aspect needs it lit")
        rs = self.core.route_of(signal)
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
            blocker = self.core.open_blocker(rs, guide=True)
            if blocker.startswith(("turnout", "block", "screen", "line")):
                return Result.refuse(f"guide refused: {blocker}")
            self.lifecycle.open_guide(rs)
            return Result.accept(f"guide aspect {guide} on {signal}")
        throat = next((name for name, turnouts in self.core.table.throats.items()
                       if name == signal and all(self._guide_locked(t, name) for t in turnouts)), None)
        if throat is None:
            return Result.refuse(f"no route is set from {signal} and its throat is not under guide total lock: "
                                 f"set the route first, or 'guide-lock {signal}'")
        if self.core.power_up_locked:  # no movement authority before the operator has confirmed the station's state
            return Result.refuse("guide refused: the station is locked since the interlocking started (上电锁闭): "
                                 "give the power-up release first")
        why = self.core.line_against(signal)
        if why:
            return Result.refuse(f"guide refused: {why}")
        inside, beside = self.core.guide_area(signal)
        for sec in sorted(inside | beside):  # the way is not known: nothing may be locked where the train may go
            holders = self.core.locks.section_holders(sec)
            if holders:
                return Result.refuse(f"guide refused: section {sec}, where a train guided past {signal} may run, is "
                                     f"locked in route {holders[0]}")
        for rs in self.core.routes.values():  # nor may a shunting movement run into a track it may reach, at sight
            ro = rs.run_on
            if self.core.guide_only_meets(signal, (), ro.leads_into if ro else rs.route.leads_into):
                return Result.refuse(f"guide refused: route {rs.id} leads into a track a train guided past {signal} "
                                     "may reach")
        for other in self.core.guide_only:  # nor may another guided train, from the other end
            if self.core.guide_only_meets(other, inside | beside, None):
                return Result.refuse(f"guide refused: the guide aspect of {other} is lit under guide total lock, "
                                     f"towards the tracks {signal} leads to")
        doors = self.core.doors_blocker(self.core.guide_only_doors(signal))
        if doors:  # the way is not known: every platform track the signal leads to must have its doors safe
            return Result.refuse(f"guide refused: {doors}")
        if self.core.proven(signal, guide) != guide:
            return Result.refuse(f"guide refused: a lamp of the guide aspect {guide} of {signal} is dark")
        self.lifecycle.throat_guide.open(signal)
        return Result.accept(f"guide aspect {guide} on {signal} (guide total lock)")

    def _guide_route(self, signal: str, end: str, via: tuple[str, ...], rs: RouteState | None) -> Result:
        if rs is not None:
            return Result.refuse(f"signal {signal} already has route {rs.id} set: give 'guide {signal}' over it, or "
                                 "cancel it first")
        r, why = self.selection.find("train", signal, end, via)
        if r is None:
            return Result.refuse(f"guide refused: {why}")
        if r.category != "receiving" and self.core.station.signals[signal].kind is not SignalKind.route:
            return Result.refuse(f"guide refused: {r.id} is not a receiving route")
        why = self.selection.route_blocker(r, guide=True)
        if why:
            return Result.refuse(f"guide refused: {why}")
        self.lifecycle.select(RouteState(r, RouteStage.setting, self.core.now, guide_route=True))
        self.core.event("route", f"guide route {r.id} selected (引导进路锁闭): its track circuits are not checked")
        return Result.accept(f"guide route {r.id} selected: {self.core.rules.aspects.guide} on {signal} once its "
                             "turnouts are in position")

    def _guide_locked(self, turnout: str, throat: str) -> bool:
        return any(lk.hold is Hold.guide and lk.holder == throat for lk, _, _ in self.core.locks.turnout_locks(turnout))

    def guide_lock(self, throat: str, lock: bool) -> Result:
        """引导总锁闭: lock (or unlock) every turnout of a throat."""
        if throat not in self.core.table.throats:
            names = ", ".join(sorted(self.core.table.throats))
            return Result.refuse(f"there is no throat '{throat}'; throats are named by their home signal: {names}")
        turnouts = self.core.table.throats[throat]
        if not lock and not any(self._guide_locked(t, throat) for t in turnouts):
            return Result.refuse(f"throat {throat} is not under guide total lock (引导总锁闭)")
        if not lock and throat in self.core.guide_only:
            return Result.refuse(f"the guide aspect of {throat} is open: cancel it before unlocking the throat")
        for t in turnouts:
            if lock:
                self.core.locks.lock_turnout(t, Hold.guide, throat)
            else:
                self.core.locks.unlock_turnout(t, Hold.guide, throat)
        word = "locked" if lock else "unlocked"
        self.core.event("turnout", f"guide total lock: throat {throat} {word} ({', '.join(turnouts)})")
        return Result.accept(f"throat {throat} {word}: turnouts {', '.join(turnouts)}")

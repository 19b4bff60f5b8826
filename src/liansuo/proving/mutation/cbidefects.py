"""Seeded defects of the running interlocking: locks not asked, conditions not checked, releases without
their delay or check, lamps unproved, guide aspects kept, timers cut, commands accepted that a CBI refuses."""

from __future__ import annotations

from collections.abc import Callable
from contextlib import ExitStack
from typing import Any
from unittest import mock

import liansuo.interlocking.autoblock as autoblock
import liansuo.interlocking.block64d as block64d
import liansuo.interlocking.core as core
import liansuo.interlocking.lifecycle as lifecycle
import liansuo.interlocking.locks as locks
import liansuo.interlocking.memos as memos
import liansuo.interlocking.operations as operations
import liansuo.interlocking.selection as selection
import liansuo.interlocking.state as state
import liansuo.interlocking.stationblock as stationblock
import liansuo.interlocking.table.derive as derive
import liansuo.interlocking.table.flank as flank
import liansuo.interlocking.table.overlap as overlap
import liansuo.interlocking.throatguide as throatguide
from liansuo.interlocking.io import RelayBoard, Result
from liansuo.interlocking.state import RouteStage, RouteState
from liansuo.interlocking.table.route import Route
from liansuo.proving.mutation.patching import patch, patched_during, wrap
from liansuo.stations.profile import falling


# ---- the running interlocking ---------------------------------------------------------------------------------------
def usu_without_onward(s: ExitStack) -> None:
    patch(s, core, "onward_allows_usu", lambda station, turnouts, rules: True)


def throw_ignores_locks(s: ExitStack) -> None:
    def throw(real: Any) -> Any:
        def careless(self: Any, name: str, position: str) -> Result:
            with mock.patch.object(self.core.locks, "why_turnout", lambda t: ""):
                return real(self, name, position)  # type: ignore[no-any-return]
        return careless
    wrap(s, operations.Operator, "throw", throw)


def throw_ignores_section_locks(s: ExitStack) -> None:
    def own(self: Any, turnout: str) -> list[Any]:
        return [(lk, "") for lk in sorted(self.turnouts.get(turnout, ()), key=locks._order)]
    patch(s, locks.LockLedger, "_own_locks", own)


def open_blocker_ignoring(s: ExitStack, ignored: Callable[[str], bool]) -> None:
    """The signal opens and stays open whenever the only thing against it is a reason ``ignored`` accepts."""
    def blind(real: Any) -> Any:
        def open_blocker(self: Any, rs: RouteState, **kw: Any) -> str:
            why = real(self, rs, **kw)
            return "" if ignored(why) else why
        return open_blocker
    wrap(s, core.Core, "open_blocker", blind)


def blind_to_occupancy(s: ExitStack) -> None:
    open_blocker_ignoring(s, lambda why: why.endswith("is occupied"))


def blind_to_indication(s: ExitStack) -> None:
    open_blocker_ignoring(s, lambda why: why.startswith("turnout"))


def reopens_by_itself(s: ExitStack) -> None:
    def advance(real: Any) -> Any:
        def forgetful(self: Any, rs: RouteState) -> None:
            if rs.stage is RouteStage.closed:
                rs.stage = RouteStage.locked
            real(self, rs)
        return forgetful
    wrap(s, lifecycle.RouteLifecycle, "advance", advance)


def no_three_point_check(s: ExitStack) -> None:
    def release(self: Any, rs: RouteState) -> None:  # a section releases once it is clear again, whatever is next
        secs = rs.sections
        for i, sec in enumerate(secs):
            if not rs.released[i] and not self.core.clear(sec):
                rs.was_occupied[i] = True
        for i, sec in enumerate(secs):
            if not rs.released[i] and rs.was_occupied[i] and (self.core.clear(sec) or i == len(secs) - 1):
                self.release_section(rs, i)
        if all(rs.released):
            self.finish(rs, all_sections=False)
    patch(s, lifecycle.RouteLifecycle, "_sequential_release", release)


def cancel_ignores_approach(s: ExitStack) -> None:
    patch(s, lifecycle.RouteLifecycle, "approach_locked", lambda self, rs: False)


def no_release_delay(s: ExitStack) -> None:
    patch(s, operations.Operator, "release_delay", lambda self, r: 0.0)


def no_red_lamp_check(s: ExitStack) -> None:
    def lamp_alarms(real: Any) -> Any:
        def deaf(self: Any, signal: str) -> None:
            real(self, signal)
            self.signals[signal].red_dark = False
        return deaf
    wrap(s, core.Core, "_lamp_alarms", lamp_alarms)


def no_red_lamp_transfer_on_the_line(s: ExitStack) -> None:
    wrap(s, autoblock.AutoBlock, "update", lambda real: lambda self, out, clear, proven, red_dark=(),
          reversed_lines=(): real(self, out, clear, proven, (), reversed_lines))


def no_lamp_proving(s: ExitStack) -> None:
    patch(s, core.Core, "proven", lambda self, signal, aspect: aspect)


def deaf_to_flash_check(s: ExitStack) -> None:
    patch(s, RelayBoard, "flasher_ok", lambda self, signal: True)


def deaf_to_doors(s: ExitStack) -> None:
    patch(s, RelayBoard, "doors_safe", lambda self, key: True)


def no_64d_check(s: ExitStack) -> None:
    def liaison(real: Any) -> Any:
        def careless(self: Any, r: Route) -> str:
            why = real(self, r)
            return "" if why.startswith("block line") else why
        return careless
    wrap(s, core.Core, "liaison_blocker", liaison)


def block_over_occupied_line(s: ExitStack) -> None:
    def blind(real: Any) -> Any:
        def careless(self: Any, action: str, section_clear: bool = True) -> tuple[str, str]:
            return real(self, action, True)  # type: ignore[no-any-return]
        return careless
    wrap(s, block64d.BlockLink, "operate", blind)


def station_block_ignores_neighbour(s: ExitStack) -> None:
    def blocker(real: Any) -> Any:
        def careless(self: Any, clear: Any) -> str:
            if self.state in (stationblock.StationBlockState.inbound, stationblock.StationBlockState.arriving):
                return ""
            return real(self, clear)  # type: ignore[no-any-return]
        return careless
    wrap(s, stationblock.StationBlockLink, "blocker", blocker)


def station_block_blind_to_counters(s: ExitStack) -> None:
    def blocker(real: Any) -> Any:
        def careless(self: Any, clear: Any) -> str:
            return real(self, lambda section: True)  # type: ignore[no-any-return]
        return careless

    def step(real: Any) -> Any:
        def careless(self: Any, departing: bool, clear: Any, *args: Any) -> None:
            real(self, departing, lambda section: True, *args)
        return careless
    wrap(s, stationblock.StationBlockLink, "blocker", blocker)
    wrap(s, stationblock.StationBlockLink, "step", step)


def guide_lock_ignores_doors(s: ExitStack) -> None:
    patch(s, core.Core, "guide_only_doors", lambda self, signal: [])


def line_without_block_unchecked(s: ExitStack) -> None:
    patch(s, derive._Builder, "_line_beyond", lambda self, node, d: ())


def against_running_allowed(s: ExitStack) -> None:
    patch(s, core.Core, "against_running", lambda self, link: "")


def guide_stays_open(s: ExitStack) -> None:
    def guide(real: Any) -> Any:
        def late(self: Any, signal: str, *args: Any) -> Result:
            result = real(self, signal, *args)
            rs = self.core.route_of(signal)
            if rs is not None:
                rs.guide_first_clear = False  # closes only once the train is past, not when it enters
            return result  # type: ignore[no-any-return]
        return late
    wrap(s, operations.Operator, "guide", guide)


def no_power_up_lock(s: ExitStack) -> None:
    def init(real: Any) -> Any:
        def unlocked(self: Any, *args: Any, locked_at_start: bool = False, **kw: Any) -> None:
            real(self, *args, locked_at_start=False, **kw)
        return unlocked
    wrap(s, core.Core, "__init__", init)


def overlap_released_at_once(s: ExitStack) -> None:
    def release(real: Any) -> Any:
        def hasty(self: Any, rs: RouteState) -> None:
            real(self, rs)
            if rs.overlap_release_at is not None:
                rs.overlap_release_at = min(rs.overlap_release_at, self.core.now)
        return hasty
    wrap(s, lifecycle.RouteLifecycle, "_sequential_release", release)


def table_conflicts_skipped(s: ExitStack) -> None:
    patch(s, selection.Selection, "_conditional", lambda self, r, rs: "")

    def blocker(real: Any) -> Any:
        def careless(self: Any, r: Route, run_on: Any = None, **kw: Any) -> str:
            with mock.patch.object(r, "conflicts", {}):
                return real(self, r, run_on, **kw)  # type: ignore[no-any-return]
        return careless
    wrap(s, selection.Selection, "route_blocker", blocker)


def route_ignores_locked_sections(s: ExitStack) -> None:
    def blocker(real: Any) -> Any:
        def careless(self: Any, r: Route, run_on: Any = None, **kw: Any) -> str:
            why = real(self, r, run_on, **kw)
            return "" if why.startswith("section") and "is locked" in why else why
        return careless
    wrap(s, selection.Selection, "route_blocker", blocker)


def open_skip_blind_to_relays(s: ExitStack) -> None:
    def holds(self: state.OpenMemo, rs: RouteState, cycle: int, changes: Any) -> bool:
        return self.cycle == cycle - 1 and rs.route is self.route
    patch(s, state.OpenMemo, "holds", holds)


def open_skip_blind_to_the_signal_ahead(s: ExitStack) -> None:
    def unchanged(real: Any) -> Any:
        def careless(self: Any, rs: RouteState, memo: state.OpenMemo) -> bool:
            end = rs.route.end_signal
            if end is None:
                return real(self, rs, memo)  # type: ignore[no-any-return]
            with mock.patch.object(memo, "end_aspect", self.core.out.signals.get(end)):
                return real(self, rs, memo)  # type: ignore[no-any-return]
        return careless
    wrap(s, memos.Memos, "_open_unchanged", unchanged)


def rest_deaf_to_relays(s: ExitStack) -> None:
    patch(s, RelayBoard, "pending", lambda self: False)


# ---- crossings, overlaps, guide and line direction ------------------------------------------------------------------
def no_crossing_check(s: ExitStack) -> None:
    def blind(real: Any) -> Any:
        def careless(self: Any, *args: Any) -> Any:
            protection, fouling = real(self, *args)
            return protection, [f for f in fouling if f.diamond is None]
        return careless
    wrap(s, flank.Flank, "of", blind)


def overlap_fault_release_at_once(s: ExitStack) -> None:
    def at_once(self: Any, section: str, rid: str) -> Result:
        self.lifecycle.release_overlap(rid)
        return Result.accept(f"overlap of {rid} released")
    patch(s, operations.Operator, "_fault_release_overlap", at_once)


def fault_release_ahead_at_once(s: ExitStack) -> None:
    patch(s, operations.Operator, "_ahead_of_movement", lambda self, rs, i: False)


def fault_release_cuts_time_release(s: ExitStack) -> None:
    patch(s, operations.Operator, "_counting_down", staticmethod(lambda rs: False))


def time_release_ends_on_any_occupancy(s: ExitStack) -> None:
    def ends(real: Any) -> Any:
        def careless(self: Any, rs: Any) -> None:
            if any(not self.core.clear(x) for x in rs.sections):
                rs.stage, rs.entered, rs.release_at = state.RouteStage.in_use, True, None
                return
            real(self, rs)
        return careless
    wrap(s, lifecycle.RouteLifecycle, "_time_release", ends)


def direction_change_ignores_guide(s: ExitStack) -> None:
    def change(real: Any) -> Any:
        def careless(self: Any, link: str, direction: str) -> Result:
            with mock.patch.object(self.core, "guide_only", {}):
                return real(self, link, direction)  # type: ignore[no-any-return]
        return careless
    wrap(s, operations.Operator, "line_direction", change)


def home_ignores_line_direction(s: ExitStack) -> None:
    patch(s, core.Core, "line_against", lambda self, signal: "")


def overlap_from_the_yard(s: ExitStack) -> None:
    """The overlap derived where the throat beyond the end signal falls, not the approach outside the home signal."""
    def beyond(st: Any, home: str, end_signal: str, rules: Any) -> Any:
        tracks, turnouts = overlap.throat_beyond(st, end_signal)
        if not tracks or not st.model.profile:
            return None
        sig = st.signals[end_signal]
        far = st.node_at(st.topology.far_node((tracks[-1], sig.direction)))
        fall = falling(st.model.profile, st.node_at(sig.at), far, sig.direction)
        if fall <= rules.overlap_gradient_per_mille:
            return None
        sections = tuple(dict.fromkeys(st.tracks[t].section for t in tracks))
        return overlap.ProfileOverlap(end_signal, sections, tuple(turnouts), fall)
    patch(s, derive, "profile_overlap", beyond)


def through_route_in_one_order(s: ExitStack) -> None:
    """The onward route may run over the overlap only of a receiving route that is set (not one set after it, nor
    one whose overlap is timing behind its train)."""
    wrap(s, selection.Selection, "continues", lambda real: lambda self, rid, r, section: (
        rid in self.core.routes and real(self, rid, r, section)))


def guide_route_checks_occupancy(s: ExitStack) -> None:
    def blocker(real: Any) -> Any:
        def careless(self: Any, r: Route, run_on: Any = None, **kw: Any) -> str:
            return real(self, r, run_on)  # type: ignore[no-any-return]
        return careless
    wrap(s, selection.Selection, "route_blocker", blocker)


def guide_blind(s: ExitStack) -> None:
    patch(s, core.Core, "guide_only_meets", lambda self, signal, sections, leads_into: False)


# ---- timers, commands, queued moves and lamps beyond the first ---------------------------------------------------
def release_delay_tenth(s: ExitStack) -> None:
    wrap(s, operations.Operator, "release_delay", lambda real: lambda self, r: real(self, r) / 10)


def shunt_delay_for_trains(s: ExitStack) -> None:
    def delay(self: Any, r: Route) -> float:
        own = self.core.station.signals[r.signal].release_s
        return own if own is not None else float(self.core.rules.release_s["shunt"])
    patch(s, operations.Operator, "release_delay", delay)


def overlap_time_tenth(s: ExitStack) -> None:
    def add(real: Any) -> Any:
        def hasty(self: Any, routes: dict[str, Route], *args: Any) -> None:
            before = set(routes)
            real(self, routes, *args)
            for rid in set(routes) - before:
                routes[rid].overlap_release_s /= 10
        return hasty
    wrap(s, derive._Builder, "_add", add)


def guide_never_times_out(s: ExitStack) -> None:
    def forever(real: Any) -> Any:
        def careless(self: Any, *args: Any) -> None:
            patient = self.core.rules.model_copy(update={"guide_close_s": float("inf")})
            with mock.patch.object(self.core, "rules", patient):
                real(self, *args)
        return careless
    wrap(s, lifecycle.RouteLifecycle, "_keep_guide", forever)
    wrap(s, throatguide.ThroatGuide, "cycle", forever)


def power_up_release_over_occupancy(s: ExitStack) -> None:
    patched_during(s, operations.Operator, "power_up_release", lambda op: op.core, "clear", lambda section: True)


def fault_release_of_station_track(s: ExitStack) -> None:
    patched_during(s, operations.Operator, "fault_release", lambda op: op.core.station, "is_station_track",
                    lambda section: False)


def fault_release_under_open_signal(s: ExitStack) -> None:
    def release(real: Any) -> Any:
        def careless(self: Any, section: str) -> Result:
            shown = [rs for rs in self.core.routes.values()
                     if rs.stage is RouteStage.open and section in (*rs.sections, *rs.route.overlap_sections)]
            for rs in shown:
                rs.stage = RouteStage.locked
            try:
                return real(self, section)  # type: ignore[no-any-return]
            finally:
                for rs in shown:
                    if rs.stage is RouteStage.locked:
                        rs.stage = RouteStage.open
        return careless
    wrap(s, operations.Operator, "fault_release", release)


def reopen_without_conditions(s: ExitStack) -> None:
    patched_during(s, operations.Operator, "reopen", lambda op: op.core, "open_blocker", lambda rs: "")


def queued_move_under_a_vehicle(s: ExitStack) -> None:
    """A move waiting in the queue is started without looking again at its turnout's section."""
    def supervise(real: Any) -> Any:
        def careless(self: Any) -> None:
            waiting = {self.turnouts[t].section for t in self.queue}
            sound = self.clear
            with mock.patch.object(self, "clear", lambda sec: sec in waiting or sound(sec)):
                real(self)
        return careless
    wrap(s, core.Core, "_supervise_turnouts", supervise)


def second_lamp_unproved(s: ExitStack) -> None:
    """Lamp proving looks at the first lamp of an aspect only (a dark second yellow of UU goes unnoticed)."""
    def dark(self: Any, signal: str, aspect: str) -> set[str]:
        lamps = self.rules.lamps.get(aspect, [])[:1]
        out = {lamp for lamp in lamps if not self.board.lamp_ok(signal, lamp)}
        if aspect in self.rules.aspects.flashing and not self.board.flasher_ok(signal):
            out.add("flasher")
        return out
    patch(s, core.Core, "_dark", dark)


def guide_before_power_up_release(s: ExitStack) -> None:
    def guide(real: Any) -> Any:
        def careless(self: Any, signal: str, end: str | None = None, via: tuple[str, ...] = ()) -> Result:
            if end is not None or self.core.route_of(signal) is not None:
                return real(self, signal, end, via)  # type: ignore[no-any-return]
            with mock.patch.object(self.core, "power_up_locked", False):
                return real(self, signal, end, via)  # type: ignore[no-any-return]
        return careless
    wrap(s, operations.Operator, "guide", guide)

"""Seeded defects (mutants) of the interlocking, to show that ``liansuo verify`` and the safety oracle catch them.

Each mutant changes the interlocking's code for as long as it is applied (a context manager patching one method or
function), the way a plausible programming or design mistake would: a conflict class dropped from the table, a
protection turnout forgotten, a lock not asked, a release without its three-point check. None touches the oracle,
verify or the station data. ``liansuo mutate`` runs each against verify (and, if verify misses it, a short random
run under the oracle) and reports the score (docs/safety.md).
"""

from __future__ import annotations

from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from dataclasses import dataclass
from typing import Any
from unittest import mock

import liansuo.interlocking.autoblock as autoblock
import liansuo.interlocking.block64d as block64d
import liansuo.interlocking.core as core
import liansuo.interlocking.lifecycle as lifecycle
import liansuo.interlocking.locks as locks
import liansuo.interlocking.operations as operations
import liansuo.interlocking.state as state
import liansuo.interlocking.stationblock as stationblock
import liansuo.interlocking.table.conflicts as conflicts
import liansuo.interlocking.table.derive as derive
import liansuo.interlocking.table.overlap as overlap
from liansuo.interlocking.io import RelayBoard, Result
from liansuo.interlocking.state import RouteStage, RouteState
from liansuo.interlocking.table.route import Route
from liansuo.kit.native import native_modules
from liansuo.stations.profile import falling

Apply = Callable[[ExitStack], None]


@dataclass(frozen=True)
class Mutant:
    name: str
    what: str  # the defect, in words
    apply: Apply
    # where the defect shows (a bundled name, an example station's file name or hub:T:N): tried there first, so a
    # run stops early; the other stations are still tried after it when it is not caught there
    first: str = ""

    @contextmanager
    def applied(self) -> Iterator[None]:
        compiled = [m for m in native_modules() if m.startswith("liansuo.interlocking.")]
        if compiled:  # a patch of a compiled module would change nothing, and the defect would go untried
            raise RuntimeError(f"mutant {self.name}: the interlocking runs compiled ({', '.join(compiled)}); seeded "
                               "defects need its Python sources (LIANSUO_PURE=1, or run_mutants)")
        with ExitStack() as stack:
            self.apply(stack)
            yield


def _patch(stack: ExitStack, owner: object, attr: str, new: Any) -> None:
    stack.enter_context(mock.patch.object(owner, attr, new))


def _wrap(stack: ExitStack, owner: object, attr: str, make: Callable[[Any], Any]) -> None:
    _patch(stack, owner, attr, make(getattr(owner, attr)))


# ---- the table ------------------------------------------------------------------------------------------------------
def _no_head_on(s: ExitStack) -> None:
    _wrap(s, derive, "derive_conflicts",
          lambda real: lambda routes, rules, is_track: real(routes, rules.model_copy(update={"enemy_onto_track": []}),
                                                            is_track))


def _no_diamonds(s: ExitStack) -> None:
    def build(real: Any) -> Any:
        def without(self: Any) -> Any:
            saved, self.st.crossings = self.st.crossings, {}
            try:
                return real(self)
            finally:
                self.st.crossings = saved
        return without
    _wrap(s, derive._Builder, "build", build)


def _no_protection(s: ExitStack) -> None:
    _wrap(s, derive._Builder, "_flank", lambda real: lambda self, *a: ({}, real(self, *a)[1]))


def _guide_over_lost_indication(s: ExitStack) -> None:
    def blind(real: Any) -> Any:
        def open_blocker(self: Any, rs: RouteState, *, guide: bool = False, **kw: Any) -> str:
            why = real(self, rs, guide=guide, **kw)
            return "" if guide and why.startswith("turnout") else why
        return open_blocker
    _wrap(s, core.Core, "open_blocker", blind)


def _no_run_on(s: ExitStack) -> None:
    _patch(s, derive._Builder, "_run_on", lambda self, end, d, tracks, turnouts: (None, ()))


def _no_overlap(s: ExitStack) -> None:
    def add(real: Any) -> Any:
        def without(self: Any, routes: dict[str, Route], *args: Any) -> None:
            before = set(routes)
            real(self, routes, *args)
            for rid in set(routes) - before:
                routes[rid].overlap_sections, routes[rid].overlap_turnouts = (), ()
        return without
    _wrap(s, derive._Builder, "_add", add)


def _approach_one_section(s: ExitStack) -> None:
    def one(self: Any, signal: str) -> tuple[str, ...]:
        rear = self.st.signal_rear_track(signal)
        return (self.st.tracks[rear].section,) if rear else ()
    _patch(s, derive._Builder, "_approach", one)


def _no_conflict_table(s: ExitStack) -> None:
    _patch(s, conflicts, "_bulk", lambda routes, en, simple: None)
    _patch(s, conflicts, "_with_run_on", lambda routes, en: None)


# ---- the running interlocking ---------------------------------------------------------------------------------------
def _usu_without_onward(s: ExitStack) -> None:
    _patch(s, core, "onward_allows_usu", lambda station, turnouts, rules: True)


def _throw_ignores_locks(s: ExitStack) -> None:
    def throw(real: Any) -> Any:
        def careless(self: Any, name: str, position: str) -> Result:
            with mock.patch.object(self.il.locks, "why_turnout", lambda t: ""):
                return real(self, name, position)  # type: ignore[no-any-return]
        return careless
    _wrap(s, operations.Operator, "throw", throw)


def _throw_ignores_section_locks(s: ExitStack) -> None:
    def own(self: Any, turnout: str) -> list[Any]:
        return [(lk, "") for lk in sorted(self.turnouts.get(turnout, ()), key=locks._order)]
    _patch(s, locks.LockLedger, "_own_locks", own)


def _open_blocker_ignoring(s: ExitStack, ignored: Callable[[str], bool]) -> None:
    """The signal opens and stays open whenever the only thing against it is a reason ``ignored`` accepts."""
    def blind(real: Any) -> Any:
        def open_blocker(self: Any, rs: RouteState, **kw: Any) -> str:
            why = real(self, rs, **kw)
            return "" if ignored(why) else why
        return open_blocker
    _wrap(s, core.Core, "open_blocker", blind)


def _blind_to_occupancy(s: ExitStack) -> None:
    _open_blocker_ignoring(s, lambda why: why.endswith("is occupied"))


def _blind_to_indication(s: ExitStack) -> None:
    _open_blocker_ignoring(s, lambda why: why.startswith("turnout"))


def _reopens_by_itself(s: ExitStack) -> None:
    def advance(real: Any) -> Any:
        def forgetful(self: Any, rs: RouteState) -> None:
            if rs.stage is RouteStage.closed:
                rs.stage = RouteStage.locked
            real(self, rs)
        return forgetful
    _wrap(s, lifecycle.RouteLifecycle, "advance", advance)


def _no_three_point_check(s: ExitStack) -> None:
    def release(self: Any, rs: RouteState) -> None:  # a section releases once it is clear again, whatever is next
        secs = rs.sections
        for i, sec in enumerate(secs):
            if not rs.released[i] and not self.il.clear(sec):
                rs.was_occupied[i] = True
        for i, sec in enumerate(secs):
            if not rs.released[i] and rs.was_occupied[i] and (self.il.clear(sec) or i == len(secs) - 1):
                self.release_section(rs, i)
        if all(rs.released):
            self.finish(rs, all_sections=False)
    _patch(s, lifecycle.RouteLifecycle, "_sequential_release", release)


def _cancel_ignores_approach(s: ExitStack) -> None:
    _patch(s, lifecycle.RouteLifecycle, "approach_locked", lambda self, rs: False)


def _no_release_delay(s: ExitStack) -> None:
    _patch(s, operations.Operator, "release_delay", lambda self, r: 0.0)


def _no_red_lamp_check(s: ExitStack) -> None:
    def lamp_alarms(real: Any) -> Any:
        def deaf(self: Any, signal: str) -> None:
            real(self, signal)
            self.signals[signal].red_dark = False
        return deaf
    _wrap(s, core.Core, "_lamp_alarms", lamp_alarms)


def _no_red_lamp_transfer_on_the_line(s: ExitStack) -> None:
    _wrap(s, autoblock.AutoBlock, "update", lambda real: lambda self, out, clear, proven, red_dark=(),
          reversed_lines=(): real(self, out, clear, proven, (), reversed_lines))


def _no_lamp_proving(s: ExitStack) -> None:
    _patch(s, core.Core, "proven", lambda self, signal, aspect: aspect)


def _deaf_to_flash_check(s: ExitStack) -> None:
    _patch(s, RelayBoard, "flasher_ok", lambda self, signal: True)


def _deaf_to_doors(s: ExitStack) -> None:
    _patch(s, RelayBoard, "doors_safe", lambda self, key: True)


def _no_64d_check(s: ExitStack) -> None:
    def liaison(real: Any) -> Any:
        def careless(self: Any, r: Route) -> str:
            why = real(self, r)
            return "" if why.startswith("block line") else why
        return careless
    _wrap(s, core.Core, "liaison_blocker", liaison)


def _block_over_occupied_line(s: ExitStack) -> None:
    def blind(real: Any) -> Any:
        def careless(self: Any, action: str, section_clear: bool = True) -> tuple[str, str]:
            return real(self, action, True)  # type: ignore[no-any-return]
        return careless
    _wrap(s, block64d.BlockLink, "operate", blind)


def _station_block_ignores_neighbour(s: ExitStack) -> None:
    def blocker(real: Any) -> Any:
        def careless(self: Any, clear: Any) -> str:
            if self.state in (stationblock.StationBlockState.inbound, stationblock.StationBlockState.arriving):
                return ""
            return real(self, clear)  # type: ignore[no-any-return]
        return careless
    _wrap(s, stationblock.StationBlockLink, "blocker", blocker)


def _station_block_blind_to_counters(s: ExitStack) -> None:
    def blocker(real: Any) -> Any:
        def careless(self: Any, clear: Any) -> str:
            return real(self, lambda section: True)  # type: ignore[no-any-return]
        return careless

    def step(real: Any) -> Any:
        def careless(self: Any, departing: bool, clear: Any, *args: Any) -> None:
            real(self, departing, lambda section: True, *args)
        return careless
    _wrap(s, stationblock.StationBlockLink, "blocker", blocker)
    _wrap(s, stationblock.StationBlockLink, "step", step)


def _guide_lock_ignores_doors(s: ExitStack) -> None:
    _patch(s, core.Core, "guide_only_doors", lambda self, signal: [])


def _line_without_block_unchecked(s: ExitStack) -> None:
    _patch(s, derive._Builder, "_line_beyond", lambda self, node, d: ())


def _against_running_allowed(s: ExitStack) -> None:
    _patch(s, core.Core, "against_running", lambda self, link: "")


def _guide_stays_open(s: ExitStack) -> None:
    def guide(real: Any) -> Any:
        def late(self: Any, signal: str, *args: Any) -> Result:
            result = real(self, signal, *args)
            rs = self.il.route_of(signal)
            if rs is not None:
                rs.guide_first_clear = False  # closes only once the train is past, not when it enters
            return result  # type: ignore[no-any-return]
        return late
    _wrap(s, operations.Operator, "guide", guide)


def _no_power_up_lock(s: ExitStack) -> None:
    def init(real: Any) -> Any:
        def unlocked(self: Any, *args: Any, locked_at_start: bool = False, **kw: Any) -> None:
            real(self, *args, locked_at_start=False, **kw)
        return unlocked
    _wrap(s, core.Core, "__init__", init)


def _overlap_released_at_once(s: ExitStack) -> None:
    def release(real: Any) -> Any:
        def hasty(self: Any, rs: RouteState) -> None:
            real(self, rs)
            if rs.overlap_release_at is not None:
                rs.overlap_release_at = min(rs.overlap_release_at, self.il.now)
        return hasty
    _wrap(s, lifecycle.RouteLifecycle, "_sequential_release", release)


def _table_conflicts_skipped(s: ExitStack) -> None:
    _patch(s, operations.Operator, "_conditional", lambda self, r, rs: "")

    def blocker(real: Any) -> Any:
        def careless(self: Any, r: Route, run_on: Any = None, **kw: Any) -> str:
            with mock.patch.object(r, "conflicts", {}):
                return real(self, r, run_on, **kw)  # type: ignore[no-any-return]
        return careless
    _wrap(s, operations.Operator, "route_blocker", blocker)


def _route_ignores_locked_sections(s: ExitStack) -> None:
    def blocker(real: Any) -> Any:
        def careless(self: Any, r: Route, run_on: Any = None, **kw: Any) -> str:
            why = real(self, r, run_on, **kw)
            return "" if why.startswith("section") and "is locked" in why else why
        return careless
    _wrap(s, operations.Operator, "route_blocker", blocker)


def _open_skip_blind_to_relays(s: ExitStack) -> None:
    def holds(self: state.OpenMemo, rs: RouteState, cycle: int, changes: Any) -> bool:
        return self.cycle == cycle - 1 and rs.route is self.route
    _patch(s, state.OpenMemo, "holds", holds)


def _open_skip_blind_to_the_signal_ahead(s: ExitStack) -> None:
    def unchanged(real: Any) -> Any:
        def careless(self: Any, rs: RouteState, memo: state.OpenMemo) -> bool:
            end = rs.route.end_signal
            if end is None:
                return real(self, rs, memo)  # type: ignore[no-any-return]
            with mock.patch.object(memo, "end_aspect", self.il.out.signals.get(end)):
                return real(self, rs, memo)  # type: ignore[no-any-return]
        return careless
    _wrap(s, lifecycle.RouteLifecycle, "_open_unchanged", unchanged)


def _rest_deaf_to_relays(s: ExitStack) -> None:
    _patch(s, RelayBoard, "pending", lambda self: False)


# ---- crossings, overlaps, guide and line direction ------------------------------------------------------------------
def _no_crossing_check(s: ExitStack) -> None:
    def flank(real: Any) -> Any:
        def careless(self: Any, *args: Any) -> Any:
            protection, fouling = real(self, *args)
            return protection, [f for f in fouling if f.diamond is None]
        return careless
    _wrap(s, derive._Builder, "_flank", flank)


def _overlap_fault_release_at_once(s: ExitStack) -> None:
    def at_once(self: Any, section: str, rid: str) -> Result:
        self.lifecycle.release_overlap(rid)
        return Result.accept(f"overlap of {rid} released")
    _patch(s, operations.Operator, "_fault_release_overlap", at_once)


def _fault_release_ahead_at_once(s: ExitStack) -> None:
    _patch(s, operations.Operator, "_ahead_of_movement", lambda self, rs, i: False)


def _fault_release_cuts_time_release(s: ExitStack) -> None:
    _patch(s, operations.Operator, "_counting_down", staticmethod(lambda rs: False))


def _time_release_ends_on_any_occupancy(s: ExitStack) -> None:
    def ends(real: Any) -> Any:
        def careless(self: Any, rs: Any) -> None:
            if any(not self.il.clear(x) for x in rs.sections):
                rs.stage, rs.entered, rs.release_at = state.RouteStage.in_use, True, None
                return
            real(self, rs)
        return careless
    _wrap(s, lifecycle.RouteLifecycle, "_time_release", ends)


def _patched_during(stack: ExitStack, owner: object, method: str, target: Callable[[Any], object], attr: str,
                    value: Any) -> None:
    """``owner.method`` runs with ``attr`` of ``target(self)`` replaced by ``value``: a check it asks left out."""
    def make(real: Any) -> Any:
        def careless(self: Any, *args: Any) -> Any:
            with mock.patch.object(target(self), attr, value):
                return real(self, *args)
        return careless
    _wrap(stack, owner, method, make)


def _direction_change_ignores_guide(s: ExitStack) -> None:
    def change(real: Any) -> Any:
        def careless(self: Any, link: str, direction: str) -> Result:
            with mock.patch.object(self.il, "guide_only", {}):
                return real(self, link, direction)  # type: ignore[no-any-return]
        return careless
    _wrap(s, operations.Operator, "line_direction", change)


def _home_ignores_line_direction(s: ExitStack) -> None:
    _patch(s, core.Core, "line_against", lambda self, signal: "")


def _overlap_from_the_yard(s: ExitStack) -> None:
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
    _patch(s, derive, "profile_overlap", beyond)


def _through_route_in_one_order(s: ExitStack) -> None:
    """The onward route may run over the overlap only of a receiving route that is set (not one set after it, nor
    one whose overlap is timing behind its train)."""
    _wrap(s, operations.Operator, "_continues", lambda real: lambda self, rid, r, section: (
        rid in self.il.routes and real(self, rid, r, section)))


def _guide_route_checks_occupancy(s: ExitStack) -> None:
    def blocker(real: Any) -> Any:
        def careless(self: Any, r: Route, run_on: Any = None, **kw: Any) -> str:
            return real(self, r, run_on)  # type: ignore[no-any-return]
        return careless
    _wrap(s, operations.Operator, "route_blocker", blocker)


def _guide_blind(s: ExitStack) -> None:
    _patch(s, core.Core, "guide_only_meets", lambda self, signal, sections, leads_into: False)


# ---- timers, commands, queued moves and lamps beyond the first ---------------------------------------------------
def _release_delay_tenth(s: ExitStack) -> None:
    _wrap(s, operations.Operator, "release_delay", lambda real: lambda self, r: real(self, r) / 10)


def _shunt_delay_for_trains(s: ExitStack) -> None:
    def delay(self: Any, r: Route) -> float:
        own = self.il.station.signals[r.signal].release_s
        return own if own is not None else float(self.il.rules.release_s["shunt"])
    _patch(s, operations.Operator, "release_delay", delay)


def _overlap_time_tenth(s: ExitStack) -> None:
    def add(real: Any) -> Any:
        def hasty(self: Any, routes: dict[str, Route], *args: Any) -> None:
            before = set(routes)
            real(self, routes, *args)
            for rid in set(routes) - before:
                routes[rid].overlap_release_s /= 10
        return hasty
    _wrap(s, derive._Builder, "_add", add)


def _guide_never_times_out(s: ExitStack) -> None:
    def forever(real: Any) -> Any:
        def careless(self: Any, *args: Any) -> None:
            patient = self.il.rules.model_copy(update={"guide_close_s": float("inf")})
            with mock.patch.object(self.il, "rules", patient):
                real(self, *args)
        return careless
    _wrap(s, lifecycle.RouteLifecycle, "_keep_guide", forever)
    _wrap(s, lifecycle.RouteLifecycle, "_guide_only", forever)


def _power_up_release_over_occupancy(s: ExitStack) -> None:
    _patched_during(s, operations.Operator, "power_up_release", lambda op: op.il, "clear", lambda section: True)


def _fault_release_of_station_track(s: ExitStack) -> None:
    _patched_during(s, operations.Operator, "fault_release", lambda op: op.il.station, "is_station_track",
                    lambda section: False)


def _fault_release_under_open_signal(s: ExitStack) -> None:
    def release(real: Any) -> Any:
        def careless(self: Any, section: str) -> Result:
            shown = [rs for rs in self.il.routes.values()
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
    _wrap(s, operations.Operator, "fault_release", release)


def _reopen_without_conditions(s: ExitStack) -> None:
    _patched_during(s, operations.Operator, "reopen", lambda op: op.il, "open_blocker", lambda rs: "")


def _queued_move_under_a_vehicle(s: ExitStack) -> None:
    """A move waiting in the queue is started without looking again at its turnout's section."""
    def supervise(real: Any) -> Any:
        def careless(self: Any) -> None:
            waiting = {self.turnouts[t].section for t in self.queue}
            sound = self.clear
            with mock.patch.object(self, "clear", lambda sec: sec in waiting or sound(sec)):
                real(self)
        return careless
    _wrap(s, core.Core, "_supervise_turnouts", supervise)


def _second_lamp_unproved(s: ExitStack) -> None:
    """Lamp proving looks at the first lamp of an aspect only (a dark second yellow of UU goes unnoticed)."""
    def dark(self: Any, signal: str, aspect: str) -> set[str]:
        lamps = self.rules.lamps.get(aspect, [])[:1]
        out = {lamp for lamp in lamps if not self.board.lamp_ok(signal, lamp)}
        if aspect in self.rules.aspects.flashing and not self.board.flasher_ok(signal):
            out.add("flasher")
        return out
    _patch(s, core.Core, "_dark", dark)


def _guide_before_power_up_release(s: ExitStack) -> None:
    def guide(real: Any) -> Any:
        def careless(self: Any, signal: str, end: str | None = None, via: tuple[str, ...] = ()) -> Result:
            if end is not None or self.il.route_of(signal) is not None:
                return real(self, signal, end, via)  # type: ignore[no-any-return]
            with mock.patch.object(self.il, "power_up_locked", False):
                return real(self, signal, end, via)  # type: ignore[no-any-return]
        return careless
    _wrap(s, operations.Operator, "guide", guide)


MUTANTS: tuple[Mutant, ...] = (
    Mutant("no-head-on-enemies", "the table leaves out opposing routes onto one track (train against train or "
           "shunting movement)", _no_head_on),
    Mutant("no-diamond", "the table ignores diamond crossings: no conflict, no protection of the crossing track",
           _no_diamonds, first="shuangxian"),
    Mutant("no-flank-protection", "the table lists no flank protection turnouts", _no_protection, first="doubleslip"),
    Mutant("guide-over-lost-indication", "the guide aspect opens over a route with a turnout out of position or "
           "without indication", _guide_over_lost_indication),
    Mutant("no-run-on", "a shunting route ending at a signal of the other direction stops there on paper; the "
           "movement runs on unprotected", _no_run_on),
    Mutant("no-overlap", "receiving routes lock no overlap (延续进路)", _no_overlap, first="danxian"),
    Mutant("approach-one-section", "approach locking is one section everywhere, whatever the line",
           _approach_one_section, first="shuangxian"),
    Mutant("empty-conflict-table", "the table lists no conflicting routes at all", _no_conflict_table),
    Mutant("usu-without-onward-check", "USU is given whatever turnouts the onward route diverges over",
           _usu_without_onward, first="shuangxian"),
    Mutant("throw-ignores-locks", "individual operation moves a locked turnout", _throw_ignores_locks),
    Mutant("throw-ignores-section-locks", "a turnout standing in a locked section is not locked with it",
           _throw_ignores_section_locks),
    Mutant("blind-to-occupancy", "a signal opens and stays open over an occupied section", _blind_to_occupancy),
    Mutant("blind-to-indication", "a signal opens and stays open over a turnout without indication",
           _blind_to_indication),
    Mutant("reopens-by-itself", "a signal closed abnormally reopens once the fault is gone", _reopens_by_itself),
    Mutant("no-three-point-check", "sections release as soon as they are clear, without the three-point check",
           _no_three_point_check),
    Mutant("cancel-ignores-approach", "a route is cancelled at once with a train approaching",
           _cancel_ignores_approach),
    Mutant("no-release-delay", "manual time release releases at once", _no_release_delay),
    Mutant("no-red-lamp-check", "a dark red lamp goes unnoticed: no red lamp transfer (红灯转移)",
           _no_red_lamp_check),
    Mutant("no-red-lamp-transfer-on-the-line", "the block signal in rear of a dark red lamp is not held at H",
           _no_red_lamp_transfer_on_the_line, first="shuangxian"),
    Mutant("no-lamp-proving", "a dark lamp does not change the aspect commanded", _no_lamp_proving),
    Mutant("deaf-to-flash-check", "USU is kept with the flasher's check relay down", _deaf_to_flash_check,
           first="shuangxian"),
    Mutant("deaf-to-doors", "signals open with screen doors open", _deaf_to_doors, first="shuangxian"),
    Mutant("no-64d-acceptance", "a 64D departure opens without the neighbour's acceptance", _no_64d_check),
    Mutant("64d-block-over-occupied-line", "a 64D block is given with the line's departure section occupied",
           _block_over_occupied_line),
    Mutant("station-block-ignores-neighbour", "a departure onto a station-block line opens although the neighbour "
           "has blocked the line for its own train", _station_block_ignores_neighbour, first="danxian"),
    Mutant("station-block-blind-to-counters", "the station block never reads the line's axle counters: a "
           "departure opens with the line showing occupied", _station_block_blind_to_counters, first="danxian"),
    Mutant("line-without-block-unchecked", "a departure onto a line with no block described ignores the line's "
           "track circuits", _line_without_block_unchecked, first="hub:10:4"),
    Mutant("against-running-direction", "a departure against a line's running direction opens without 改方",
           _against_running_allowed, first="shuangxian"),
    Mutant("guide-lock-ignores-doors", "the guide aspect under guide total lock ignores the screen doors",
           _guide_lock_ignores_doors, first="shuangxian"),
    Mutant("guide-stays-open", "the guide aspect stays lit after the guided train has entered", _guide_stays_open),
    Mutant("no-power-up-lock", "after the interlocking starts, the station is not locked", _no_power_up_lock),
    Mutant("overlap-released-at-once", "the overlap releases as soon as the train is on the receiving track",
           _overlap_released_at_once, first="danxian"),
    Mutant("table-conflicts-skipped", "route setting skips the table's conflicts (only locked sections and "
           "turnouts stop it)", _table_conflicts_skipped),
    Mutant("open-signal-unwatched", "an open signal is not looked at again while it was fine last cycle, whatever "
           "relay changed since", _open_skip_blind_to_relays),
    Mutant("open-signal-blind-ahead", "an open signal keeps its aspect when the signal ahead changes",
           _open_skip_blind_to_the_signal_ahead),
    Mutant("rest-deaf-to-relays", "the interlocking at rest sleeps on through relay changes, until a command or "
           "a timer wakes it", _rest_deaf_to_relays),
    Mutant("route-over-locked-sections", "route setting ignores sections other routes hold (an overlap after its "
           "route has released)", _route_ignores_locked_sections, first="danxian"),
    Mutant("no-crossing-check", "a route over a diamond crossing does not check the section of the track that "
           "crosses it", _no_crossing_check, first="jiaocha"),
    Mutant("overlap-fault-release-at-once", "a section fault release of an overlap is carried out at once, under "
           "the open signal or with a train approaching", _overlap_fault_release_at_once, first="danxian"),
    Mutant("fault-release-ahead-at-once", "a section fault release ahead of a movement in its route is carried out "
           "at once", _fault_release_ahead_at_once),
    Mutant("fault-release-cuts-time-release", "a section fault release given while its route counts down a time "
           "release frees the route at once when the approach shows clear", _fault_release_cuts_time_release),
    Mutant("time-release-ends-on-any-occupancy", "a manual time release ends as if a movement had entered when any "
           "section of the route shows occupied", _time_release_ends_on_any_occupancy),
    Mutant("direction-change-ignores-guide", "the line's direction changes while a guide aspect calls a train in "
           "from it", _direction_change_ignores_guide, first="podao"),
    Mutant("home-ignores-line-direction", "a home signal receives from a line set for departures from the station",
           _home_ignores_line_direction, first="podao"),
    Mutant("overlap-from-the-yard", "the overlap is derived from the gradient beyond the end signal, not from the "
           "approach outside the home signal", _overlap_from_the_yard, first="podao"),
    Mutant("through-route-in-one-order", "a through movement is refused when its departure is set first or its "
           "overlap is timing", _through_route_in_one_order, first="danxian"),
    Mutant("guide-route-checks-occupancy", "a guide route is refused over the occupied section it is meant for",
           _guide_route_checks_occupancy),
    Mutant("guide-blind", "routes and guide aspects ignore a guide aspect lit under guide total lock",
           _guide_blind),
    Mutant("release-delay-a-tenth", "a manual time release waits a tenth of its delay (18 s for 180 s)",
           _release_delay_tenth),
    Mutant("shunt-delay-for-trains", "a manual time release of a train route waits the shunting delay (30 s)",
           _shunt_delay_for_trains),
    Mutant("overlap-time-a-tenth", "the overlap releases a tenth of its time after the train reached the receiving "
           "track", _overlap_time_tenth, first="danxian"),
    Mutant("guide-never-times-out", "an unused guide aspect stays lit for ever", _guide_never_times_out),
    Mutant("power-up-release-over-occupancy", "the power-up release is given with sections showing occupied",
           _power_up_release_over_occupancy),
    Mutant("fault-release-of-station-track", "a section fault release of a station track is carried out",
           _fault_release_of_station_track),
    Mutant("fault-release-under-open-signal", "a section fault release is carried out under the open signal",
           _fault_release_under_open_signal),
    Mutant("reopen-without-conditions", "a signal closed abnormally is reopened without its conditions checked",
           _reopen_without_conditions),
    Mutant("queued-move-under-a-vehicle", "a turnout move waiting in the queue starts without looking again at "
           "its section", _queued_move_under_a_vehicle),
    Mutant("second-lamp-unproved", "lamp proving looks at an aspect's first lamp only", _second_lamp_unproved),
    Mutant("guide-before-power-up-release", "a guide aspect under guide total lock is given before the power-up "
           "release", _guide_before_power_up_release),
)

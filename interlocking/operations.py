"""Operator commands of the CBI console (操作表示机). Each returns a :class:`Result`; a refusal says why in a
signaller's terms. Commands act on the current state at once; the routes then progress cycle by cycle."""

from __future__ import annotations

from liansuo.stations.schema import Button, SignalKind

from .aspects import stop_aspect
from .engine import INTERLOCKED, Engine
from .io import Result
from .locks import Hold
from .route import Condition, Kind, Route, RunOn
from .state import RouteStage, RouteState

_KIND_WORD = {"train": "train", "shunt": "shunting"}


class Interlocking(Engine):
    """A station's CBI: the cycle of :class:`~interlocking.engine.Engine` plus the operator's commands."""

    # ---- route setting ----------------------------------------------------------------------------------------
    def set_route(self, kind: Kind, start: str, end: str, via: tuple[str, ...] = ()) -> Result:
        """Select a route by its start, optional variant and end buttons (列车/调车进路)."""
        st = self.station
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
        r = self.table.by_buttons(kind, start, end, via)
        if r is None:
            options = sorted(x.id for x in self.table.routes.values() if x.kind == kind and x.start == start)
            return Result.refuse(f"no {_KIND_WORD[kind]} route from {start} to {end}"
                                 + (" via " + ",".join(via) if via else "")
                                 + (f"; routes from {start}: {', '.join(options)}" if options else ""))
        run_on, why = self.choose_run_on(r)
        if not why:
            why = self.route_blocker(r, run_on)
        if why:
            return Result.refuse(why)
        rs = RouteState(r, RouteStage.setting, self.now, run_on=run_on)
        self.routes[r.id] = rs
        self.by_signal[r.signal] = r.id
        for s in rs.sections:
            self.locks.lock_section(s, Hold.route, r.id)
        for f in r.fouling:
            self.locks.lock_section(f.section, Hold.fouling, r.id)
        for s in r.overlap_sections:
            self.locks.lock_section(s, Hold.overlap, r.id)
        for t in rs.turnouts:
            self.locks.lock_turnout(t.id, Hold.route, r.id)
        for t in r.overlap_turnouts:
            self.locks.lock_turnout(t.id, Hold.overlap, r.id)
        for t in rs.all_turnouts:
            if self.board.indication(t.id) != t.position.value:
                self.request_move(t.id, t.position.value)
        self.codes_dirty = True
        self.event("route", f"route {r.id} selected")
        return Result.accept(f"route {r.id} selected")

    def choose_run_on(self, r: Route) -> tuple[RunOn | None, str]:
        """The way a shunting movement runs on past the end of ``r``, as the turnouts beyond lie; or why it cannot
        be told (a turnout beyond without indication)."""
        if not r.run_on:
            return None, ""
        lies = {t: self.board.indication(t) for ro in r.run_on for t, _ in ro.when}
        ro = r.run_on_for(lies)
        if ro is not None:
            return ro, ""
        lost = sorted(t for t, pos in lies.items() if pos is None)
        return None, (f"turnout {lost[0] if lost else '?'} beyond {r.end} has no indication: a shunting movement "
                      f"running on past {r.end} could go either way")

    def route_blocker(self, r: Route, run_on: RunOn | None = None) -> str:
        """Why ``r`` (running on over ``run_on``) may not be set now; '' when it may."""
        if self.power_up_locked:
            return "the station is locked since the interlocking started (上电锁闭): give the power-up release first"
        if r.signal in self.by_signal:
            return f"signal {r.signal} already has route {self.by_signal[r.signal]} set"
        if r.exit_link in self.auto_links:
            why = self.against_running(r.exit_link)
            if why:
                return why
        for other, rs in self.routes.items():
            why = r.conflicts.get(other) or self._conditional(r, rs)
            held = self._still_conflicts(rs, r, run_on) if why else ""
            if held:
                return f"conflicting route {other} is locked ({held})"
        sections = list(r.sections) + (list(run_on.sections) if run_on else []) + list(r.overlap_sections)
        for s in [*sections, *(f.section for f in r.fouling)]:
            for lk in self.locks.section_locks(s):
                if lk.hold is Hold.fouling and s not in sections:
                    continue  # several routes may check the same fouling section
                if lk.hold is Hold.overlap and lk.holder in self.routes and self._continues(lk.holder, r, s):
                    continue  # the onward route of a through movement runs over the overlap
                if lk.hold is Hold.power_up:
                    return self.route_blocker_power_up(s)
                return f"section {s} is locked {lk.words()}"
            if not self.clear(s):
                return f"section {s} is occupied"
        turnouts = r.all_turnouts + (run_on.turnouts if run_on else ())
        for t in turnouts:
            if t.id in self.locks.blocked:
                return f"turnout {t.id} is single-blocked (单封)"
            for member in self.pair_members(t.id):
                if self.board.indication(member) == t.position.value:
                    continue
                why = self.locks.why_turnout(member)
                if why:
                    return f"{why}; the route needs it {t.position.value}"
                if not self.clear(self.turnouts[member].section):
                    return f"turnout {member} cannot move: section {self.turnouts[member].section} is occupied"
        return ""

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
        return all(self.board.indication(t) in (p.value, None) for t, p in cond)

    def _continues(self, rid: str, r: Route, section: str) -> bool:
        """``r`` continues active route ``rid`` from its end signal in the same direction over its overlap."""
        first = self.routes[rid].route
        return (r.signal == first.end_signal and r.direction is first.direction
                and section in first.overlap_sections and section not in first.sections)

    def _still_conflicts(self, rs: RouteState, r: Route, run_on: RunOn | None) -> str:
        """What the active route ``rs`` still holds that ``r`` needs, in a signaller's words; '' when nothing.
        Sections released behind a train are free for the next route, as in a real CBI, even while the rest of the
        train's route is still locked. An enemy that leads head-on onto a track stays one while it holds (or leads
        into) that track."""
        held = {s for i, s in enumerate(rs.sections) if not rs.released[i]}
        wanted = set(r.all_sections) | (set(run_on.sections) if run_on else set())
        shared = sorted(wanted & (held | {f.section for f in rs.route.fouling} | set(rs.route.overlap_sections)))
        if shared:
            return f"section {shared[0]}"
        track = r.head_on.get(rs.id)
        if track is not None:
            theirs = rs.run_on.leads_into if rs.run_on else rs.route.leads_into
            if track in held or (theirs == track and bool(held)):
                return f"both lead onto {track} from opposite ends"
        need = {t.id: t.position for t in r.all_turnouts + (run_on.turnouts if run_on else ())}
        for t in rs.all_turnouts:
            if t.id in need and need[t.id] is not t.position and rs.id in self.locks.holders(t.id):
                return f"turnout {t.id} {t.position.value}/{need[t.id].value}"
        crossings = self.station.crossings
        for track_id in rs.route.path.tracks:
            diamonds = [d for d, _ in crossings.get(track_id, ()) if d in r.diamonds]
            if diamonds and self.station.tracks[track_id].section in held:
                return f"diamond {diamonds[0]}"
        return ""

    def approach_locked(self, rs: RouteState) -> bool:
        """接近锁闭: the signal has been open and a train is in the approach section."""
        return rs.opened_once and any(not self.clear(s) for s in rs.route.approach)

    def _need_route(self, signal: str) -> tuple[RouteState | None, str]:
        if signal not in self.station.signals:
            return None, f"there is no signal '{signal}' at {self.station.id}"
        rs = self.route_of(signal)
        if rs is None:
            return None, f"no route is set from signal {signal}"
        return rs, ""

    # ---- cancel, manual release, section fault release, reopen ----------------------------------------------
    def cancel(self, signal: str) -> Result:
        """总取消: cancel a route at once while its approach section is clear."""
        if signal in self.guide_only:
            del self.guide_only[signal]
            self.out.set_aspect(signal, stop_aspect(self.station, signal))
            return Result.accept(f"guide aspect of {signal} cancelled")
        rs, why = self._releasable(signal)
        if rs is None:
            return Result.refuse(why)
        if self.approach_locked(rs):
            occupied = [s for s in rs.route.approach if not self.clear(s)]
            return Result.refuse(f"approach section {', '.join(occupied)} is occupied: route {rs.id} is "
                                 f"approach-locked (接近锁闭); use 'release {signal}' (manual time release)")
        self._close_if_open(rs, "route cancelled")
        self.finish(rs, all_sections=True)
        self.event("route", f"route {rs.id} cancelled")
        return Result.accept(f"route {rs.id} cancelled")

    def _close_if_open(self, rs: RouteState, reason: str) -> None:
        if self.out.signals.get(rs.route.signal) != stop_aspect(self.station, rs.route.signal):
            self.close_signal(rs, reason, abnormal=False)

    def _releasable(self, signal: str) -> tuple[RouteState | None, str]:
        """The route of ``signal`` if it may be cancelled or released by hand, or why not."""
        rs, why = self._need_route(signal)
        if rs is None:
            return None, why
        if rs.stage is RouteStage.in_use:
            return None, (f"a train has entered route {rs.id}: it releases section by section; use "
                          "fault-release for a section that stays locked")
        if rs.stage is RouteStage.time_release:
            left = (rs.release_at or self.now) - self.now
            return None, f"route {rs.id} is already being released by manual time release ({left:.0f} s left)"
        return rs, ""

    def release(self, signal: str) -> Result:
        """总人解: close the signal and release after 180 s (train) / 30 s (shunting), everything still checked."""
        rs, why = self._releasable(signal)
        if rs is None:
            return Result.refuse(why)
        if not self.approach_locked(rs):
            self._close_if_open(rs, "route released")
            self.finish(rs, all_sections=True)
            return Result.accept(f"route {rs.id} released at once: no train is approaching")
        delay = self.release_delay(rs.route)
        self._close_if_open(rs, "manual time release")
        rs.stage = RouteStage.time_release
        rs.release_at = self.now + delay
        rs.guide = False
        self.event("route", f"manual time release of {rs.id}: {delay:g} s")
        return Result.accept(f"route {rs.id} releases in {delay:g} s unless a train enters")

    def release_delay(self, r: Route) -> float:
        sig = self.station.signals[r.signal]
        if sig.release_s is not None:
            return sig.release_s
        return self.rules.release_s["shunt" if r.kind == "shunt" else "train"]

    def fault_release(self, section: str) -> Result:
        """区故解: release one locked, clear section (never a station track)."""
        st = self.station
        if section not in st.sections:
            return Result.refuse(f"there is no section '{section}' at {st.id}")
        if st.is_station_track(section):
            return Result.refuse(f"section {section} is a station track: section fault release is not allowed on "
                                 "a station track (股道)")
        locks = self.locks.section_locks(section)
        if any(lk.hold is Hold.power_up for lk in locks):
            return Result.refuse(f"section {section} is locked since the interlocking started (上电锁闭): give the "
                                 "power-up release")
        routes = [lk.holder for lk in locks if lk.hold is Hold.route and lk.holder in self.routes]
        overlaps = [lk.holder for lk in locks if lk.hold is Hold.overlap]
        if not routes and not overlaps:
            return Result.refuse(f"section {section} is not locked")
        if not self.clear(section):
            return Result.refuse(f"section {section} is occupied: only a clear section can be released")
        if not routes:
            rid = overlaps[0]
            self._release_overlap(rid)
            return Result.accept(f"overlap of {rid} released")
        rs = self.routes[routes[0]]
        if rs.stage is RouteStage.open:
            return Result.refuse(f"signal {rs.route.signal} is open over {section}: close it first (cancel)")
        if self.approach_locked(rs) and not rs.entered:
            delay = self.rules.section_fault_release_s if rs.route.kind == "train" else self.rules.release_s["shunt"]
            rs.stage = RouteStage.time_release
            rs.release_at = self.now + delay
            self.event("route", f"section fault release of {section} with a train approaching: {delay:g} s")
            return Result.accept(f"section {section} ({rs.id}) releases in {delay:g} s unless a train enters")
        self._release_section(rs, rs.sections.index(section))
        self.event("release", f"section {section} released by section fault release")
        if all(rs.released):
            self.finish(rs, all_sections=False)
        return Result.accept(f"section {section} released")

    def reopen(self, signal: str) -> Result:
        """重复开放: reopen a signal closed abnormally, once its conditions are back."""
        rs, why = self._need_route(signal)
        if rs is None:
            return Result.refuse(why)
        if rs.stage is RouteStage.open:
            return Result.refuse(f"signal {signal} is already open")
        if rs.stage is not RouteStage.locked or rs.entered:
            return Result.refuse(f"route {rs.id} is {rs.stage.value}: only a locked route whose signal closed "
                                 "abnormally can be reopened")
        blocker = self.open_blocker(rs)
        if blocker:
            return Result.refuse(f"signal {signal} cannot reopen: {blocker}")
        rs.needs_reopen = False
        self.clear_alarm(f"closed:{signal}")
        self._open(rs)
        return Result.accept(f"signal {signal} reopened")

    # ---- guide ------------------------------------------------------------------------------------------------
    def guide(self, signal: str) -> Result:
        """引导: open HB over a set route without checking its track circuits, or over a guide-locked throat."""
        st = self.station
        if signal not in st.signals:
            return Result.refuse(f"there is no signal '{signal}' at {st.id}")
        sig = st.signals[signal]
        if sig.kind not in (SignalKind.home, SignalKind.route) or "B" not in [lamp.value for lamp in sig.lamps]:
            return Result.refuse(f"signal {signal} has no guide aspect: only home and route signals with a "
                                 "moon-white lamp show HB")
        if not self.board.lamp_ok(signal, "H"):
            return Result.refuse(f"the red lamp of {signal} is dark: the guide aspect needs it lit")
        rs = self.route_of(signal)
        if rs is not None:
            if rs.stage not in (RouteStage.locked, RouteStage.setting) or rs.entered:
                return Result.refuse(f"route {rs.id} is {rs.stage.value}; a guide route needs a locked route "
                                     "whose signal is closed")
            released = [s for i, s in enumerate(rs.sections) if rs.released[i]]
            if released:  # e.g. by section fault release: its turnouts are no longer locked
                return Result.refuse(f"guide refused: section {released[0]} of route {rs.id} has been released; "
                                     "cancel the route and set it again")
            blocker = self.open_blocker(rs, guide=True)
            if blocker.startswith(("turnout", "block", "screen", "line")):
                return Result.refuse(f"guide refused: {blocker}")
            rs.stage = RouteStage.open
            rs.guide = True
            rs.guide_first_clear = self.clear(rs.route.sections[0])
            rs.guide_approach_seen = False
            rs.opened_once = True
            rs.since = self.now
            rs.needs_reopen = False
            self.clear_alarm(f"closed:{signal}")
            self.signals[signal].route = rs.id
            self.out.set_aspect(signal, "HB")
            self.codes_dirty = True
            self.event("signal", f"guide aspect HB on {signal} (route {rs.id})")
            return Result.accept(f"guide aspect HB on {signal}")
        throat = next((name for name, turnouts in self.table.throats.items()
                       if name == signal and all(self._guide_locked(t, name) for t in turnouts)), None)
        if throat is None:
            return Result.refuse(f"no route is set from {signal} and its throat is not under guide total lock: "
                                 f"set the route first, or 'guide-lock {signal}'")
        doors = self.doors_blocker(self.guide_only_doors(signal))
        if doors:  # the way is not known: every platform track the signal leads to must have its doors safe
            return Result.refuse(f"guide refused: {doors}")
        self.guide_only[signal] = self.now
        self.out.set_aspect(signal, "HB")
        self.event("signal", f"guide aspect HB on {signal} under guide total lock")
        return Result.accept(f"guide aspect HB on {signal} (guide total lock)")

    def _guide_locked(self, turnout: str, throat: str) -> bool:
        return any(lk.hold is Hold.guide and lk.holder == throat for lk, _, _ in self.locks.turnout_locks(turnout))

    def guide_lock(self, throat: str, lock: bool) -> Result:
        """引导总锁闭: lock (or unlock) every turnout of a throat."""
        if throat not in self.table.throats:
            names = ", ".join(sorted(self.table.throats))
            return Result.refuse(f"there is no throat '{throat}'; throats are named by their home signal: {names}")
        turnouts = self.table.throats[throat]
        if not lock and throat in self.guide_only:
            return Result.refuse(f"the guide aspect of {throat} is open: cancel it before unlocking the throat")
        for t in turnouts:
            if lock:
                self.locks.lock_turnout(t, Hold.guide, throat)
            else:
                self.locks.unlock_turnout(t, Hold.guide, throat)
        word = "locked" if lock else "unlocked"
        self.event("turnout", f"guide total lock: throat {throat} {word} ({', '.join(turnouts)})")
        return Result.accept(f"throat {throat} {word}: turnouts {', '.join(turnouts)}")

    # ---- turnouts ---------------------------------------------------------------------------------------------
    def _turnout_ids(self, name: str) -> list[str] | None:
        if name in self.station.turnouts:
            return self.pair_members(name)
        if name in self.station.pairs:
            return list(self.station.pairs[name])
        return None

    def throw(self, name: str, position: str) -> Result:
        """单操: individual operation of a turnout (a crossover pair moves together)."""
        ids = self._turnout_ids(name)
        if ids is None:
            return Result.refuse(f"there is no turnout '{name}' at {self.station.id}")
        if position not in ("normal", "reverse"):
            return Result.refuse(f"a turnout goes 'normal' or 'reverse', not '{position}'")
        if all(self.board.indication(t) == position for t in ids):
            return Result.accept(f"turnout {name} is already {position}")
        for t in ids:
            why = self.locks.why_turnout(t)
            if why:
                return Result.refuse(why)
            if not self.clear(self.turnouts[t].section):
                return Result.refuse(f"turnout {t} cannot move: section {self.turnouts[t].section} is occupied")
        self.request_move(ids[0], position)
        self.event("turnout", f"turnout {name} to {position} (individual operation)")
        return Result.accept(f"turnout {name} moving to {position}")

    def single_lock(self, name: str, on: bool) -> Result:
        """单锁 / 单解: the turnout (and its crossover partner) may not be moved."""
        ids = self._turnout_ids(name)
        if ids is None:
            return Result.refuse(f"there is no turnout '{name}' at {self.station.id}")
        for t in ids:
            if on:
                self.locks.lock_turnout(t, Hold.single)
            else:
                self.locks.unlock_turnout(t, Hold.single)
        word = "single-locked (单锁)" if on else "unlocked (单解)"
        self.event("turnout", f"turnout {name} {word}")
        return Result.accept(f"turnout {name} {word}")

    def single_block(self, name: str, on: bool) -> Result:
        """单封 / 解封: no route through the turnout; individual operation stays allowed."""
        ids = self._turnout_ids(name)
        if ids is None:
            return Result.refuse(f"there is no turnout '{name}' at {self.station.id}")
        for t in ids:
            if on:
                self.locks.blocked.add(t)
            else:
                self.locks.blocked.discard(t)
        word = "single-blocked (单封)" if on else "unblocked (解封)"
        self.event("turnout", f"turnout {name} {word}")
        return Result.accept(f"turnout {name} {word}")

    # ---- power-up, line direction ----------------------------------------------------------------------------
    def power_up_release(self) -> Result:
        """上电解锁 (a sealed button): give back the sections locked since the interlocking started; refused while a
        section of the station shows occupied."""
        if not self.power_up_locked:
            return Result.refuse("there is no power-up lock to release: the interlocking is in service")
        occupied = [s for s, sec in self.station.sections.items() if sec.role in INTERLOCKED and not self.clear(s)]
        if occupied:
            return Result.refuse(f"power-up release refused: section {', '.join(occupied[:6])}"
                                 f"{' ...' if len(occupied) > 6 else ''} shows occupied; every section of the station "
                                 "must be clear (confirm on site, then use fault-release after the power-up release)")
        self.locks.release_all(Hold.power_up)
        self.power_up_locked = False
        self.event("power", "power-up release (上电解锁): every section released")
        return Result.accept("power-up release: the station is in service")

    def line_direction(self, link: str, direction: str) -> Result:
        """改方: set an automatic line for departures from this station ('out') or back to its running direction
        ('in'). Only a bidirectional line, clear, with no route into or out of it."""
        lk = next((x for x in self.station.model.links if x.id == link), None)
        if lk is None or lk.kind.value != "automatic":
            names = ", ".join(x.id for x in self.station.model.links if x.kind.value == "automatic") or "none"
            return Result.refuse(f"there is no automatic block line '{link}' (automatic lines: {names})")
        if direction not in ("out", "in"):
            return Result.refuse("line-direction LINE out|in")
        if self.station.link_running(link) != "inbound":
            return Result.refuse(f"line {link} already runs away from this station: its direction needs no change")
        if not lk.bidirectional:
            return Result.refuse(f"line {link} is not bidirectional (双向): its direction cannot be changed")
        want_out = direction == "out"
        if (link in self.line_out) == want_out:
            return Result.accept(f"line {link} is already set {'for departures' if want_out else 'towards us'}")
        occupied = [s for s in lk.sections if not self.clear(s)]
        if occupied:
            return Result.refuse(f"line {link} is not clear ({', '.join(occupied)} occupied): the direction changes "
                                 "only with the whole line clear")
        for rs in self.routes.values():
            r = rs.route
            if r.exit_link == link or set(r.approach) & set(lk.sections):
                return Result.refuse(f"route {r.id} uses line {link}: the direction changes only with no route "
                                     "into or out of it")
        if want_out:
            self.line_out.add(link)
            self.out.line_direction[link] = "outbound"
        else:
            self.line_out.discard(link)
            self.out.line_direction.pop(link, None)
        self.codes_dirty = self.blocks_dirty = True
        word = "set for departures from this station" if want_out else "back to its running direction"
        self.event("block", f"line {link} {word} (改方)")
        return Result.accept(f"line {link} {word}")

    # ---- 64D block and platform doors ------------------------------------------------------------------------
    def block_line(self, link: str, action: str) -> Result:
        bl = self.links.get(link)
        if bl is None:
            names = ", ".join(sorted(self.links)) or "none"
            return Result.refuse(f"there is no 64D block line '{link}' (64D lines: {names})")
        before = bl.state
        why, pulse = bl.operate(action, self.clear(bl.departure_section))
        if why:
            return Result.refuse(why)
        if pulse:
            self.send(link, pulse)
        self.event("block", f"block line {link}: {action}, {before.value} -> {bl.state.value}")
        return Result.accept(f"block line {link}: {bl.state.value}")

    def doors(self, platform: str, action: str) -> Result:
        p = next((p for p in self.station.model.platforms if p.id == platform), None)
        if p is None or not p.screen_doors:
            return Result.refuse(f"there is no platform with screen doors '{platform}'")
        if action not in ("open", "close"):
            return Result.refuse("doors open|close")
        if action == "open" and self.clear(p.section):
            return Result.refuse(f"no train at platform {platform}: section {p.section} is clear")
        for d in p.screen_doors:
            cmd = self.out.doors[f"{p.id}:{d.side.value}"]
            cmd.zckj = not self.clear(p.section)
            cmd.kmj = action == "open"
            cmd.gmj = action == "close"
        self.event("doors", f"platform {platform}: {action} command")
        return Result.accept(f"platform {platform} doors: {action}")

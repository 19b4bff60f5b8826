"""Operator commands of the CBI console (操作表示机). Each returns a :class:`Result`; a refusal says why in a
signaller's terms. Commands act on the current state at once; the routes then progress cycle by cycle."""

from __future__ import annotations

from stations.schema import Button, SignalKind

from .aspects import stop_aspect
from .engine import Engine
from .io import Result
from .state import RouteStage, RouteState
from .table import Kind, Route

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
        why = self.route_blocker(r)
        if why:
            return Result.refuse(why)
        rs = RouteState(r, RouteStage.setting, self.now)
        self.routes[r.id] = rs
        self.by_signal[r.signal] = r.id
        for s in r.sections + tuple(f.section for f in r.fouling):
            self.section_lock[s] = r.id
        for s in r.overlap_sections:
            self.section_lock[s] = f"overlap:{r.id}"
        for t in r.turnouts:
            self.turnouts[t.id].locks.add(r.id)
        for t in r.overlap_turnouts:
            self.turnouts[t.id].locks.add(f"overlap:{r.id}")
        for t in r.all_turnouts:
            if self.board.indication(t.id) != t.position.value:
                self.request_move(t.id, t.position.value)
        self.codes_dirty = True
        self.event("route", f"route {r.id} selected")
        return Result.accept(f"route {r.id} selected")

    def route_blocker(self, r: Route) -> str:
        if r.signal in self.by_signal:
            return f"signal {r.signal} already has route {self.by_signal[r.signal]} set"
        for other, why in r.conflicts.items():
            if other in self.routes and self._still_holds(self.routes[other], r):
                return f"conflicting route {other} is locked ({why})"
        for s in r.all_sections:
            owner = self.section_lock.get(s)
            if owner is not None:
                return f"section {s} is locked in route {owner.removeprefix('overlap:')}"
            if not self.clear(s):
                return f"section {s} is occupied"
        for t in r.all_turnouts:
            ts = self.turnouts[t.id]
            if ts.single_blocked:
                return f"turnout {t.id} is single-blocked (单封)"
            for member in self.pair_members(t.id):
                ms = self.turnouts[member]
                if self.board.indication(member) == t.position.value:
                    continue
                if ms.single_locked:
                    return f"turnout {member} is single-locked (单锁) and not {t.position.value}"
                if ms.guide_locked:
                    return f"turnout {member} is under guide total lock (引导总锁闭)"
                if ms.locks:
                    holder = sorted(ms.locks)[0].removeprefix("overlap:")
                    return f"turnout {member} is locked in route {holder}"
                if not self.clear(ms.section):
                    return f"turnout {member} cannot move: section {ms.section} is occupied"
        return ""

    def _still_holds(self, rs: RouteState, r: Route) -> bool:
        """Does the active route ``rs`` still lock something ``r`` needs? Sections released behind a train are free
        for the next route, as in a real CBI, even while the rest of the train's route is still locked."""
        wanted = set(r.all_sections)
        held = {s for i, s in enumerate(rs.route.sections) if not rs.released[i]}
        held |= {f.section for f in rs.route.fouling} | set(rs.route.overlap_sections)
        if wanted & held:
            return True
        need = {t.id: t.position for t in r.all_turnouts}
        return any(t.id in need and need[t.id] is not t.position and rs.id in self.turnouts[t.id].locks
                   for t in rs.route.all_turnouts)

    def route_of(self, signal: str) -> RouteState | None:
        rid = self.by_signal.get(signal)
        return self.routes.get(rid) if rid else None

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
        owner = self.section_lock.get(section)
        if owner is None:
            return Result.refuse(f"section {section} is not locked")
        if not self.clear(section):
            return Result.refuse(f"section {section} is occupied: only a clear section can be released")
        if owner.startswith("overlap:"):
            rid = owner.removeprefix("overlap:")
            r = self.table.routes[rid]
            self.overlap_pending.pop(rid, None)
            self._release_overlap(rid, r.overlap_sections, tuple(t.id for t in r.overlap_turnouts))
            return Result.accept(f"overlap of {rid} released")
        rs = self.routes[owner]
        if rs.stage is RouteStage.open:
            return Result.refuse(f"signal {rs.route.signal} is open over {section}: close it first (cancel)")
        if self.approach_locked(rs) and not rs.entered:
            delay = self.rules.section_fault_release_s if rs.route.kind == "train" else self.rules.release_s["shunt"]
            rs.stage = RouteStage.time_release
            rs.release_at = self.now + delay
            self.event("route", f"section fault release of {section} with a train approaching: {delay:g} s")
            return Result.accept(f"section {section} ({rs.id}) releases in {delay:g} s unless a train enters")
        if section in rs.route.sections:
            i = rs.route.sections.index(section)
            self._release_section(rs, i)
        else:
            del self.section_lock[section]
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
            released = [s for i, s in enumerate(rs.route.sections) if rs.released[i]]
            if released:  # e.g. by section fault release: its turnouts are no longer locked
                return Result.refuse(f"guide refused: section {released[0]} of route {rs.id} has been released; "
                                     "cancel the route and set it again")
            blocker = self.open_blocker(rs, guide=True)
            if blocker.startswith("turnout") or blocker.startswith("block") or blocker.startswith("screen"):
                return Result.refuse(f"guide refused: {blocker}")
            rs.stage = RouteStage.open
            rs.guide = True
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
                       if name == signal and set(turnouts) <= self.guide_locked), None)
        if throat is None:
            return Result.refuse(f"no route is set from {signal} and its throat is not under guide total lock: "
                                 f"set the route first, or 'guide-lock {signal}'")
        self.guide_only[signal] = self.now
        self.out.set_aspect(signal, "HB")
        self.event("signal", f"guide aspect HB on {signal} under guide total lock")
        return Result.accept(f"guide aspect HB on {signal} (guide total lock)")

    def guide_lock(self, throat: str, lock: bool) -> Result:
        """引导总锁闭: lock (or unlock) every turnout of a throat."""
        if throat not in self.table.throats:
            names = ", ".join(sorted(self.table.throats))
            return Result.refuse(f"there is no throat '{throat}'; throats are named by their home signal: {names}")
        turnouts = self.table.throats[throat]
        if not lock and throat in self.guide_only:
            return Result.refuse(f"the guide aspect of {throat} is open: cancel it before unlocking the throat")
        for t in turnouts:
            self.turnouts[t].guide_locked = lock
            if lock:
                self.guide_locked.add(t)
            else:
                self.guide_locked.discard(t)
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
            ts = self.turnouts[t]
            if ts.single_locked:
                return Result.refuse(f"turnout {t} is single-locked (单锁): unlock it first")
            if ts.locks:
                holder = sorted(ts.locks)[0].removeprefix("overlap:")
                return Result.refuse(f"turnout {t} is locked in route {holder}")
            if ts.guide_locked:
                return Result.refuse(f"turnout {t} is under guide total lock (引导总锁闭)")
            if not self.clear(ts.section):
                return Result.refuse(f"turnout {t} cannot move: section {ts.section} is occupied")
        self.request_move(ids[0], position)
        self.event("turnout", f"turnout {name} to {position} (individual operation)")
        return Result.accept(f"turnout {name} moving to {position}")

    def single_lock(self, name: str, on: bool) -> Result:
        """单锁 / 单解: the turnout (and its crossover partner) may not be moved."""
        return self._turnout_flag(name, "single_locked", on, ("single-locked (单锁)", "unlocked (单解)"))

    def single_block(self, name: str, on: bool) -> Result:
        """单封 / 解封: no route through the turnout; individual operation stays allowed."""
        return self._turnout_flag(name, "single_blocked", on, ("single-blocked (单封)", "unblocked (解封)"))

    def _turnout_flag(self, name: str, flag: str, on: bool, words: tuple[str, str]) -> Result:
        ids = self._turnout_ids(name)
        if ids is None:
            return Result.refuse(f"there is no turnout '{name}' at {self.station.id}")
        for t in ids:
            setattr(self.turnouts[t], flag, on)
        word = words[0] if on else words[1]
        self.event("turnout", f"turnout {name} {word}")
        return Result.accept(f"turnout {name} {word}")

    # ---- 64D block and platform doors ------------------------------------------------------------------------
    def block_line(self, link: str, action: str) -> Result:
        bl = self.links.get(link)
        if bl is None:
            names = ", ".join(sorted(self.links)) or "none"
            return Result.refuse(f"there is no 64D block line '{link}' (64D lines: {names})")
        before = bl.state
        why, pulse = bl.operate(action)
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

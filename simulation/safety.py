"""Safety properties of the interlocking, checked after every cycle of a running simulation.

A :class:`SafetyChecker` attached to a :class:`~simulation.sim.Simulation` watches every cycle (and notes the
operator's ``reopen`` and ``guide`` commands) and records each violation once, with the simulated time, when it
starts:

- ``conflict``: no two routes hold the same section, or the same turnout in opposite positions, at once. What a
  route holds is judged by resources, as the engine's ``_still_holds`` does: its sections not yet released behind a
  train, its fouling sections, its overlap while locked, and the turnouts it still locks; sections released behind
  a train are free for the next route.
- ``open-signal``: an open signal's route is set and open; every route, protection, driven and overlap turnout is in
  position, proven (indication) and locked by it; every route, fouling and overlap section is locked by it and clear
  (a shunting signal stays open until the whole consist is past it: with its approach and first section occupied,
  occupied route sections are the passing consist's); its liaison holds (64D permitted, automatic block ahead
  clear, screen doors closed and locked or bypassed, the red lamp ahead proven). A guide aspect HB needs the
  route's turnouts in position and locked (or the throat under guide total lock) and the red lamp proven. An
  automatic block signal is open only over clear sections.
- ``aspect``: no aspect is more permissive than the rules give for the state the interlocking sees: the aspect
  ahead (this cycle's or the last, as a signal follows the one ahead a cycle later), the clear block sections, the
  flasher's check relay (USU only when it proves), the proven lamps (the downgrade table). So a fault never makes an
  aspect more permissive.
- ``turnout-moved``: a locked turnout (single-locked, under guide total lock, or locked by a route past setting or by
  an overlap) is never driven or moved (a move begun before the lock may finish; a train trailing through a turnout,
  which squeezes it, is the train's doing, not the interlocking's).
- ``reopened``: a signal closed after it was open for a route never opens again for that same route without an
  accepted ``reopen`` or ``guide`` command.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from interlocking.aspects import ORDER, downgrade, is_open, select_aspect
from interlocking.state import RouteStage, RouteState
from stations.schema import SignalKind

if TYPE_CHECKING:
    from interlocking.io import Result
    from interlocking.table import Route

    from .sim import Simulation

_FOLLOW = {"H": "U", "A": "U", "": "U", "HB": "U", "U": "LU", "UU": "U"}  # automatic block: aspect ahead -> at most


@dataclass(frozen=True)
class Violation:
    t: float
    prop: str  # conflict, open-signal, aspect, turnout-moved, reopened
    text: str
    cycle: int  # the interlocking's cycle count
    key: str = ""  # what it is about, e.g. 'open:X' (the same key is the same violation)

    def as_dict(self) -> dict[str, object]:
        return {"t": self.t, "property": self.prop, "text": self.text, "cycle": self.cycle, "key": self.key}


def not_more_permissive(shown: str, allowed: str) -> bool:
    return shown == allowed or ORDER.get(shown, 0) < ORDER.get(allowed, 0) or not is_open(shown)


class SafetyChecker:
    def __init__(self, sim: Simulation, *, attach: bool = True) -> None:
        self.sim = sim
        self.violations: list[Violation] = []
        self.cycles = 0
        self._active: set[str] = set()  # violations going on (recorded once, when they start)
        self._prev: dict[str, str] = dict(sim.interlocking.out.signals)  # aspects at the last check
        self._closed_for: dict[str, RouteState] = {}  # signal -> route it was open for and then closed
        self._lock_at: dict[str, tuple[str | None, str | None]] = {}  # locked turnout -> (rails, target) at lock
        st = sim.station
        self._stop_lamp = {s.id: ("A" if s.kind is SignalKind.shunting else "H") for s in st.model.signals}
        self._lamps = {s.id: {lamp.value for lamp in s.lamps} for s in st.model.signals}
        self._block = {sig: (secs, nxt) for sig, secs, nxt in sim.interlocking.autoblock.signals}
        self._doors = {p.section: [f"{p.id}:{d.side.value}" for d in p.screen_doors]
                       for p in st.model.platforms if p.screen_doors}
        if attach:
            self.attach()

    # ---- wiring into the simulation ------------------------------------------------------------------------------
    def attach(self) -> None:
        """Check after every ``sim.step()`` and note commands run through ``sim.command()``."""
        sim = self.sim
        step, command = sim.step, sim.command

        def checked_step() -> None:
            step()
            self.check()

        def noted_command(line: str) -> Result:
            result = command(line)
            self.note(line, result)
            return result

        sim.step = checked_step  # type: ignore[method-assign]
        sim.command = noted_command  # type: ignore[method-assign]

    def note(self, line: str, result: Result) -> None:
        words = line.split("#", 1)[0].split()
        if result.ok and len(words) >= 2 and words[0] in ("reopen", "guide"):
            self._closed_for.pop(words[1], None)

    # ---- the check ------------------------------------------------------------------------------------------------
    def check(self) -> list[Violation]:
        """Check every property now; returns the violations that started at this check."""
        self.cycles += 1
        found: dict[str, tuple[str, str]] = {}
        self._conflicts(found)
        self._signals(found)
        self._turnouts(found)
        new = [Violation(self.sim.t, prop, text, self.sim.interlocking.cycles, key)
               for key, (prop, text) in found.items() if key not in self._active]
        self._active = set(found)
        self.violations += new
        self._prev = dict(self.sim.interlocking.out.signals)
        return new

    def _holders(self) -> dict[str, tuple[set[str], dict[str, str]]]:
        """Who holds what: route id (or 'overlap:ROUTE') -> (sections, turnout -> position)."""
        il = self.sim.interlocking
        out: dict[str, tuple[set[str], dict[str, str]]] = {}
        for rid, rs in il.routes.items():
            r = rs.route
            secs = {s for i, s in enumerate(r.sections) if not rs.released[i]} | {f.section for f in r.fouling}
            tos = {t.id: t.position.value for t in r.turnouts if rid in il.turnouts[t.id].locks}
            out[rid] = (secs, tos)
        for rid in {*il.routes, *il.overlap_pending}:
            key = f"overlap:{rid}"
            r = il.table.routes[rid]
            secs = {s for s in r.overlap_sections if il.section_lock.get(s) == key}
            tos = {t.id: t.position.value for t in r.overlap_turnouts if key in il.turnouts[t.id].locks}
            if secs or tos:
                out[key] = (secs, tos)
        return out

    def _conflicts(self, found: dict[str, tuple[str, str]]) -> None:
        by_section: dict[str, str] = {}
        by_turnout: dict[str, tuple[str, str]] = {}
        for holder, (secs, tos) in self._holders().items():
            for s in secs:
                other = by_section.setdefault(s, holder)
                if other != holder and other.removeprefix("overlap:") != holder.removeprefix("overlap:"):
                    found[f"conflict:{s}"] = ("conflict", f"section {s} is held by both {other} and {holder}")
            for t, pos in tos.items():
                o_holder, o_pos = by_turnout.setdefault(t, (holder, pos))
                if o_pos != pos:
                    found[f"conflict:{t}"] = ("conflict", f"turnout {t} is held {o_pos} by {o_holder} and {pos} by "
                                                          f"{holder}")

    # ---- signals ----------------------------------------------------------------------------------------------------
    def _signals(self, found: dict[str, tuple[str, str]]) -> None:
        il = self.sim.interlocking
        for sig, aspect in il.out.signals.items():
            was = self._prev.get(sig, "")
            if sig in self._block:
                if is_open(aspect):
                    self._block_signal(sig, aspect, found)
                continue
            rs = il.route_of(sig)
            if is_open(was) and not is_open(aspect) and rs is not None:
                self._closed_for[sig] = rs
            if not is_open(aspect):
                continue
            if not is_open(was) and rs is not None and self._closed_for.get(sig) is rs:
                found[f"reopened:{sig}"] = ("reopened", f"signal {sig} reopened ({aspect}) for route {rs.id} "
                                                        "without a reopen command")
            if self._closed_for.get(sig) is not rs:
                self._closed_for.pop(sig, None)
            problem = self._open_problem(sig, aspect, rs)
            if problem:
                found[f"open:{sig}"] = ("open-signal", f"signal {sig} shows {aspect} but {problem}")
            elif aspect != "HB" and rs is not None:
                allowed = self._allowed(rs.route)
                if not any(not_more_permissive(aspect, a) for a in allowed):
                    found[f"aspect:{sig}"] = ("aspect", f"signal {sig} shows {aspect}; for route {rs.id} the rules "
                                                        f"give at most {' or '.join(sorted(set(allowed)))}")

    def _open_problem(self, sig: str, aspect: str, rs: RouteState | None) -> str:
        il = self.sim.interlocking
        board = il.board
        if aspect == "HB" and rs is None:
            throat = il.table.throats.get(sig, ())
            if sig not in il.guide_only or not all(il.turnouts[t].guide_locked for t in throat):
                return "no route is set and its throat is not under guide total lock"
            return "" if board.lamp_ok(sig, "H") else "its red lamp is not proven (the guide aspect needs it lit)"
        if rs is None:
            return "no route is set from it"
        r = rs.route
        if rs.stage is not RouteStage.open:
            return f"route {r.id} is {rs.stage.value}"
        why = self._turnouts_of(rs)
        if why:
            return why
        if aspect == "HB":
            if not rs.guide:
                return f"route {r.id} was not opened as a guide route"
            return "" if board.lamp_ok(sig, "H") else "its red lamp is not proven (the guide aspect needs it lit)"
        return self._sections_of(rs) or self._liaison_of(r)

    def _turnouts_of(self, rs: RouteState) -> str:
        il, fld = self.sim.interlocking, self.sim.field
        for t in rs.route.all_turnouts:
            want = t.position.value
            m = fld.machines[t.id]
            if il.board.indication(t.id) != want or m.rails != want or m.running:
                return f"turnout {t.id} is not proven {want} (indication {il.board.indication(t.id)}, rails {m.rails})"
            locks = il.turnouts[t.id].locks
            if rs.id not in locks and f"overlap:{rs.id}" not in locks:
                return f"turnout {t.id} is not locked by route {rs.id}"
        return ""

    def _sections_of(self, rs: RouteState) -> str:
        il = self.sim.interlocking
        r = rs.route
        for s in r.all_sections:
            if il.section_lock.get(s) not in (rs.id, f"overlap:{rs.id}"):
                return f"section {s} is not locked by route {r.id}"
        occupied = [s for s in r.all_sections if not self.sim.field.track_up(s)]
        if not occupied:
            return ""
        # a shunting signal stays open until the whole consist is past it: with the approach and the first section
        # occupied the consist is passing, and the route's own sections it occupies are excused (the interlocking
        # cannot tell one consist from two); fouling and overlap sections never are
        passing = (r.kind == "shunt" and r.sections[0] in occupied and set(occupied) <= set(r.sections)
                   and any(not self.sim.field.track_up(a) for a in r.approach))
        return "" if passing else f"section {occupied[0]} of route {r.id} is occupied"

    def _liaison_of(self, r: Route) -> str:
        il, fld = self.sim.interlocking, self.sim.field
        link = il.links.get(r.exit_link or "")
        if link is not None and link.state.value != "permitted":
            return f"64D line {link.id} is {link.state.value}, not permitted"
        auto = il.auto_links.get(r.exit_link or "")
        if auto and not fld.track_up(auto[0]):
            return f"the first block section {auto[0]} is occupied"
        rear = self.sim.station.signal_rear_track(r.signal)
        door_sections = {*r.sections, self.sim.station.tracks[rear].section if rear else ""}
        for sec in door_sections & set(self._doors):
            for key in self._doors[sec]:
                pdkj, pdqcj = fld.doors_relays(key)
                if not (pdkj or pdqcj):
                    return f"screen doors {key} are neither closed and locked nor bypassed"
        end = r.end_signal
        if end and self._stop_lamp[end] in self._lamps[end] and not il.board.lamp_ok(end, self._stop_lamp[end]):
            return f"the {self._stop_lamp[end]} lamp of {end} ahead is not proven"
        return ""

    def _allowed(self, r: Route) -> list[str]:
        """The most permissive aspect the rules give for ``r`` now, for this cycle's and last cycle's aspect ahead."""
        il = self.sim.interlocking
        sim = self.sim
        out = []
        nexts = {sim.aspect(r.end_signal), self._prev.get(r.end_signal, "")} if r.end_signal else {""}
        auto = il.auto_links.get(r.exit_link or "")
        blocks = None
        if auto:
            blocks = 0
            for s in auto[:3]:
                if not sim.field.track_up(s):
                    break
                blocks += 1
        for nxt in nexts:
            usu_ready = bool(r.end_signal) and is_open(nxt) and sim.field.flasher_ok(r.signal)
            aspect = select_aspect(sim.station, r, nxt, blocks, usu_ready, sim.rules)
            dark = {lamp for lamp in sim.rules.lamps.get(aspect, []) if not il.board.lamp_ok(r.signal, lamp)}
            if aspect == "USU" and not sim.field.flasher_ok(r.signal):
                dark.add("flasher")
            out.append(downgrade(aspect, dark, sim.rules) if dark else aspect)
        return out

    def _block_signal(self, sig: str, aspect: str, found: dict[str, tuple[str, str]]) -> None:
        sections, nxt = self._block[sig]
        occupied = [s for s in sections if not self.sim.field.track_up(s)]
        if occupied:
            found[f"open:{sig}"] = ("open-signal", f"block signal {sig} shows {aspect} over occupied {occupied[0]}")
            return
        aheads = {self.sim.aspect(nxt), self._prev.get(nxt, "")} if nxt else {"L"}
        allowed = [_FOLLOW.get(a, "L") for a in aheads]
        if not any(not_more_permissive(aspect, a) for a in allowed):
            found[f"aspect:{sig}"] = ("aspect", f"block signal {sig} shows {aspect} with {nxt} ahead showing "
                                                f"{self.sim.aspect(nxt or '')}")

    # ---- turnouts ---------------------------------------------------------------------------------------------------
    def _locked(self, t: str) -> bool:
        il = self.sim.interlocking
        ts = il.turnouts[t]
        if ts.single_locked or ts.guide_locked:
            return True
        for holder in ts.locks:
            rid = holder.removeprefix("overlap:")
            rs = il.routes.get(rid)
            if rs is None or rs.stage is not RouteStage.setting:
                return True
        return False

    def _turnouts(self, found: dict[str, tuple[str, str]]) -> None:
        il, fld = self.sim.interlocking, self.sim.field
        for t in il.turnouts:
            if not self._locked(t):
                self._lock_at.pop(t, None)
                continue
            m = fld.machines[t]
            if t not in self._lock_at:
                self._lock_at[t] = (m.rails, m.target if m.running else None)
                continue
            rails, target = self._lock_at[t]
            if target is not None and m.rails == target and not m.running:
                self._lock_at[t] = (target, None)  # the move begun before the lock has finished
                continue
            if m.faults.squeezed:
                self._lock_at[t] = (m.rails, None)  # trailed through (挤岔): the train's doing, not a command
                continue
            # where it lies or was going when locked; a machine retrying that same position (an obstruction keeps
            # the lock from engaging) moves nothing
            allowed = {p for p in (rails, target) if p is not None}
            driven = il.out.turnouts.get(t)
            moving = m.running and m.target not in allowed
            moved = (m.rails is not None and m.rails not in allowed) or (m.rails is None and rails is not None
                                                                         and m.target not in allowed)
            if moving or moved or (driven is not None and driven not in allowed):
                found[f"moved:{t}"] = ("turnout-moved", f"locked turnout {t} moved: rails {rails} -> {m.rails}, "
                                                        f"driven to {driven}")

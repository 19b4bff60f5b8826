"""Whether a route may be selected now: the conditions a CBI checks before it locks a route (进路选排的联锁条件), in
a signaller's words when one fails. They read the interlocking's core only; the operator's commands
(:mod:`.operations`) ask them before a route, a guide route or a through movement is set."""

from __future__ import annotations

from liansuo.interlocking.core import Core
from liansuo.interlocking.locks import Hold
from liansuo.interlocking.state import RouteState
from liansuo.interlocking.table.route import Condition, Kind, Route, RunOn

KIND_WORD = {"train": "train", "shunt": "shunting"}


class Selection:
    """The conditions of route selection on one interlocking ``core``."""

    def __init__(self, core: Core) -> None:
        self.core = core

    def find(self, kind: Kind, start: str, end: str, via: tuple[str, ...]) -> tuple[Route | None, str]:
        """The route the buttons select, or why there is none."""
        r = self.core.table.by_buttons(kind, start, end, via)
        if r is None and via:  # the last button may be an overlap's end button
            r = self.core.table.by_buttons(kind, start, via[-1], via[:-1], overlap=end)
        if r is not None:
            return r, ""
        options = sorted(x.id for x in self.core.table.routes.values() if x.kind == kind and x.start == start)
        return None, (f"no {KIND_WORD[kind]} route from {start} to {end}" + (" via " + ",".join(via) if via else "")
                      + (f"; routes from {start}: {', '.join(options)}" if options else ""))

    def choose_run_on(self, r: Route) -> tuple[RunOn | None, str]:
        """The way a shunting movement runs on past the end of ``r``, as the turnouts beyond lie; or why it cannot
        be told (a turnout beyond without indication)."""
        if not r.run_on:
            return None, ""
        lies = {t: self.core.board.indication(t) for ro in r.run_on for t, _ in ro.when}
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
        if self.core.power_up_locked:
            return "the station is locked since the interlocking started (上电锁闭): give the power-up release first"
        if r.signal in self.core.by_signal:
            return f"signal {r.signal} already has route {self.core.by_signal[r.signal]} set"
        why = self.core.line_against(r.signal)
        if why:
            return why
        leads_into = run_on.leads_into if run_on else r.leads_into
        for sig in self.core.guide_only:
            if self.core.guide_only_meets(sig, [*r.sections, *(run_on.sections if run_on else ())], leads_into):
                return (f"the guide aspect of {sig} is lit under guide total lock (引导总锁闭): no route into its "
                        "throat or onto a track it leads to until it closes")
        if r.exit_link in self.core.auto_links:
            why = self.core.against_running(r.exit_link)
            if why:
                return why
        for other, rs in self.core.routes.items():
            why = r.conflicts.get(other) or self._conditional(r, rs)
            held = self._still_conflicts(rs, r, run_on) if why else ""
            if held:
                return f"conflicting route {other} is locked ({held})"
        sections = list(r.sections) + (list(run_on.sections) if run_on else []) + list(r.overlap_sections)
        for s in [*sections, *(f.section for f in r.fouling)]:
            for lk in self.core.locks.section_locks(s):
                if lk.hold is Hold.fouling and s not in sections:
                    continue  # several routes may check the same fouling section
                if lk.hold is Hold.overlap and self.continues(lk.holder, r, s):
                    continue  # the onward route of a through movement runs over the overlap (held or timing)
                if lk.hold is Hold.route and self.continues(r.id, self.core.table.routes.get(lk.holder), s):
                    continue  # the departure of a through movement is set first: its route covers our overlap
                if lk.hold is Hold.power_up:
                    return self.route_blocker_power_up(s)
                return f"section {s} is locked {lk.words()}"
            if not guide and not self.core.clear(s):
                return f"section {s} is occupied"
        turnouts = r.all_turnouts + (run_on.turnouts if run_on else ())
        for t in turnouts:
            if t.id in self.core.locks.blocked:
                return f"turnout {t.id} is single-blocked (单封)"
            for member in self.core.pair_members(t.id):
                if self.core.board.indication(member) == t.position.value:
                    continue
                why = self.core.locks.why_turnout(member)
                if why and not self._driven_there(member, t.position.value) and not self._beside_overlap(member, r):
                    return f"{why}; the route needs it {t.position.value}"
                if not self.core.clear(self.core.turnouts[member].section):
                    return f"turnout {member} cannot move: section {self.core.turnouts[member].section} is occupied"
        return ""

    def _driven_there(self, turnout: str, position: str) -> bool:
        """Every lock on ``turnout`` is held by a route (or its overlap) that is driving it to ``position`` itself: a
        compatible route (a through movement over an overlap, say) may then wait for it there."""
        locks = self.core.locks.turnout_locks(turnout)
        for lk, _, partner in locks:
            rs = self.core.routes.get(lk.holder)
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
        locks = self.core.locks.turnout_locks(turnout)
        for lk, via, partner in locks:
            first = self.core.table.routes.get(lk.holder)
            if lk.hold is not Hold.overlap or not via or first is None or not self.continues(first.id, r, via):
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
        return all(self.core.board.indication(t) in (p.value, None) for t, p in cond)

    def continues(self, rid: str, r: Route | None, section: str) -> bool:
        """``r`` continues route ``rid`` (set, or its overlap still timing) from its end signal in the same direction,
        and ``section`` is in ``rid``'s overlap: a through movement, which is no enemy in either order of setting."""
        first = self.core.table.routes.get(rid)
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
            if t.id in need and need[t.id] is not t.position and rs.id in self.core.locks.holders(t.id):
                return f"turnout {t.id} {t.position.value}/{need[t.id].value}"
        crossings = self.core.station.crossings
        for track_id in rs.route.path.tracks:
            diamonds = [d for d, _ in crossings.get(track_id, ()) if d in r.diamonds]
            if diamonds and self.core.station.tracks[track_id].section in held:
                return f"diamond {diamonds[0]}"
        return ""

"""The life of a route (进路), as one state machine.

Every route in progress is in one :class:`~.state.RouteStage`; each cycle :meth:`RouteLifecycle.advance` calls the
handler of its stage, and every change of stage, whether the cycle makes it or an operator's command does, goes
through :meth:`RouteLifecycle.to`, which allows only the moves of the table :data:`STAGES`::

    setting ──turnouts in position──> locked ──conditions hold──> open ──train enters──> in_use ──> (released)
                                        │  ^                       │                       ^
                      guide command ────┼──┼──> guide ─────────────┼──guided train enters──┘
                                        │  │      │                │
                                        │  └──────┴──> closed <────┘ a condition lost (alarm); 'reopen' -> open
                                        └── release (approach locked) ──> time_release ──delay over──> (released)

Cancel and release without a train approaching release the route at once (:meth:`finish`). A section fault release
(区故解) releases one section (:meth:`release_section`). The locks a route holds are the ledger's (:mod:`.locks`);
what a signal needs to open is the core's (:meth:`~.core.Core.open_blocker`).
"""

from __future__ import annotations

from liansuo.interlocking.aspects import is_open, stop_aspect
from liansuo.interlocking.core import Core
from liansuo.interlocking.locks import Hold
from liansuo.interlocking.memos import Memos
from liansuo.interlocking.state import RouteStage, RouteState
from liansuo.interlocking.table.route import Route, RunOn
from liansuo.interlocking.throatguide import ThroatGuide

_S = RouteStage
# The route state machine as one table: for each stage, the handler that runs a route in it each cycle (routes in
# order of selection; what a handler looks at first wins, as its docstring says) and the stages it may move to,
# whether the cycle moves it or an operator's command does. Release (finish) ends a route in any stage. A move the
# table does not list is a defect of the interlocking, refused loudly (RouteLifecycle.to).
STAGES: dict[RouteStage, tuple[str, frozenset[RouteStage]]] = {
    _S.setting: ("_setting", frozenset({_S.locked, _S.guide})),  # turnouts in position; the guide command
    _S.locked: ("_locked", frozenset({_S.open, _S.guide, _S.in_use})),  # conditions hold; guide; entered at danger
    _S.open: ("_keep_open", frozenset({_S.in_use, _S.closed, _S.time_release})),  # entered; lost; release (总人解)
    _S.guide: ("_keep_guide", frozenset({_S.in_use, _S.closed, _S.time_release})),  # entered; lost or unused; release
    _S.closed: ("_closed", frozenset({_S.open, _S.guide, _S.in_use, _S.time_release})),  # reopen; guide; in; release
    _S.in_use: ("_sequential_release", frozenset()),  # releases section by section, then finish
    _S.time_release: ("_time_release", frozenset({_S.in_use})),  # a movement entered; else finish after the delay
}
# stages in which the signal has been opened: a train approaching makes the route approach-locked (接近锁闭)
SIGNAL_GIVEN = frozenset({RouteStage.open, RouteStage.guide, RouteStage.closed, RouteStage.time_release})


class RouteLifecycle:
    """The stage handlers and transitions of every route of one interlocking ``core``."""

    def __init__(self, core: Core) -> None:
        self.core = core
        self.skip_unchanged = True  # skip a route's cycle when nothing it reads changed (advance_all)
        self.memos = Memos(core)
        self.throat_guide = ThroatGuide(core)

    # ---- the cycle ----------------------------------------------------------------------------------------------
    def advance_all(self) -> bool:
        """Every route in progress, in order of selection; with ``skip_unchanged``, not those :meth:`unchanged`.
        True when no route changed: each was skipped, or its handler left it as it was and reads no clock (a guide
        aspect closes by itself after a time: :mod:`.quiet` counts only the timers it knows)."""
        skip = self.skip_unchanged
        settled = True
        routes = self.core.routes
        for rs in list(routes.values()):
            if skip and self.unchanged(rs):
                continue
            if not settled or rs.stage is RouteStage.guide:
                self.advance(rs)
                settled = False
                continue
            before = _look(rs)
            self.advance(rs)
            settled = routes.get(rs.id) is rs and _look(rs) == before
        self.throat_guide.cycle()
        self._overlaps()
        return settled

    def unchanged(self, rs: RouteState) -> bool:
        """The handler of ``rs``'s stage would change nothing this cycle (:meth:`.memos.Memos.unchanged`)."""
        return self.memos.unchanged(rs)

    def advance(self, rs: RouteState) -> None:
        """One cycle of one route: the handler of its stage."""
        getattr(self, STAGES[rs.stage][0])(rs)

    def to(self, rs: RouteState, stage: RouteStage) -> None:
        """Move ``rs`` to ``stage``, a move :data:`STAGES` lists (the core hears that the routes changed)."""
        if stage not in STAGES[rs.stage][1]:
            raise RuntimeError(f"route {rs.id}: no move from {rs.stage.value} to {stage.value} in the route state "
                               "machine (lifecycle.STAGES)")
        rs.stage = stage
        self.core.routes_changed()

    # ---- selection ----------------------------------------------------------------------------------------------
    def select(self, rs: RouteState) -> None:
        """A route accepted by the operator: it takes its locks and its turnouts start moving (setting)."""
        core, r = self.core, rs.route
        core.routes[r.id] = rs
        core.by_signal[r.signal] = r.id
        for s in rs.sections:
            core.locks.lock_section(s, Hold.route, r.id)
        for f in r.fouling:
            core.locks.lock_section(f.section, Hold.fouling, r.id)
        for s in r.overlap_sections:
            core.locks.lock_section(s, Hold.overlap, r.id)
        for t in rs.turnouts:
            core.locks.lock_turnout(t.id, Hold.route, r.id)
        for t in r.overlap_turnouts:
            core.locks.lock_turnout(t.id, Hold.overlap, r.id)
        for t in rs.all_turnouts:
            if core.board.indication(t.id) != t.position.value:
                core.request_move(t.id, t.position.value)
        core.routes_changed()
        core.event("route", f"route {r.id} selected")

    # ---- stage handlers -----------------------------------------------------------------------------------------
    def _setting(self, rs: RouteState) -> None:
        core = self.core
        if all(core.board.indication(t.id) == t.position.value for t in rs.all_turnouts):
            self.to(rs, RouteStage.locked)
            rs.memo = None
            rs.since = core.now
            core.event("route", f"route {rs.id} locked")
            self._locked(rs)
        else:
            rs.memo = self.memos.setting(rs)

    def _locked(self, rs: RouteState) -> None:
        """Locked, the signal not yet given: it opens as soon as every condition holds; a guide route gives the
        guide aspect once what it checks holds (not its track circuits)."""
        if rs.guide_route:
            if not self.core.open_blocker(rs, guide=True):
                self.open_guide(rs)
            return
        if not self._entered_closed(rs) and not self.core.open_blocker(rs):
            self.open(rs)

    def _closed(self, rs: RouteState) -> None:
        """The signal was given and closed again: only the operator opens it again ('reopen', 'guide')."""
        self._entered_closed(rs)

    def _entered_closed(self, rs: RouteState) -> bool:
        """A movement entered under the closed signal (detected as SPAD): the route releases behind it."""
        if rs.entered or self._first_occupied(rs):
            rs.entered = True
            self.to(rs, RouteStage.in_use)
            return True
        return False

    def _first_occupied(self, rs: RouteState) -> bool:
        """A movement is in the first section. With the approach clear an occupied first section is a track-circuit
        fault (red band), as ``_keep_open`` judges it, not a movement entering: the route stays locked. Where the
        signal was last given as a guide aspect over the first section showing occupied (the red band the guide is
        for), that section says nothing, also once the aspect has closed: the movement has entered once it has
        passed the signal, its approach clear again after a train was seen in it (noted here, as under the guide
        aspect)."""
        r, core = rs.route, self.core
        if core.clear(r.sections[0]):
            return False
        approach = any(not core.clear(s) for s in r.approach)
        if not rs.guide_first_clear:
            rs.guide_approach_seen = rs.guide_approach_seen or approach
            return rs.guide_approach_seen and not approach
        return not (r.approach and not approach)

    def _keep_open(self, rs: RouteState) -> None:
        core, r = self.core, rs.route
        if (not rs.entered and not core.clear(r.sections[0]) and r.approach
                and all(core.clear(s) for s in r.approach)):
            # occupied with nobody approaching: a track-circuit fault (red band), not a train entering
            self.close_signal(rs, f"section {r.sections[0]} is occupied", abnormal=True)
            return
        if not core.clear(r.sections[0]):
            rs.entered = True
            if r.kind == "shunt" and any(not core.clear(s) for s in r.approach):
                # a shunting signal stays open until the whole consist is past it; everything else is still checked
                blocker = core.open_blocker(rs, sections=False)
                if blocker:
                    self.close_signal(rs, blocker, abnormal=True)
                return
            self.close_signal(rs, f"train entered {r.sections[0]}", abnormal=False)
            self.to(rs, RouteStage.in_use)
            self._sequential_release(rs)
            return
        blocker = core.open_blocker(rs)
        if blocker:
            self.close_signal(rs, blocker, abnormal=True)
            return
        wanted = core.wanted_aspect(rs)
        aspect = core.proven(r.signal, wanted)
        before = core.out.signals.get(r.signal)
        if aspect != before:
            core.out.set_aspect(r.signal, aspect)
            core.event("signal", f"signal {r.signal}: {before} -> {aspect}")
        if aspect == wanted:  # every lamp proven, no alarm raised: looking again on the same finds the same
            rs.memo = self.memos.open_memo(rs, aspect)

    def _keep_guide(self, rs: RouteState) -> None:
        """The guide aspect closes when the guided train enters the first section inside the signal; when that
        section is the faulty one (already showing occupied), once the train has passed the signal (its approach
        clear again); unused, after the rule set's time."""
        core, r = self.core, rs.route
        for t in rs.all_turnouts:
            if core.board.indication(t.id) != t.position.value:
                self.close_signal(rs, f"turnout {t.id} lost its indication", abnormal=True)
                return
        if not core.board.lamp_ok(r.signal, stop_aspect(core.station, r.signal)):
            self.close_signal(rs, "red lamp dark: the guide aspect needs the red lamp lit", abnormal=True)
            return
        guide = core.rules.aspects.guide
        if core.proven(r.signal, guide) != guide:
            self.close_signal(rs, f"a lamp of the guide aspect {guide} is dark", abnormal=True)
            return
        doors = core.doors_blocker(core.door_sections(r))
        if doors:
            self.close_signal(rs, doors, abnormal=True)
            return
        approach_occupied = any(not core.clear(s) for s in r.approach)
        if approach_occupied:
            rs.guide_approach_seen = True
        entered = (rs.guide_first_clear and not core.clear(r.sections[0])) or (
            not rs.guide_first_clear and rs.guide_approach_seen and not approach_occupied)
        if entered:
            self.close_signal(rs, f"guided train entered {r.sections[0]}", abnormal=False)
            self.to(rs, RouteStage.in_use)
            rs.entered = True
        elif not rs.guide_approach_seen and core.now - rs.since > core.rules.guide_close_s:
            self.close_signal(rs, "guide aspect not used", abnormal=False)
            self.to(rs, RouteStage.closed)

    def _time_release(self, rs: RouteState) -> None:
        """The route releases after the delay unless the movement enters it (passes the signal into the first
        section). A section occupied further in (a red band, a vehicle come another way) neither ends the delay nor
        is released under it: once the delay is over the route waits for its sections to show clear."""
        core = self.core
        if self._first_occupied(rs):
            self.to(rs, RouteStage.in_use)
            rs.entered = True
            rs.release_at = None
            core.event("route", f"time release of {rs.id} abandoned: a movement entered {rs.route.sections[0]}")
        elif rs.release_at is not None and core.now >= rs.release_at and self._all_clear(rs):
            core.event("route", f"route {rs.id} released by manual time release")
            self.finish(rs, all_sections=True)

    def _all_clear(self, rs: RouteState) -> bool:
        return all(self.core.clear(s) for s in rs.sections)

    def _sequential_release(self, rs: RouteState) -> None:
        """Normal release with the three-point check: a section releases when the one in rear has released, this
        one was occupied and is clear again, and the next one is occupied."""
        core, r = self.core, rs.route
        secs = rs.sections
        n = len(secs)
        any_occupied = False
        for i, s in enumerate(secs):
            if not rs.released[i] and not core.clear(s):
                rs.was_occupied[i] = True
                any_occupied = True
        for i, due in list(rs.fault_release_at.items()):  # section fault releases given ahead of the movement
            if rs.released[i] or rs.was_occupied[i]:
                del rs.fault_release_at[i]  # released, or the movement reached it: it releases behind it
            elif core.now >= due:
                del rs.fault_release_at[i]
                core.event("release", f"section {secs[i]} released by section fault release ({rs.id})")
                if self.release_by_fault(rs, i):
                    return
        last = n - 1
        # a shunting movement that drew back out of its route (中途返回): nothing in the route occupied, the section
        # in rear of the signal occupied again; the sections it passed release without the next one occupied
        drew_back = r.kind == "shunt" and not any_occupied and any(not core.clear(a) for a in r.approach)
        if (r.overlap_sections and not rs.released[last] and rs.was_occupied[last]
                and rs.overlap_release_at is None):
            rs.overlap_release_at = core.now + r.overlap_release_s
        for i in range(n):
            if rs.released[i]:
                continue
            if i > 0 and not rs.released[i - 1]:
                break
            s = secs[i]
            if (i == last and r.category == "receiving" and core.station.is_station_track(s)
                    and rs.was_occupied[i]):
                self.release_section(rs, i)  # the train stands on the receiving track
                continue
            if not rs.was_occupied[i] or not core.clear(s):
                break
            nxt = secs[i + 1] if i < last else self.beyond(rs)
            if nxt is not None and core.clear(nxt) and not drew_back:
                break  # the movement has not reached the next section
            self.release_section(rs, i)
        if drew_back and any(rs.released) and not all(rs.released):
            # partial release: the shunting movement drew back out of the route
            for i in range(n):
                if not rs.released[i]:
                    self.release_section(rs, i)
        if all(rs.released):
            self.finish(rs, all_sections=False)
        else:  # what it read, to skip it while none of that changes
            beyond = self.beyond(rs)
            watched = frozenset((*secs, *r.approach, beyond) if beyond is not None else (*secs, *r.approach))
            rs.memo = self.memos.release(rs, watched)

    def release_by_fault(self, rs: RouteState, i: int) -> bool:
        """Section ``i`` released by section fault release (区故解); True when that released the whole route. Where
        only the receiving track is left after a movement entered and left the route (a flickering relay, a train
        that backed out), and it shows clear, it goes with the route: it would never release behind a train, and a
        station track takes no section fault release of its own."""
        self.release_section(rs, i)
        left = [k for k, done in enumerate(rs.released) if not done]
        last = len(rs.sections) - 1
        if left == [last] and rs.entered and self.core.station.is_station_track(rs.sections[last]) \
                and self.core.clear(rs.sections[last]):
            self.release_section(rs, last)
        if all(rs.released):
            self.finish(rs, all_sections=False)
            return True
        return False

    def beyond(self, rs: RouteState) -> str | None:
        """The section just past the route (past its run-on, where it has one)."""
        ro: RunOn | None = rs.run_on
        st = self.core.station
        if ro is None:
            return rs.route.beyond
        if ro.leads_into is not None:
            return ro.leads_into
        if ro.end_node in st.joints:
            return st.tracks[st.entry_track(ro.end_node, rs.route.direction)].section
        return None

    # ---- transitions ----------------------------------------------------------------------------------------
    def open(self, rs: RouteState) -> None:
        """locked or closed -> open: the signal shows the aspect the route and the signal ahead call for."""
        core, r = self.core, rs.route
        self.to(rs, RouteStage.open)
        rs.memo = None
        rs.since = core.now
        rs.guide_first_clear = True  # a main aspect is given only over a clear first section
        aspect = core.proven(r.signal, core.wanted_aspect(rs))
        core.out.set_aspect(r.signal, aspect)
        core.event("signal", f"signal {r.signal} opened: {aspect} (route {r.id})")

    def reopen(self, rs: RouteState) -> None:
        """closed -> open (重复开放), the operator having seen the conditions are back."""
        self.core.clear_alarm("closed", rs.route.signal)
        self.open(rs)

    def open_guide(self, rs: RouteState) -> None:
        """setting, locked or closed -> guide: the guide aspect over the route, its track circuits not checked."""
        core, signal = self.core, rs.route.signal
        self.to(rs, RouteStage.guide)
        rs.guide_first_clear = core.clear(rs.route.sections[0])
        rs.guide_approach_seen = False
        rs.since = core.now
        core.clear_alarm("closed", signal)
        guide = core.rules.aspects.guide
        core.out.set_aspect(signal, guide)
        core.event("signal", f"guide aspect {guide} on {signal} (route {rs.id})")

    def close_signal(self, rs: RouteState, reason: str, *, abnormal: bool) -> None:
        """Show the stop aspect. ``abnormal``: a condition was lost (-> closed, with an alarm); otherwise the caller
        moves the route on (a train entered, the route is being released)."""
        core, r = self.core, rs.route
        core.out.set_aspect(r.signal, stop_aspect(core.station, r.signal))
        core.routes_changed()
        if abnormal:
            self.to(rs, RouteStage.closed)
            core.alarm("closed", r.signal, f"signal {r.signal} closed: {reason}")
        else:
            core.event("signal", f"signal {r.signal} closed: {reason}")

    def close_if_open(self, rs: RouteState, reason: str) -> None:
        if self.core.out.signals.get(rs.route.signal) != stop_aspect(self.core.station, rs.route.signal):
            self.close_signal(rs, reason, abnormal=False)

    def start_time_release(self, rs: RouteState, delay: float, reason: str) -> None:
        """-> time_release: the route releases after ``delay`` unless a train enters it (总人解, 区故解 delay)."""
        self.close_if_open(rs, reason)
        self.to(rs, RouteStage.time_release)
        rs.release_at = self.core.now + delay

    def enter_at_danger(self, rs: RouteState) -> None:
        """A movement passed the route's closed signal: the route is in use and releases behind it."""
        rs.entered = True
        if rs.stage in (RouteStage.time_release, RouteStage.locked, RouteStage.closed):
            self.to(rs, RouteStage.in_use)
            rs.release_at = None

    def release_section(self, rs: RouteState, i: int) -> None:
        core, s = self.core, rs.sections[i]
        rs.released[i] = True
        core.routes_changed()
        core.locks.unlock_section(s, Hold.route, rs.id)
        for t in rs.turnouts:
            if core.station.turnout_section[t.id] == s:
                core.locks.unlock_turnout(t.id, Hold.route, rs.id)
        core.event("release", f"section {s} released ({rs.id})")

    def finish(self, rs: RouteState, *, all_sections: bool) -> None:
        """Release the whole route (what is still locked), keeping a running overlap timer."""
        core, r = self.core, rs.route
        rs.released = [True] * len(rs.released)
        core.locks.release(Hold.route, rs.id)
        core.locks.release(Hold.fouling, rs.id)
        if r.overlap_sections and not rs.overlap_released:
            # the overlap is held on for its time after the train reached the receiving track, or for a section
            # fault release given while the train ran in (whichever is later)
            due = [at for at in (rs.overlap_release_at, core.overlap_pending.get(rs.id)) if at is not None]
            if due and not all_sections:
                core.overlap_pending[rs.id] = max(due)
            else:
                self.release_overlap(rs.id)
        if core.out.signals.get(r.signal) != stop_aspect(core.station, r.signal):
            core.out.set_aspect(r.signal, stop_aspect(core.station, r.signal))
        core.usu_failed.discard(r.signal)
        core.routes.pop(rs.id, None)
        if core.by_signal.get(r.signal) == rs.id:
            del core.by_signal[r.signal]
        core.clear_alarm("closed", r.signal)
        core.routes_changed()
        core.event("route", f"route {r.id} released")

    def release_overlap(self, rid: str) -> None:
        self.core.overlap_pending.pop(rid, None)
        self.core.locks.release(Hold.overlap, rid)
        self.core.event("release", f"overlap of {rid} released")

    def _overlaps(self) -> None:
        """Overlaps held on after their route released, until their time. A section fault release of the overlap
        given while the train ran in waits here too, for the route to release first (``finish``): the overlap is
        there for that very train."""
        now = self.core.now
        for rid, at in list(self.core.overlap_pending.items()):
            if at is not None and now >= at and rid not in self.core.routes:
                self.release_overlap(rid)

    # ---- signal passed at danger ------------------------------------------------------------------------------
    def check_spad(self, became: set[str]) -> None:
        """冒进信号: a section inside a closed signal became occupied with the section in rear occupied."""
        core, st = self.core, self.core.station
        for sec in became:
            if core.clear(sec):
                continue
            for sig in core.signal_by_entry.get(sec, ()):
                if is_open(core.out.signals.get(sig, "")):
                    continue
                own = core.by_signal.get(sig)
                passing = [core.routes[h] for h in core.locks.section_holders(sec, (Hold.route,))
                           if h != own and h in core.routes]
                if any(p.route.direction is not st.signals[sig].direction
                       or st.signals[sig].at in p.route.path.joints for p in passing):
                    continue  # a movement from the other side, or one running past a signal inside its own route
                rear = st.signal_rear_track(sig)
                if rear is None or core.clear(st.tracks[rear].section):
                    continue
                core.alarm("spad", sig, f"signal {sig} passed at danger (冒进信号): {sec} occupied with the signal "
                         "closed", detail=f"{core.now:.2f}")
                if own is not None:
                    self.enter_at_danger(core.routes[own])

    def approach_locked(self, rs: RouteState) -> bool:
        """接近锁闭: the signal has been given and a train is in the approach section, or, for the onward route of a
        through movement, a train is coming over the route that ends at its signal (in that route's approach or in
        it: the signal in rear showed it the way on)."""
        return rs.stage in SIGNAL_GIVEN and bool(self.approaching(rs.route))

    def approaching(self, r: Route, depth: int = 3) -> list[str]:
        """The occupied sections from which a train comes to the signal of ``r``: its approach, or a route in rear
        (given, or in use) that ends at that signal, with the approach of that route (so on, ``depth`` routes back)."""
        core = self.core
        out = [s for s in r.approach if not core.clear(s)]
        if out or depth == 0:
            return out
        for other in core.routes.values():
            o = other.route
            if o.end_signal == r.signal and o.direction is r.direction and (
                    other.stage in SIGNAL_GIVEN or other.stage is RouteStage.in_use):
                out = [s for i, s in enumerate(other.sections) if not other.released[i] and not core.clear(s)]
                out = out or self.approaching(o, depth - 1)
                if out:
                    return out
        return []


def _look(rs: RouteState) -> tuple[object, ...]:
    """What a route's handler may change on the route itself (the rest it changes shows in :class:`~.quiet.Mark`)."""
    return (rs.stage, rs.since, rs.entered, rs.release_at, rs.overlap_release_at, rs.guide_first_clear,
            rs.guide_approach_seen, tuple(rs.released), tuple(rs.was_occupied), rs.run_on, rs.overlap_released,
            tuple(rs.fault_release_at.items()))

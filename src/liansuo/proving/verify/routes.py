"""The interlocking test (联锁试验) of one route, item by item as on a real test record (维规, docs/references.md): the
signal opens with an aspect of the table; turnouts move and lock; it cannot open with a turnout out of position or
without indication, or with a section occupied, and closes when any of these is lost; it never reopens by itself.
Release, guide, doors and aspects are in :mod:`.release`.

Each check runs on a fresh simulation (a :class:`~.probe.Probe`) and is recorded in the :class:`~.probe.Context`.
"""

from __future__ import annotations

from liansuo.proving.oracle.authority import Tracer
from liansuo.proving.verify.probe import Probe, against_running, other, prepare, route_line, turnout_groups
from liansuo.proving.verify.release import ReleaseChecks
from liansuo.proving.verify.routecheck import RouteCheck, RouteResult
from liansuo.stations.schema import SectionRole

_LINE = (SectionRole.approach, SectionRole.departure, SectionRole.block)
SETTLE_S = 20.0  # long enough for any turnout move (the slowest machine 6.6 s, two batches) and a 64D acceptance


class RouteTest(RouteCheck):
    """All checks of one route; ``run()`` returns its tally."""

    def run(self) -> RouteResult:
        """Every item; the items of each turnout and section run in turn on shared simulations where a check leaves
        it as it was (:meth:`~.routecheck.RouteCheck.in_turn`), else on fresh ones."""
        self.opens_from_the_other_positions()
        self.liaison()
        groups = turnout_groups(self.ctx.station, self.r)
        self.in_turn(groups, self.fresh, self.out_of_position_on, lambda g: self.turnout_out_of_position(*g))
        self.in_turn(groups, self.fresh, self.obstructed_on, lambda g: self.turnout_obstructed(*g))
        turnouts = [rt.id for rt in self.r.all_turnouts]
        sections = list(self.r.all_sections)
        self.in_turn(turnouts, self.fresh, self.without_indication_on,
                     lambda t: self.without_indication(Probe(self.ctx), t))
        self.in_turn(turnouts, self.open_probe, self.indication_lost_on, self.indication_lost)
        self.in_turn(sections, self.fresh, self.occupied_refused_on,
                     lambda s: self.occupied_refused(Probe(self.ctx), s, wait=True))
        self.in_turn(sections, self.open_probe, self.occupied_closes_on, self.occupied_closes)
        ReleaseChecks(self).run()
        return self.res

    # ---- shared simulations ---------------------------------------------------------------------------------------
    def fresh(self) -> Probe:
        p = Probe(self.ctx)
        prepare(p, self.r)
        return p

    def open_probe(self) -> Probe | None:
        p = Probe(self.ctx)
        return p if self.opened(p, "opens") else None

    def out_of_position_on(self, p: Probe, group: tuple[str, str]) -> bool:
        """:meth:`out_of_position` without the wait (the refused route changed nothing), then the turnout unlocked
        (it may stay where it lies: a route moves it)."""
        return self.out_of_position(p, *group, wait=False) and p.do(f"unlock {group[0]}").ok

    def obstructed_on(self, p: Probe, group: tuple[str, str]) -> bool:
        """:meth:`obstructed`, then the route cancelled, the obstruction cleared and the turnout back."""
        t, pos = group
        if not self.obstructed(p, t, pos):
            return False
        p.do(f"cancel {self.r.signal}")
        p.do(f"repair obstruction {t}")
        p.do(f"throw {t} {pos}")
        return p.until(lambda: p.state(self.r) == "released" and p.sim.turnout_state(t)[0] == pos, SETTLE_S)

    def without_indication_on(self, p: Probe, t: str) -> bool:
        """:meth:`without_indication`, then the route cancelled and the indication repaired."""
        self.without_indication(p, t)
        p.do(f"cancel {self.r.signal}")
        p.do(f"repair no-indication {t}")
        return p.until(lambda: p.state(self.r) == "released" and p.sim.turnout_state(t)[0] is not None, SETTLE_S)

    def indication_lost_on(self, p: Probe, t: str) -> bool:
        return self.closes_until_reopened(p, "no-indication", f"fault no-indication {t}",
                                          f"turnout {t} lost its indication", f"repair no-indication {t}",
                                          f"turnout {t}'s indication came back")

    def occupied_refused_on(self, p: Probe, s: str) -> bool:
        """:meth:`occupied_refused` without the wait (the refused route changed nothing), then the section cleared."""
        refused = self.occupied_refused(p, s, wait=False)
        p.do(f"vacate {s}")
        return refused and p.until(lambda: p.sim.section_state(s) != "occupied", SETTLE_S)

    def occupied_closes_on(self, p: Probe, s: str) -> bool:
        return self.closes_until_reopened(p, "section-occupied", f"occupy {s}", f"section {s} occupied",
                                          f"vacate {s}", f"section {s} cleared")

    # ---- opening ------------------------------------------------------------------------------------------------
    def opens_from_the_other_positions(self) -> None:
        """Every route, protection and driven turnout starts the other way: selecting the route moves them all,
        locks them, locks the sections, and the signal opens with one of the table's aspects."""
        r, p, st = self.r, Probe(self.ctx), self.ctx.station
        for t, pos in turnout_groups(st, r):
            p.do(f"throw {t} {other(pos)}")
        p.until(lambda: all(p.sim.turnout_state(t)[0] == other(pos) for t, pos in turnout_groups(st, r)), SETTLE_S)
        if not self.opened(p, "opens"):
            return
        shown = p.aspect(r.signal)
        self.check(shown in r.aspects, "aspect", f"signal {r.signal} shows {shown}; the table gives "
                   f"{'/'.join(r.aspects)}", p)
        if r.end_signal and r.kind == "train":
            # the signal ahead is closed: prepare to stop, the least permissive aspect the table gives
            least = min(r.aspects, key=self.ctx.rules.aspects.rank_of)
            self.check(shown == least, "aspect", f"signal {r.signal} shows {shown} with {r.end_signal} ahead "
                       f"closed; expected {least}", p)
        for rt in r.all_turnouts:
            at, locked = p.sim.turnout_state(rt.id)
            self.check(at == rt.position.value and locked, f"{rt.role}-turnout",
                       f"{rt.role} turnout {rt.id} is {at or 'without indication'}"
                       f"{' and locked' if locked else ' and not locked'}; the route needs it {rt.position.value} "
                       "and locked", p)
        for s in r.all_sections:
            self.check(p.sim.section_state(s) == "locked", "section-locked",
                       f"section {s} is {p.sim.section_state(s)} with the signal open", p)
        for t, pos in turnout_groups(st, r):
            result = p.do(f"throw {t} {other(pos)}")
            p.run(1.0)
            self.check(not result.ok and p.sim.turnout_state(t)[0] == pos and p.is_open(r.signal), "turnout-locked",
                       f"'throw {t} {other(pos)}' with the signal open: {result.message}; turnout {t} is "
                       f"{p.sim.turnout_state(t)[0]}, signal {r.signal} shows {p.aspect(r.signal)}", p)

    def liaison(self) -> None:
        """A departure's signal stays closed without the liaison: 64D without the neighbour's acceptance or with the
        line's departure section occupied, station block with the line blocked by the neighbour or its counters
        showing occupied, automatic block with the first block section occupied; it opens once the liaison is
        there."""
        r = self.r
        il_links = self.ctx.station.model.links
        link = next((lk for lk in il_links if lk.id == r.exit_link), None)
        if link is None:
            self.line_without_block()
            return
        p = Probe(self.ctx)
        if link.kind.value == "64d":
            p.do(route_line(r))
            p.settle()
            self.check(p.closed(r.signal) and p.state(r) == "locked", "liaison",
                       f"64D departure: signal {r.signal} shows {p.aspect(r.signal)} without the neighbour's "
                       "acceptance", p)
            # a train (or a red band) in the line's departure section: no block, the signal stays closed
            line = link.sections[0]
            p.do(f"occupy {line}")
            result = p.do(f"block-line {link.id} request")
            p.run(SETTLE_S)
            self.check(not result.ok and p.closed(r.signal), "liaison",
                       f"64D departure with {line} occupied: 'block-line {link.id} request' was "
                       f"{'accepted' if result.ok else 'refused'} and {r.signal} shows {p.aspect(r.signal)}", p)
            p.do(f"block-line {link.id} cancel")
            p.do(f"vacate {line}")
            p.run(1.0)
            prepare(p, r)
        elif link.kind.value == "station":
            # the neighbour has blocked the line for a train of its own: our departure stays at stop until it
            # cancels; then, with the line's counters showing occupied, it stays at stop until they show clear
            p.do(f"neighbour {link.id} block")
            p.run(SETTLE_S)
            result = p.do(route_line(r))
            p.run(SETTLE_S)
            self.check(result.ok and p.closed(r.signal), "liaison",
                       f"station-block departure with line {link.id} blocked by the neighbour: '{route_line(r)}' was "
                       f"{'accepted' if result.ok else 'refused: ' + result.message} and {r.signal} shows "
                       f"{p.aspect(r.signal)}", p)
            p.do(f"neighbour {link.id} cancel")
            ok = p.until(lambda: p.state(r) == "open", SETTLE_S)
            self.check(ok, "liaison", f"signal {r.signal} did not open once the neighbour cancelled its block on "
                       f"{link.id}: {p.blocker(r)}", p)
            beyond = [s for s in link.sections if s not in r.sections]
            if not beyond:
                self.res.not_applicable.append("liaison (the line's sections are the route's own)")
                return
            p = Probe(self.ctx)
            self.closed_while_occupied(p, beyond[0], "station block", "line section")
        elif against_running(self.ctx.station, link.id):
            # against the line's running direction: refused until the direction is changed (改方), which a line that
            # is not bidirectional never allows
            result = p.do(route_line(r))
            self.check(not result.ok and "direction" in result.message, "line-direction",
                       f"'{route_line(r)}' against the running direction of line {link.id} without a direction "
                       f"change was {'accepted' if result.ok else 'refused: ' + result.message}", p)
            if not link.bidirectional:
                self.res.not_applicable.append("liaison (line not bidirectional)")
                return
            prepare(p, r)
            p.do(route_line(r))
        else:
            beyond = [s for s in link.sections if s not in r.sections]
            if not beyond:  # the route itself runs over the line's sections to the boundary
                self.res.not_applicable.append("liaison (the block sections are the route's own)")
                return
            self.closed_while_occupied(p, beyond[0], "automatic block", "the first block section")
        ok = p.until(lambda: p.state(r) == "open", SETTLE_S)
        self.check(ok, "liaison", f"signal {r.signal} did not open once the liaison was given: {p.blocker(r)}", p)

    def line_without_block(self) -> None:
        """A departure onto a line the station file gives no block system: the movement's authority (traced on the
        layout) runs on over the line's sections, so the signal stays closed while one of them is occupied."""
        r = self.r
        st = self.ctx.station
        if r.kind != "train":
            self.res.not_applicable.append("liaison")
            return
        lies = {t.id: t.position.value for t in r.all_turnouts}
        a = Tracer(st).trace(r.signal, "train", lies.get)
        line = [s for s in a.sections if s not in r.sections and st.sections[s].role in _LINE]
        if not line:
            self.res.not_applicable.append("liaison")
            return
        p = Probe(self.ctx)
        self.closed_while_occupied(p, line[0], "departure onto a line without block", "line section")
        ok = p.until(lambda: p.state(r) == "open", SETTLE_S)
        self.check(ok, "liaison", f"signal {r.signal} did not open once {line[0]} was clear: {p.blocker(r)}", p)

    def closed_while_occupied(self, p: Probe, section: str, case: str, what: str) -> None:
        """The departure is set with ``section`` beyond it occupied: its signal stays closed; then it clears."""
        r = self.r
        p.do(f"occupy {section}")
        p.do(route_line(r))
        p.settle()
        self.check(p.closed(r.signal), "liaison", f"{case}: signal {r.signal} shows {p.aspect(r.signal)} with "
                   f"{what} {section} occupied", p)
        p.do(f"vacate {section}")

    # ---- turnouts -----------------------------------------------------------------------------------------------
    def turnout_out_of_position(self, t: str, pos: str) -> None:
        self.out_of_position(Probe(self.ctx), t, pos, wait=True)

    def out_of_position(self, p: Probe, t: str, pos: str, *, wait: bool) -> bool:
        """A turnout lying the other way and single-locked there: the route cannot be set (``wait``: and its signal
        stays closed for a while). True when the turnout lay the other way and the route was refused."""
        r = self.r
        laid = self.lay_other(p, t, pos)
        p.do(f"lock {t}")
        result = p.do(route_line(r))
        if wait:
            p.settle()
        self.check(not result.ok and p.closed(r.signal), "turnout-out-of-position",
                   f"turnout {t} single-locked {other(pos)}: '{route_line(r)}' was "
                   f"{'accepted' if result.ok else 'refused'} and signal {r.signal} shows {p.aspect(r.signal)}", p)
        return laid and not result.ok

    def lay_other(self, p: Probe, t: str, pos: str) -> bool:
        """Throw ``t`` the other way from ``pos`` and wait until it lies there."""
        p.do(f"throw {t} {other(pos)}")
        return p.until(lambda: p.sim.turnout_state(t)[0] == other(pos), SETTLE_S)

    def turnout_obstructed(self, t: str, pos: str) -> None:
        self.obstructed(Probe(self.ctx), t, pos)

    def obstructed(self, p: Probe, t: str, pos: str) -> bool:
        """A turnout that cannot reach its position (4 mm obstruction): the route stays unlocked, the signal closed.
        True when the turnout lay the other way first and the signal stayed closed."""
        r = self.r
        laid = self.lay_other(p, t, pos)
        p.do(f"fault obstruction {t}")
        prepare(p, r)
        p.do(route_line(r))
        p.settle()
        return self.check(p.closed(r.signal), "turnout-obstructed", f"turnout {t} obstructed on its way {pos}: "
                          f"signal {r.signal} shows {p.aspect(r.signal)}", p) and laid

    def without_indication(self, p: Probe, t: str) -> None:
        """Without indication the signal cannot open (and losing it closes an open signal, which stays closed after
        the repair until the operator reopens it (重复开放): :meth:`indication_lost`)."""
        r = self.r
        p.do(f"fault no-indication {t}")
        prepare(p, r)
        p.do(route_line(r))
        p.settle()
        self.check(p.closed(r.signal), "no-indication", f"turnout {t} without indication: signal {r.signal} shows "
                   f"{p.aspect(r.signal)}", p)

    def indication_lost(self, t: str) -> None:
        p = Probe(self.ctx)
        if not self.opened(p, "opens"):
            return
        self.indication_lost_on(p, t)

    def closes_until_reopened(self, p: Probe, check: str, cause: str, what: str, repair: str, repaired: str) -> bool:
        """On an open signal: ``cause`` closes it with an alarm; after ``repair`` it stays closed until the operator
        reopens it (重复开放). True when it was reopened."""
        sig = self.r.signal
        p.do(cause)
        p.run(1.0)
        if not self.check(p.closed(sig), check, f"{what}: signal {sig} still shows {p.aspect(sig)}", p):
            return False
        self.closing_alarm(p)
        result = p.do(f"reopen {sig}")  # the cause still there: never reopened
        p.run(1.0)
        if not self.check(not result.ok and p.closed(sig), "reopen", f"'reopen {sig}' before {repaired}: "
                          f"{'accepted' if result.ok else result.message}; signal shows {p.aspect(sig)}", p):
            return False
        p.do(repair)
        p.run(5.0)
        if not self.check(p.closed(sig), "no-automatic-reopening", f"signal {sig} reopened by itself "
                          f"({p.aspect(sig)}) after {repaired}", p):
            return False
        result = p.do(f"reopen {sig}")
        p.run(1.0)
        return self.check(result.ok and p.is_open(sig), "reopen", f"'reopen {sig}' after {repaired}: "
                          f"{result.message}; signal shows {p.aspect(sig)}", p)

    def closing_alarm(self, p: Probe) -> None:
        """A signal closed abnormally raises an alarm (非正常关闭报警)."""
        sig = self.r.signal
        alarms = p.sim.alarm_texts()
        self.check(any(f"signal {sig} closed" in a for a in alarms), "closing-alarm",
                   f"signal {sig} closed abnormally without an alarm (alarms: {'; '.join(alarms) or 'none'})", p)

    # ---- sections -----------------------------------------------------------------------------------------------
    def occupied_refused(self, p: Probe, s: str, *, wait: bool) -> bool:
        """An occupied route, fouling or overlap section: the route is refused (``wait``: and its signal stays closed
        for a while); occupied while open, the signal closes until reopened (:meth:`occupied_closes`). True when it
        was refused."""
        r = self.r
        p.do(f"occupy {s}")
        prepare(p, r)
        result = p.do(route_line(r))
        if wait:
            p.settle()
        self.check(not result.ok and p.closed(r.signal), "section-occupied",
                   f"section {s} occupied: '{route_line(r)}' was {'accepted' if result.ok else 'refused'} and "
                   f"signal {r.signal} shows {p.aspect(r.signal)}", p)
        return not result.ok

    def occupied_closes(self, s: str) -> None:
        p = Probe(self.ctx)
        if not self.opened(p, "opens"):
            return
        self.occupied_closes_on(p, s)

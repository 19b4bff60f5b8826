"""What a route's handler read when it last ran (:class:`~.state.RouteMemo`), behind one small interface: the
route lifecycle (:mod:`.lifecycle`) asks :meth:`Memos.unchanged` whether a route's cycle can be skipped, and hands
each handler's reads to :meth:`Memos.setting`, :meth:`Memos.open_memo` or :meth:`Memos.release` to be kept. A memo
is a pure cache: a skipped cycle changes what the handler would have changed, which is nothing (the suite's
tests/test_shortcuts_same.py runs the handler after every skip to hold it to that)."""

from __future__ import annotations

from liansuo.interlocking.core import Core
from liansuo.interlocking.state import OpenMemo, Reads, ReleaseMemo, RouteState, SettingMemo
from liansuo.interlocking.table.route import Route, RunOn


class Memos:
    """The memos of every route of one interlocking ``core``, and the relays each route reads."""

    def __init__(self, core: Core) -> None:
        self.core = core
        self._reads: dict[str, tuple[RunOn | None, Reads]] = {}  # route id -> its run-on and what it reads (reads)

    def setting(self, rs: RouteState) -> SettingMemo:
        """A route setting whose turnouts are not all in position this cycle."""
        return SettingMemo(rs, self.core.cycles, self.reads(rs))

    def release(self, rs: RouteState, watched: frozenset[str]) -> ReleaseMemo:
        """A route in use whose release check read the track relays of ``watched`` this cycle."""
        return ReleaseMemo(rs, self.core.cycles, watched)

    def unchanged(self, rs: RouteState) -> bool:
        """The handler of ``rs``'s stage would read only what it read last cycle, unchanged, and so change nothing:
        its memo (:class:`~.state.RouteMemo`) is of this stage and holds (a route in use: :class:`ReleaseMemo`,
        setting: :class:`SettingMemo`, open: :class:`OpenMemo` and :meth:`_open_unchanged`). When so, the memo is
        marked as holding through this cycle too."""
        core, memo = self.core, rs.memo
        if memo is None or memo.stage is not rs.stage or not memo.holds(rs, core.cycles, core.changes):
            return False
        if type(memo) is OpenMemo and not self._open_unchanged(rs, memo):
            return False
        memo.cycle = core.cycles
        return True

    def open_memo(self, rs: RouteState, aspect: str) -> OpenMemo:
        core, r = self.core, rs.route
        onward = core.route_of(r.end_signal) if r.end_signal else None
        end_aspect = core.out.signals.get(r.end_signal) if r.end_signal else None
        return OpenMemo(rs, core.cycles, self.reads(rs), ledger=core.locks.version, aspect=aspect,
                        end_aspect=end_aspect, onward=onward, liaison=self._liaison(r),
                        usu_failed=r.signal in core.usu_failed)

    def _open_unchanged(self, rs: RouteState, memo: OpenMemo) -> bool:
        """Of the interlocking's own state, what an open signal's supervision reads is as ``memo`` found it."""
        core, r = self.core, rs.route
        end = r.end_signal
        if memo.ledger != core.locks.version or core.out.signals.get(r.signal) != memo.aspect:
            return False
        if end is not None:
            onward = core.route_of(end)
            if (core.out.signals.get(end) != memo.end_aspect or onward is not memo.onward
                    or (onward is not None and onward.run_on is not memo.onward_run_on)):
                return False
        return (r.signal in core.usu_failed) == memo.usu_failed and self._liaison(r) == memo.liaison

    def _liaison(self, r: Route) -> tuple[object, ...]:
        """The state of the line a departure leaves by, as the signal's conditions read it (64D, station block,
        automatic block direction); () for a route that leaves by no line."""
        core, link = self.core, r.exit_link
        if link is None:
            return ()
        block, station = core.links.get(link), core.station_links.get(link)
        return (block.state if block else None, station.state if station else None, link in core.line_out)

    def reads(self, rs: RouteState) -> Reads:
        """The relays a route's supervision reads (:class:`Reads`), worked out once per route and run-on."""
        r = rs.route
        done = self._reads.get(r.id)
        if done is not None and done[0] is rs.run_on:
            return done[1]
        core = self.core
        secs = {*rs.sections, *r.approach, *(f.section for f in r.fouling), *r.overlap_sections, *r.line_sections}
        link = r.exit_link
        if link in core.links:
            secs.add(core.links[link].departure_section)
        if link in core.station_links:
            secs.update(core.station_links[link].sections)
        if link in core.auto_links:
            secs.update(core.auto_links[link])
        reads = Reads(sections=frozenset(secs), turnouts=frozenset(t.id for t in rs.all_turnouts),
                      signals=frozenset({r.signal, *([r.end_signal] if r.end_signal else [])}),
                      doors=frozenset(k for sec in core.door_sections(r) for k in core.platform_doors.get(sec, ())))
        self._reads[r.id] = (rs.run_on, reads)
        return reads

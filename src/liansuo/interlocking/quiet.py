"""The interlocking at rest: a cycle that changed nothing is followed by cycles that change nothing, until a relay
changes, the operator gives a command, or a timer runs out.

A cycle is a function of the interlocking's state, its relay inputs and the time. When one cycle changed nothing
(no relay changed before it, every route's cycle was skipped by its memo or waited without a change, the turnouts,
lines, alarms, events, locks and outputs stayed as they were), the next cycle starts from the same state with the
same relays, so it changes nothing either, unless one of the time conditions read in a cycle turns: a turnout's
move time-out, the squeeze alarm of a turnout without indication, a time release, a section fault release
counting down, an overlap's release time. A
:class:`Quiet` keeps those conditions, asked with the very rules the cycle asks (``TurnoutState.move_timed_out``,
``squeeze_due``, ``Core.squeeze_watched``), and
:meth:`~.cbi.Interlocking.cycle` runs no cycle while it holds (it only moves the clock and the cycle count).

tests/test_quiet_same.py runs the real cycle in place of every quiet one and compares the whole state (pickled, not
read through this module) before and after it.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import TYPE_CHECKING

from liansuo.interlocking.state import RouteStage, TurnoutState

if TYPE_CHECKING:
    from liansuo.interlocking.core import Core
    from liansuo.interlocking.io import Changes


@dataclass(frozen=True)
class CycleMark:
    """What a cycle may change, counted before it: compared after it (:func:`quiet_after`)."""

    logged: int
    alarms: int
    locks: int
    moving: int
    queued: int
    lines: tuple[str, ...]
    dirty: bool

    @staticmethod
    def of(core: Core) -> CycleMark:
        return CycleMark(core.logged, len(core.alarms), core.locks.version, len(core.moving), len(core.queue),
                         tuple(sl.state.value for sl in core.station_links.values()),
                         core.codes_dirty or (core.blocks_dirty and bool(core.autoblock.signals)))


@dataclass(frozen=True)
class Quiet:
    """The time conditions that would make the next cycle act (each as the cycle writes it, negated)."""

    moves: tuple[TurnoutState, ...]  # the turnouts being driven: their move time-out
    timeout_s: float
    squeezes: tuple[TurnoutState, ...]  # the turnouts the squeeze alarm watches
    squeeze_s: float
    due: tuple[float, ...]  # time releases and overlap releases: once now >= it

    def holds(self, now: float) -> bool:
        """A cycle at ``now`` would change nothing (with no relay changed and no command since the last cycle).
        The turnouts' states are the interlocking's own: nothing changes them while it rests."""
        return (not any(ts.move_timed_out(now, self.timeout_s) for ts in self.moves)
                and not any(ts.squeeze_due(now, self.squeeze_s) for ts in self.squeezes)
                and all(not now >= at for at in self.due))


def quiet_after(core: Core, before: CycleMark, changes: Changes, routes_settled: bool) -> Quiet | None:
    """The :class:`Quiet` of the cycle just run, if it changed nothing; None if it changed something or may act
    again on its own (a guide aspect without a route, a move waiting in the queue while fewer than the allowed
    moves run)."""
    if (changes.tracks or changes.turnouts or changes.signals or changes.doors or changes.pulses
            or changes.commanded or not routes_settled):
        return None
    out = core.out
    if out.changed_signals or out.changed_turnouts or out.line_out or out.axle_resets or core.guide_only:
        return None
    if CycleMark.of(core) != before or before.dirty:
        return None
    if core.queue and len(core.moving) < core.rules.turnout_concurrency:
        return None
    moves = tuple(core.turnouts[t] for t in core.moving)
    due = [at for at in core.overlap_pending.values() if at is not None]
    due += [rs.release_at for rs in core.routes.values()  # (one over, waiting for its route to clear, waits on it)
            if rs.stage is RouteStage.time_release and rs.release_at is not None
            and not (core.now >= rs.release_at and any(not core.clear(s) for s in rs.sections))]
    due += [at for rs in core.routes.values() for at in rs.fault_release_at.values()]
    return Quiet(moves, core.rules.turnout_timeout_s, tuple(core.squeeze_watched()), core.rules.squeeze_alarm_s,
                 tuple(due))

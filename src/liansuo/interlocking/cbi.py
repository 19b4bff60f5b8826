"""One station's computer-based interlocking (计算机联锁): the core, the route lifecycle and the operator's commands,
run cycle by cycle.

Evaluation order per cycle (as in one real CBI): inputs -> signal-passed-at-danger check against last cycle's
aspects -> 64D line -> turnout supervision and the move queue -> routes in order of selection -> automatic block
signals -> cab codes. ``cycle(t)`` is given the simulated time; nothing here reads the wall clock.
"""

from __future__ import annotations

from collections import deque

from liansuo.interlocking.core import Core
from liansuo.interlocking.io import Alarm, Event, Outputs, RelayBoard
from liansuo.interlocking.lifecycle import RouteLifecycle
from liansuo.interlocking.locks import LockLedger
from liansuo.interlocking.operations import Operator
from liansuo.interlocking.quiet import CycleMark, Quiet, quiet_after
from liansuo.interlocking.state import RouteState
from liansuo.interlocking.table.route import InterlockingTable
from liansuo.rules import RuleSet


class Interlocking:
    """``core``: the state and what a signal needs; ``lifecycle``: the route state machine; ``operator``: the
    console's commands (``il.operator.set_route(...)``). ``locked_at_start``: after power-up (上电), every section
    locked until the power-up release."""

    skip_quiet = True  # run no cycle while the interlocking is at rest (quiet.py); tests switch it off

    def __init__(self, table: InterlockingTable, rules: RuleSet | None = None, cycle_s: float = 0.25, *,
                 locked_at_start: bool = False, now: float = 0.0) -> None:
        self.core = Core(table, rules, cycle_s, locked_at_start=locked_at_start, now=now)
        self.lifecycle = RouteLifecycle(self.core)
        self._operator = Operator(self.core, self.lifecycle)
        self.quiet: Quiet | None = None  # at rest after the last cycle: until when (quiet.py)

    @property
    def operator(self) -> Operator:
        """The console's commands. Reaching for them ends a rest (:mod:`.quiet`): a command may change anything."""
        self.quiet = None
        return self._operator

    def rest(self, cycles: int, t: float) -> None:
        """``cycles`` cycles at rest, the last at ``t``, that the world ran in one go: each would have found the
        interlocking quiet (:mod:`.quiet`: no relay changed, no command, no timer ran out), so only its clock moves."""
        self.core.tick(t, cycles)

    def cycle(self, t: float) -> Outputs:
        core = self.core
        quiet = self.quiet
        if quiet is not None and self.skip_quiet and not core.board.pending() and quiet.holds(t):
            core.tick(t)
            return core.out
        before = CycleMark.of(core)
        changes = core.take_inputs(t)
        if changes.tracks:
            self.lifecycle.check_spad(changes.tracks)
        core.apply_inputs(changes)
        settled = self.lifecycle.advance_all()
        out = core.give_outputs(changes)
        self.quiet = quiet_after(core, before, changes, settled)
        return out

    # ---- what the world reads of the interlocking's state ------------------------------------------------------
    @property
    def rules(self) -> RuleSet:
        """The national rule set it runs."""
        return self.core.rules

    @property
    def out(self) -> Outputs:
        """The outputs: aspects, turnout drives, doors, cab codes, line pulses."""
        return self.core.out

    @property
    def board(self) -> RelayBoard:
        """The relay inputs as the interlocking last read them."""
        return self.core.board

    @property
    def routes(self) -> dict[str, RouteState]:
        """The routes in progress, in order of selection."""
        return self.core.routes

    @property
    def by_signal(self) -> dict[str, str]:
        return self.core.by_signal

    @property
    def locks(self) -> LockLedger:
        return self.core.locks

    @property
    def alarms(self) -> dict[str, Alarm]:
        return self.core.alarms

    @property
    def events(self) -> deque[Event]:
        return self.core.events

"""Replaying a recording (``liansuo replay``): re-simulate its commands on its station and check everything the
recording says against what the replay does.

Time is injected, so the same commands at the same cycles on the same station give the same relays. The
:class:`Replayer` checks, in the order they happen: the state at the start (the ``init`` record), every command's
answer (accepted or refused, and the words of it), what each command changed without a cycle (``chg``), and every
cycle's changes, written or quiet (``cyc``). Together with the loader's checks (commands numbered without a gap, the
end record's count), a record edited, added or dropped is found. A recorded command that would run past the end of
the recording (``run 1000h`` in a damaged file) is stopped there, so a replay never takes longer than the recording
says it lasted.
"""

from __future__ import annotations

import json
from dataclasses import dataclass
from typing import Any

from liansuo.interlocking.io import Result
from liansuo.kit.printable import printable
from liansuo.simulation.recording.file import Recording, recording_station
from liansuo.simulation.recording.recorder import Recorder, State, diff
from liansuo.simulation.recording.schema import CmdRecord, state_of
from liansuo.simulation.sim import Simulation
from liansuo.stations.station import Station

MAX_MISMATCHES = 50  # listed before the rest are only counted
SHOWN_CHARS = 300  # of each side of a mismatch


@dataclass(frozen=True)
class Played:
    """A recorded command as replayed: what it answered then and now."""

    file_line: int
    cmd: CmdRecord
    ok_now: bool
    msg_now: str


class _Overrun(Exception):
    """A recorded command ran the simulation past the recording's end."""


class _Checker(Recorder):
    """The recorder of the replay: it compares what it would write with the recording instead of writing it."""

    def __init__(self, replayer: Replayer) -> None:
        self.replayer = replayer
        super().__init__(replayer.sim, lambda record: None)

    def header(self) -> None:
        self.replayer.check_init(self._state)

    def _cycle_done(self, changes: State) -> None:
        self.replayer.check_cycle(self.cycles, changes)

    def _command_done(self, n: int, t: float, line: str, result: Result) -> None:
        self.replayer.check_answer(result)

    def _command_changes(self, changes: State) -> None:
        self.replayer.check_changes(changes)


class Replayer:
    """Re-simulates a recording on a fresh simulation of ``station`` (by default the recording's own, checked to be
    the one it was made on) and collects every difference in :attr:`mismatches`."""

    def __init__(self, rec: Recording, station: Station | None = None) -> None:
        self.rec = rec
        self.station = station if station is not None else recording_station(rec)
        self.mismatches: list[str] = []
        self.reset()

    def reset(self) -> None:
        self.sim = Simulation(self.station, cycle_s=self.rec.cycle_s)
        self.mismatches = []
        self.overrun = False
        self.next_cmd = 0
        self._current = 0  # the number of the command being replayed
        self.played: list[Played] = []  # commands replayed so far, with their answers now
        self.recorder = _Checker(self).attach()

    @property
    def cycle(self) -> int:
        return self.recorder.cycles

    @property
    def done(self) -> bool:
        """The whole recording is replayed (or stopped where a command ran past its end)."""
        return self.overrun or (self.cycle >= self.rec.cycles and self.next_cmd >= len(self.rec.commands))

    # ---- the checks ------------------------------------------------------------------------------------------
    def _mismatch(self, line: int, text: str) -> None:
        if len(self.mismatches) < MAX_MISMATCHES:
            self.mismatches.append(f"{self.rec.path}:{line}: {text}")
        elif len(self.mismatches) == MAX_MISMATCHES:
            self.mismatches.append(f"{self.rec.path}: further mismatches not listed")

    def check_init(self, state: State) -> None:
        want = state_of(self.rec.init)
        if state != want:
            self._mismatch(2, f"the state at the start (init): recorded {_shown(diff(state, want))}, replayed "
                              f"{_shown(diff(want, state))}")

    def check_cycle(self, n: int, changes: State) -> None:
        if n > self.rec.cycles:
            raise _Overrun
        line, rec = self.rec.cycles_changed.get(n, (self.rec.line_of_cycle(n), None))
        want = state_of(rec) if rec is not None else {}
        if changes != want:
            t = self.rec.header.t0 + n * self.rec.cycle_s
            self._mismatch(line, f"cycle {n} (t = {t:g} s): recorded {_shown(want)}, replayed {_shown(changes)}")

    def check_answer(self, result: Result) -> None:
        if not self._current:
            return
        line, cmd = self.rec.commands[self._current - 1]
        self.played.append(Played(line, cmd, result.ok, result.message))
        if result.ok != cmd.ok or result.message != cmd.msg:
            said = "accepted" if cmd.ok else "refused"
            now = "accepted" if result.ok else "refused"
            self._mismatch(line, f"'{printable(cmd.line)}' (t = {cmd.t:g} s) was {said}: '{printable(cmd.msg)}'; "
                                 f"replayed, {now}: '{printable(result.message)}'")

    def check_changes(self, changes: State) -> None:
        if not self._current:
            return
        cmd_line, cmd = self.rec.commands[self._current - 1]
        line, rec = self.rec.changes.get(self._current, (cmd_line, None))
        want = state_of(rec) if rec is not None else {}
        if changes != want:
            self._mismatch(line, f"what '{printable(cmd.line)}' (t = {cmd.t:g} s) changed: recorded {_shown(want)}, "
                                 f"replayed {_shown(changes)}")

    # ---- playing ---------------------------------------------------------------------------------------------
    def advance(self, cycle: int) -> None:
        """Run forward to ``cycle`` cycles (at most the recording's end), sending each recorded command at its
        place and checking its answer."""
        cycle = min(cycle, self.rec.cycles)
        while not self.overrun:
            if self.next_cmd < len(self.rec.commands):
                line, cmd = self.rec.commands[self.next_cmd]
                if cmd.n <= self.cycle and cmd.n <= cycle:
                    self.next_cmd += 1
                    self._send(line, cmd)
                    continue
            if self.cycle >= cycle:
                return
            self.sim.step()

    def _send(self, line: int, cmd: CmdRecord) -> None:
        self.recorder.source = cmd.by
        self._current = cmd.i
        try:
            self.sim.command(cmd.line)  # the checker compares its answer and what it changed
        except _Overrun:
            self.overrun = True
            self._mismatch(line, f"'{printable(cmd.line)}' (t = {cmd.t:g} s) runs past the end of the recording "
                                 f"(cycle {self.rec.cycles}, t = {self.rec.end.t:g} s); the replay stops there")
        finally:
            self._current = 0

    def seek(self, t: float) -> None:
        target = max(0, min(round(t / self.rec.cycle_s), self.rec.cycles))
        if target < self.cycle:
            self.reset()
        self.advance(target)

    def verify(self) -> list[str]:
        """Replay the whole recording from the start; the mismatches (none when the replay reproduces it)."""
        self.reset()
        self.advance(self.rec.cycles)
        return self.mismatches


def _shown(state: State | dict[str, Any]) -> str:
    text = json.dumps(state, sort_keys=True)
    return text if len(text) <= SHOWN_CHARS else text[:SHOWN_CHARS - 3] + "..."

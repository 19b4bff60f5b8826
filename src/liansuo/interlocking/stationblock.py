"""Automatic station-to-station block (自动站间闭塞) from this station's side.

The line between two stations is one block section, proven clear by its axle counters (计轴). Nobody requests or
accepts a block: a departure route locked with the line clear, and not blocked by the neighbour, blocks the line for
our train (发车闭塞: BLOCK is sent); the route cancelled before the train leaves unblocks it (CANCEL). Our train
entering the line occupies it; once the counters show the whole line clear again the train has arrived complete and
the block restores by itself. A BLOCK from the neighbour blocks the line towards us (接车闭塞): no departure from here
until its train has arrived and the line is clear again, when we restore it (RESTORE is sent).

A line that shows occupied with no train expected (a disturbed count) keeps every departure at stop until it is clear
again; the operator resets the counters after confirming the line clear (计轴复零, :mod:`.operations`).
"""

from __future__ import annotations

from collections.abc import Callable, Collection
from dataclasses import dataclass
from enum import StrEnum

BLOCK, CANCEL, RESTORE = "block", "cancel", "restore"


class StationBlockState(StrEnum):
    idle = "idle"  # 闭塞定位: not blocked
    outbound = "outbound"  # 发车闭塞: blocked for our departure, the train not yet on the line
    departed = "departed"  # our train is on the line (区间占用)
    inbound = "inbound"  # the neighbour blocked the line for its train towards us (接车闭塞)
    arriving = "arriving"  # its train is on the line towards us


Notify = Callable[[str, str], None]  # (kind, text) -> an event in the interlocking's log
Send = Callable[[str, str], None]  # (link, pulse)


@dataclass
class StationBlockLink:
    id: str
    sections: tuple[str, ...]  # the line's sections, nearest the station first
    state: StationBlockState = StationBlockState.idle

    def blocker(self, clear: Callable[[str], bool]) -> str:
        """Why a departure onto this line must stay at stop ('' when it may go)."""
        s = self.state
        if s in (StationBlockState.inbound, StationBlockState.arriving):
            return (f"line {self.id} is blocked by the neighbour station for a train towards us (自动站间闭塞, "
                    f"{s.value})")
        if s is StationBlockState.departed:
            return f"our previous train is still on line {self.id}"
        occupied = [sec for sec in self.sections if not clear(sec)]
        if occupied:
            return (f"line section {occupied[0]} shows occupied (axle counter): no block onto line {self.id}; once "
                    f"the line is confirmed clear on site, reset the counter ('axle-reset {occupied[0]}')")
        if s is not StationBlockState.outbound:
            return f"line {self.id} is not yet blocked for our departure"
        return ""

    def step(self, departing: bool, clear: Callable[[str], bool], pulses: Collection[str], send: Send,
             event: Notify) -> None:
        """One cycle: the neighbour's pulses, then the line's counters, then our departure route (``departing``: a
        departure route onto this line is locked)."""
        before = self.state
        line_clear = all(clear(sec) for sec in self.sections)
        S = StationBlockState
        for p in sorted(pulses):
            if p == BLOCK and self.state is S.idle:
                self.state = S.inbound
            elif p == CANCEL and self.state is S.inbound and line_clear:
                self.state = S.idle
        if not line_clear:
            if self.state is S.outbound:
                self.state = S.departed
            elif self.state is S.inbound:
                self.state = S.arriving
        elif self.state is S.departed:
            self.state = S.idle  # the counters show our train has left the line at the neighbour
        elif self.state is S.arriving:
            self.state = S.idle
            send(self.id, RESTORE)
        if departing and self.state is S.idle and line_clear:
            self.state = S.outbound
            send(self.id, BLOCK)
        elif not departing and self.state is S.outbound:
            self.state = S.idle
            send(self.id, CANCEL)
        if self.state is not before:
            event("block", f"line {self.id} (station block): {before.value} -> {self.state.value}")

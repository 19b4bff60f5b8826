"""64D semi-automatic block (64D 半自动闭塞) between this station and a neighbour, from this station's side.

The two block machines talk by line pulses (each sent for a few seconds): REQUEST (闭塞请求), ACCEPT (同意),
DEPART (出发通知), RESTORE (到达复原 / 取消复原), ACCIDENT (事故复原). Departure needs the neighbour's acceptance;
once the train occupies the departure section the line is blocked until the neighbour restores it after the arrival.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass
from enum import StrEnum


class BlockState(StrEnum):
    idle = "idle"  # 定位: line clear, no block
    requested = "requested"  # we asked to send a train; waiting for ACCEPT
    permitted = "permitted"  # neighbour accepted: our starting signal may open (发车表示灯绿)
    departed = "departed"  # our train is on the line (区间占用)
    asked = "asked"  # the neighbour asks to send us a train
    accepted = "accepted"  # we accepted (接车表示灯绿)
    arriving = "arriving"  # the neighbour's train is on the line towards us (接车表示灯红)
    arrived = "arrived"  # it arrived complete; waiting for our RESTORE


REQUEST, ACCEPT, DEPART, RESTORE, ACCIDENT = "request", "accept", "depart", "restore", "accident"


@dataclass
class BlockLink:
    id: str
    departure_section: str  # the section a departing train occupies first (and an arriving train last)
    state: BlockState = BlockState.idle
    accidents: int = 0  # the accident button is counted, as on the real console

    # ---- operator actions: return (refusal or '', pulse to send or '') ------------------------------------------
    def operate(self, action: str, section_clear: bool = True) -> tuple[str, str]:
        """``section_clear``: the departure section's track relay is up. A block is requested or accepted only
        with it clear: a train (or a fault) there would meet the one the block lets onto the line."""
        s = self.state
        occupied = (f"block line {self.id}: departure section {self.departure_section} shows occupied; the block "
                    "is given only with the line's track circuit clear")
        if action == "request":
            if s is not BlockState.idle:
                return (f"block line {self.id} is not clear ({s.value}); a request needs the line in its normal "
                        "state"), ""
            if not section_clear:
                return occupied, ""
            self.state = BlockState.requested
            return "", REQUEST
        if action == "accept":
            if s is not BlockState.asked:
                return f"block line {self.id}: the neighbour has not asked to send a train ({s.value})", ""
            if not section_clear:
                return occupied, ""
            self.state = BlockState.accepted
            return "", ACCEPT
        if action == "cancel":
            if s not in (BlockState.requested, BlockState.permitted, BlockState.accepted):
                return f"block line {self.id}: nothing to cancel before a departure ({s.value})", ""
            self.state = BlockState.idle
            return "", RESTORE
        if action == "restore":
            if s is not BlockState.arrived:
                return (f"block line {self.id}: restore (复原) only after the train has arrived complete "
                        f"({s.value}); use 'accident' to force it"), ""
            self.state = BlockState.idle
            return "", RESTORE
        if action == "accident":
            self.state = BlockState.idle
            self.accidents += 1
            return "", ACCIDENT
        return f"unknown block-line action '{action}': use request, accept, cancel, restore or accident", ""

    # ---- pulses from the neighbour ------------------------------------------------------------------------------
    def receive(self, pulse: str) -> None:
        s = self.state
        if pulse == ACCIDENT:
            self.state = BlockState.idle
        elif pulse == REQUEST and s is BlockState.idle:
            self.state = BlockState.asked
        elif pulse == ACCEPT and s is BlockState.requested:
            self.state = BlockState.permitted
        elif pulse == DEPART and s is BlockState.accepted:
            self.state = BlockState.arriving
        elif pulse == RESTORE and s in (BlockState.departed, BlockState.asked, BlockState.requested,
                                        BlockState.permitted):
            self.state = BlockState.idle

    # ---- what the trains do -------------------------------------------------------------------------------------
    def departure_section_occupied(self) -> str:
        """Our train entered the line: returns the pulse to send (DEPART) if this was a departure."""
        if self.state is BlockState.permitted:
            self.state = BlockState.departed
            return DEPART
        return ""

    def arrival_complete(self) -> None:
        if self.state is BlockState.arriving:
            self.state = BlockState.arrived


Notify = Callable[[str, str], None]  # (kind, text) -> an event in the interlocking's log


def line_pulses_in(links: dict[str, BlockLink], link: str, msgs: set[str], event: Notify) -> None:
    """Pulses from the neighbour's block machine."""
    bl = links.get(link)
    if bl is None:
        return
    for m in sorted(msgs):
        before = bl.state
        bl.receive(m)
        if bl.state is not before:
            event("block", f"block line {link}: {m} received, {before.value} -> {bl.state.value}")


def line_tracks_changed(links: dict[str, BlockLink], tracks: set[str], clear: Callable[[str], bool],
                        send: Callable[[str, str], None], event: Notify) -> None:
    """A departure section became occupied (our train left: DEPART) or clear (the neighbour's train arrived)."""
    for bl in links.values():
        if bl.departure_section not in tracks:
            continue
        if not clear(bl.departure_section):
            pulse = bl.departure_section_occupied()
            if pulse:
                send(bl.id, pulse)
                event("block", f"block line {bl.id}: train departed, line blocked")
        elif bl.state is BlockState.arriving:
            bl.arrival_complete()
            event("block", f"block line {bl.id}: train arrived complete; restore the block")

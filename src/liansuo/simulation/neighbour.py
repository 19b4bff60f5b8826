"""Virtual neighbour stations at the far end of 64D and station-block lines (the teaching base's 虚拟邻站).

On a 64D line a neighbour accepts our block request after the line signal's duration, and once our train has left the
departure section (it reached them) it restores the line. Instructors and scripts drive the rest by hand
(``neighbour LINK request|depart|restore|accident``). On a station-block line (自动站间闭塞) the block needs no
answer; the neighbour's own departures are given by hand (``neighbour LINK block|cancel``), and it sees the line's
axle counters as we do.
"""

from __future__ import annotations

from collections.abc import Callable
from dataclasses import dataclass, field

from liansuo.interlocking.io import RelayBoard
from liansuo.stations.station import Station


@dataclass
class Neighbour:
    auto: bool = True
    outbox: list[tuple[float, str]] = field(default_factory=list)  # (send at, pulse)
    our_train_out: bool = False
    accepted: bool = False  # it has accepted our train and the train has not left yet (its block machine's view)


@dataclass
class StationNeighbour:
    """The neighbour's end of a station-block line: who has blocked it."""

    ours: bool = False  # we blocked it for our train (its block machine shows 接车)
    its: bool = False  # it blocked it for its own train towards us (发车)
    seen_occupied: bool = False  # the line has shown occupied since it was blocked


class Neighbours:
    def __init__(self, station: Station, pulse_s: float) -> None:
        self.pulse_s = pulse_s
        self.by_link = {lk.id: Neighbour() for lk in station.model.links if lk.kind.value == "64d"}
        self.station_lines = {lk.id: StationNeighbour() for lk in station.model.links if lk.kind.value == "station"}
        self.line_sections = {lk.id: tuple(lk.sections) for lk in station.model.links}
        self.outbox: list[tuple[float, str, str]] = []  # station-block pulses (send at, link, pulse)
        self.section = {lk.id: (lk.sections[0] if lk.sections else "") for lk in station.model.links}
        self.t = 0.0

    def send(self, link: str, pulse: str) -> None:
        self.by_link[link].outbox.append((self.t, pulse))

    def refuses(self, link: str, action: str) -> str:
        """Why the neighbour's block machine cannot do ``action`` now ('' when it can): a 64D machine asks to send
        a train only from its normal state, never while it has accepted ours or ours is on the line."""
        nb = self.by_link[link]
        if action == "request" and (nb.accepted or nb.our_train_out):
            what = "has accepted our train" if nb.accepted else "has our train on the line"
            return (f"the neighbour on {link} {what}: its block machine asks to send a train only once the line is "
                    "restored")
        return ""

    def permits(self, link: str) -> bool:
        """64D: the neighbour has accepted our train on ``link`` and it has not departed yet. Station block: the
        neighbour has not blocked the line for a train of its own."""
        sn = self.station_lines.get(link)
        if sn is not None:
            return not sn.its
        nb = self.by_link.get(link)
        return nb is not None and nb.accepted

    def station_action(self, link: str, action: str, clear: Callable[[str], bool]) -> str:
        """The neighbour's departure on a station-block line: ``block`` (its departure route is set; the block takes
        effect when the line signal reaches us) or ``cancel``; '' when sent, else why its block machine would not."""
        sn = self.station_lines[link]
        pending = any(x[1] == link and x[2] == "block" for x in self.outbox)
        if action == "block":
            if sn.ours or sn.its or pending:
                return f"line {link} is already blocked ({'for our train' if sn.ours else 'by the neighbour'})"
            if not all(clear(s) for s in self.line_sections[link]):
                return f"the neighbour sees line {link} occupied (axle counter): no block"
        elif action == "cancel":
            if pending:
                self.outbox = [x for x in self.outbox if x[1] != link]
                return ""
            if not sn.its:
                return f"the neighbour has not blocked line {link}"
            if sn.seen_occupied:
                return f"the neighbour's train is on line {link}: the block restores when it arrives"
        else:
            return "neighbour LINK block|cancel on a station-block line"
        self.outbox.append((self.t + self.pulse_s, link, action))
        return ""

    def step(self, t: float, line_out: dict[str, set[str]], clear: Callable[[str], bool]) -> None:
        self.t = t
        for link, pulses in line_out.items():
            nb = self.by_link.get(link)
            if nb is None:
                continue
            for p in pulses:
                if p == "request" and nb.auto:
                    nb.outbox.append((t + self.pulse_s, "accept"))
                elif p == "depart":
                    nb.our_train_out = True
                    nb.accepted = False
                elif p in ("restore", "accident"):
                    nb.accepted = False
                    nb.outbox = [(at, q) for at, q in nb.outbox if q != "accept"]
        for link, sn in self.station_lines.items():
            for p in line_out.get(link, ()):
                if p == "block":  # ours went first: a block of its own not yet sent is dropped
                    sn.ours, sn.seen_occupied = True, False
                    self.outbox = [x for x in self.outbox if not (x[1] == link and x[2] == "block")]
                elif p == "cancel":
                    sn.ours = False
                elif p == "restore":
                    sn.its = False
            line_clear = all(clear(s) for s in self.line_sections[link])
            if (sn.ours or sn.its) and not line_clear:
                sn.seen_occupied = True
            elif sn.ours and sn.seen_occupied and line_clear:
                sn.ours = False  # our train arrived here complete: the block restores by itself
        line_out.clear()
        for link, nb in self.by_link.items():
            if nb.our_train_out and nb.auto and clear(self.section[link]):
                nb.our_train_out = False
                nb.outbox.append((t + self.pulse_s, "restore"))

    def rests(self, line_out: dict[str, set[str]], clear: Callable[[str], bool]) -> bool:
        """A step with these pulses sent out (and none of the neighbours' falling due: :meth:`next_due`) would change
        nothing but the clock."""
        if line_out:
            return False
        for link, sn in self.station_lines.items():
            line_clear = all(clear(s) for s in self.line_sections[link])
            if ((sn.ours or sn.its) and not line_clear and not sn.seen_occupied) or \
                    (sn.ours and sn.seen_occupied and line_clear):
                return False
        return not any(nb.our_train_out and nb.auto and clear(self.section[link]) for link, nb in self.by_link.items())

    def next_due(self) -> float | None:
        """When the first pulse waiting to be sent falls due (None: none waits)."""
        times = [at for at, _, _ in self.outbox] + [at for nb in self.by_link.values() for at, _ in nb.outbox]
        return min(times) if times else None

    def publish(self, board: RelayBoard) -> None:
        sent = [(link, p) for at, link, p in self.outbox if at <= self.t]
        if sent:
            self.outbox = [x for x in self.outbox if x[0] > self.t]
            for link, p in sent:
                board.pulse(link, p)
                sn = self.station_lines[link]
                if p == "block":
                    sn.its, sn.seen_occupied = True, False
                elif p == "cancel":
                    sn.its = False
        for link, nb in self.by_link.items():
            due = [p for at, p in nb.outbox if at <= self.t]
            if due:
                nb.outbox = [(at, p) for at, p in nb.outbox if at > self.t]
                for p in due:
                    board.pulse(link, p)
                    if p == "accept":
                        nb.accepted = True
                    elif p in ("restore", "accident", "request"):
                        nb.accepted = False

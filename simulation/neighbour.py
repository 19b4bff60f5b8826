"""Virtual neighbour stations at the far end of 64D block lines (the teaching base's 虚拟邻站).

A neighbour accepts our block request after the line signal's duration, and once our train has left the departure
section (it reached them) it restores the line. Instructors and scripts drive the rest by hand
(``neighbour LINK request|depart|restore|accident``).
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


class Neighbours:
    def __init__(self, station: Station, pulse_s: float) -> None:
        self.pulse_s = pulse_s
        self.by_link = {lk.id: Neighbour() for lk in station.model.links if lk.kind.value == "64d"}
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
        """The neighbour has accepted our train on ``link`` and it has not departed yet."""
        nb = self.by_link.get(link)
        return nb is not None and nb.accepted

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
        line_out.clear()
        for link, nb in self.by_link.items():
            if nb.our_train_out and nb.auto and clear(self.section[link]):
                nb.our_train_out = False
                nb.outbox.append((t + self.pulse_s, "restore"))

    def publish(self, board: RelayBoard) -> None:
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

"""The most permissive aspect a path allows, stated from the published rules, not from the interlocking's code.

The Technical Regulations (铁路技术管理规程, 2014) give the meaning of each aspect; read as a ceiling on the path a
movement is about to run:

- a signal whose path runs over a turnout in its reverse position (diverging) shows at most two yellows (UU); the
  flashing yellow over yellow (USU) only when every diverging turnout of the path is No. 18 or larger (the rule
  set's ``usu_min_turnout_number``), the signal has a flasher, and the next signal is open over a path that is
  straight or diverges over No. 18 or larger turnouts only. Only home and route signals tell the diverging route:
  a starting signal's aspect counts the block sections ahead, whatever its path;
- on a straight path a signal shows at most what the next signal allows: green (L) when the next shows green,
  green-yellow or the flashing yellow; green-yellow (LU) when it shows yellow; yellow (U) when it is at stop, shows
  the guide aspect or two yellows. A dark signal ahead (its red lamp out, 红灯转移) allows nothing;
- a path that runs out onto a block line: a semi-automatic (64D) line allows the departure aspect of the rule set
  only once the neighbour station has accepted the train; an automatic line allows L with three clear block
  sections ahead, LU with two, U with one; a line worked against its running direction after a direction change
  (改方) is one block: L when all of it is clear;
- a shunting path allows the moon-white B, whatever lies ahead.
"""

from __future__ import annotations

from dataclasses import dataclass

from liansuo.stations.schema import SignalKind
from liansuo.stations.station import Station

from .authority import Authority
from .lamps import DARK, RANK, TRAIN_PROCEED, UNDEFINED
from .view import FieldView

STOP = "H"
_GREEN = frozenset({"L", "LL", "LU"})


@dataclass(frozen=True)
class Limit:
    aspect: str  # the most permissive aspect allowed
    why: str


def permits(limit: str, shown: str) -> bool:
    """Is ``shown`` no more permissive than ``limit``? Where the path diverges, only a diverging aspect (or stop, or
    the guide aspect) is allowed: a green or a lone yellow would tell the driver the way is straight."""
    if shown == limit:
        return True
    if limit in ("USU", "UU") and (shown in _GREEN or shown == "U"):
        return False
    return RANK.get(shown, 0) < RANK.get(limit, 0)


def follow(ahead: str, signal_ahead: str) -> Limit:
    if ahead in (DARK, UNDEFINED):
        return Limit(STOP, f"signal {signal_ahead} ahead is dark")
    if ahead in ("L", "LL", "LU", "USU"):
        return Limit("L", f"{signal_ahead} ahead shows {ahead}")
    if ahead == "U":
        return Limit("LU", f"{signal_ahead} ahead shows U")
    return Limit("U", f"{signal_ahead} ahead shows {ahead}")


class Ceiling:
    def __init__(self, station: Station, usu_min_number: int, semi_auto_departure: str) -> None:
        self.st = station
        self.usu_min = usu_min_number
        self.semi_auto = semi_auto_departure
        self.links = {lk.id: lk for lk in station.model.links}

    def of(self, a: Authority, view: FieldView, ahead: str, ahead_path: Authority | None) -> Limit:
        """The ceiling for authority ``a``; ``ahead`` is the aspect its end signal shows (as read from its lamps)
        and ``ahead_path`` that signal's own authority when it is open."""
        if a.kind == "shunt":
            return Limit("B", "shunting")
        if a.end in ("broken", "loop"):
            return Limit(STOP, "the path cannot be traced")
        sig = self.st.signals[a.signal]
        if sig.kind in (SignalKind.home, SignalKind.route):
            reverse = [t for t, pos in a.turnouts.items() if pos == "reverse"]
            if reverse:
                return self._diverging(a, reverse, ahead, ahead_path)
        if a.end == "signal" and a.end_signal is not None:
            return follow(ahead, a.end_signal)
        if a.end == "boundary" and a.link is not None and sig.kind is not SignalKind.block:
            return self._line(a, view)
        if a.end == "buffer":
            return Limit("U", "the path ends at a buffer stop")
        return Limit("L", "the path leaves the station model with no block line to judge")

    def _diverging(self, a: Authority, reverse: list[str], ahead: str, ahead_path: Authority | None) -> Limit:
        small = [t for t in reverse if self.st.turnouts[t].number < self.usu_min]
        if small:
            return Limit("UU", f"diverging over turnout {small[0]} (No. {self.st.turnouts[small[0]].number})")
        if not self.st.signals[a.signal].usu:
            return Limit("UU", f"diverging; {a.signal} has no flashing yellow")
        if ahead not in TRAIN_PROCEED or ahead_path is None:
            return Limit("UU", f"diverging; the next signal {a.end_signal or '-'} is not open")
        onward = [t for t, pos in ahead_path.turnouts.items()
                  if pos == "reverse" and self.st.turnouts[t].number < self.usu_min]
        if onward:
            return Limit("UU", f"the next signal {a.end_signal} is open over turnout {onward[0]} reversed "
                               f"(No. {self.st.turnouts[onward[0]].number})")
        return Limit("USU", f"diverging over No. {self.usu_min}+ turnouts, {a.end_signal} open straight or over "
                            f"No. {self.usu_min}+")

    def _line(self, a: Authority, view: FieldView) -> Limit:
        assert a.link is not None
        lk = self.links[a.link]
        if lk.kind.value == "64d":
            if view.line_permits(lk.id):
                return Limit(self.semi_auto, f"64D line {lk.id} accepted by the neighbour")
            return Limit(STOP, f"64D line {lk.id} has not been accepted by the neighbour station")
        clear = 0
        for s in lk.sections:
            if not view.clear(s):
                break
            clear += 1
        if self.st.link_running(lk.id) == "inbound":
            if not view.line_outbound(lk.id):
                return Limit(STOP, f"line {lk.id} runs towards this station: a departure onto it needs a direction "
                                   "change (改方)")
            if clear < len(lk.sections):
                return Limit(STOP, f"line {lk.id} worked against its running direction is one block, not all clear")
            return Limit("L", f"line {lk.id} set for departures and clear")
        aspect = {0: STOP, 1: "U", 2: "LU"}.get(clear, "L")
        return Limit(aspect, f"{clear} clear block section(s) on line {lk.id}")


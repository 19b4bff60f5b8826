"""The most permissive aspect a path allows, stated from the published rules, not from the interlocking's code.

The Technical Regulations (铁路技术管理规程, 2014) give the meaning of each aspect; read as a ceiling on the path a
movement is about to run:

- a signal whose path runs over a turnout in its reverse position (diverging) shows at most two yellows (UU); the
  flashing yellow over yellow (USU) only when every diverging turnout of the path is No. 18 or larger (the rule
  set's ``usu_min_diverging_kmh``), the signal has a flasher, and the next signal is open over a path that is
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

The codes above are those of the Chinese rule set. The code reads every aspect by its role from the rule set's data
(``aspects.yaml``: ``diverging``, ``rear``, ``automatic_block``, ``rank`` ...), never by its code, and shares none
of the interlocking's aspect selection.
"""

from __future__ import annotations

from dataclasses import dataclass

from liansuo.proving.oracle.authority import Authority
from liansuo.proving.oracle.lamps import DARK, UNDEFINED
from liansuo.proving.oracle.view import FieldView
from liansuo.rules import Aspects, RuleSet
from liansuo.stations.schema import SignalKind
from liansuo.stations.station import Station


@dataclass(frozen=True)
class AspectLimit:
    aspect: str  # the most permissive aspect allowed
    why: str


def permits(limit: str, shown: str, aspects: Aspects) -> bool:
    """Is ``shown`` no more permissive than ``limit``? Where the path diverges, only a diverging aspect (or stop, or
    the guide aspect) is allowed: a green or a lone yellow would tell the driver the way is straight."""
    if shown == limit:
        return True
    if limit in aspects.diverging and shown in aspects.train_proceed and shown not in aspects.diverging:
        return False
    return aspects.rank_of(shown) < aspects.rank_of(limit)


def follow(ahead: str, signal_ahead: str, aspects: Aspects) -> AspectLimit:
    if ahead in (DARK, UNDEFINED):
        return AspectLimit(aspects.stop, f"signal {signal_ahead} ahead is dark")
    most = aspects.rear.get(ahead, aspects.caution)
    return AspectLimit(most, f"{signal_ahead} ahead shows {ahead}")


class Ceiling:
    def __init__(self, station: Station, rules: RuleSet) -> None:
        self.st = station
        self.a = rules.aspects
        self.usu_min = rules.usu_min_diverging_kmh
        # the speed each turnout allows over its diverging track: the station file's figure, else the rule set's
        # typical figure for its number (the largest number listed not above it)
        table = sorted(rules.design.diverging_speed_kmh.items(), reverse=True)
        self.speed = {t.id: t.diverging_speed_kmh if t.diverging_speed_kmh is not None else
                      next((v for n, v in table if n <= t.number), table[-1][1]) for t in station.model.turnouts}
        self.semi_auto = rules.aspects.semi_auto_departure
        self.links = {lk.id: lk for lk in station.model.links}
        # diverging: the steady aspect (two yellows), and the flashing one over No. 18+ turnouts where it may show
        self.diverging = next(d for d in self.a.diverging if d not in self.a.flashing)
        self.diverging_flashing = next((d for d in self.a.diverging if d in self.a.flashing), self.diverging)

    def of(self, a: Authority, view: FieldView, ahead: str, ahead_path: Authority | None) -> AspectLimit:
        """The ceiling for authority ``a``; ``ahead`` is the aspect its end signal shows (as read from its lamps)
        and ``ahead_path`` that signal's own authority when it is open."""
        if a.kind == "shunt":
            return AspectLimit(self.a.shunt, "shunting")
        if a.end in ("broken", "loop"):
            return AspectLimit(self.a.stop, "the path cannot be traced")
        sig = self.st.signals[a.signal]
        if sig.kind in (SignalKind.home, SignalKind.route):
            reverse = [t for t, pos in a.turnouts.items() if pos == "reverse"]
            if reverse:
                return self._diverging(a, reverse, ahead, ahead_path)
        if a.end == "signal" and a.end_signal is not None:
            return follow(ahead, a.end_signal, self.a)
        if a.end == "boundary" and a.link is not None and sig.kind is not SignalKind.block:
            return self._line(a, view)
        if a.end == "buffer":
            return AspectLimit(self.a.caution, "the path ends at a buffer stop")
        return AspectLimit(self.a.clear, "the path leaves the station model with no block line to judge")

    def _diverging(self, a: Authority, reverse: list[str], ahead: str, ahead_path: Authority | None) -> AspectLimit:
        most, flashing = self.diverging, self.diverging_flashing
        small = [t for t in reverse if self.speed[t] < self.usu_min]
        if small:
            return AspectLimit(most, f"diverging over turnout {small[0]} ({self.speed[small[0]]:g} km/h)")
        if not self.st.signals[a.signal].usu:
            return AspectLimit(most, f"diverging; {a.signal} has no flashing yellow")
        if ahead not in self.a.train_proceed or ahead_path is None:
            return AspectLimit(most, f"diverging; the next signal {a.end_signal or '-'} is not open")
        onward = [t for t, pos in ahead_path.turnouts.items()
                  if pos == "reverse" and self.speed[t] < self.usu_min]
        if onward:
            return AspectLimit(most, f"the next signal {a.end_signal} is open over turnout {onward[0]} reversed "
                               f"({self.speed[onward[0]]:g} km/h)")
        return AspectLimit(flashing, f"diverging over turnouts for {self.usu_min:g} km/h, {a.end_signal} open straight "
                               f"or over such turnouts")

    def _line(self, a: Authority, view: FieldView) -> AspectLimit:
        assert a.link is not None
        lk = self.links[a.link]
        if lk.kind.value == "64d":
            if view.line_permits(lk.id):
                return AspectLimit(self.semi_auto, f"64D line {lk.id} accepted by the neighbour")
            return AspectLimit(self.a.stop, f"64D line {lk.id} has not been accepted by the neighbour station")
        if lk.kind.value == "station":  # one block section to the neighbour, proven clear by its axle counters
            if not view.line_permits(lk.id):
                return AspectLimit(self.a.stop, f"station-block line {lk.id} is blocked by the neighbour for its train")
            occupied = [s for s in lk.sections if not view.clear(s)]
            if occupied:
                return AspectLimit(self.a.stop, f"station-block line {lk.id}: {occupied[0]} shows occupied")
            return AspectLimit(self.semi_auto, f"station-block line {lk.id} clear and not blocked by the neighbour")
        clear = 0
        for s in lk.sections:
            if not view.clear(s):
                break
            clear += 1
        if self.st.link_running(lk.id) == "inbound":
            if not view.line_outbound(lk.id):
                return AspectLimit(self.a.stop, f"line {lk.id} runs towards this station: a departure onto it needs a "
                                          "direction change (改方)")
            if clear < len(lk.sections):
                return AspectLimit(self.a.stop, f"line {lk.id} worked against its running direction is one block, "
                                                "not all clear")
            return AspectLimit(self.a.clear, f"line {lk.id} set for departures and clear")
        steps = self.a.automatic_block
        aspect = steps[min(clear, len(steps) - 1)]
        return AspectLimit(aspect, f"{clear} clear block section(s) on line {lk.id}")


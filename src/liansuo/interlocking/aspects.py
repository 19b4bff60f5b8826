"""Aspect selection (Chinese rules): pure functions of the route and the state of the signal ahead.

Codes: L green, LL two greens, LU green-yellow, U yellow, UU two yellows, USU flashing yellow over yellow,
H red, HB red + moon-white (guide), B moon-white (shunting proceed), A blue (shunting stop).
Nothing outside this module and the rule set's data (``rules/china/``) knows these aspects by their codes: the rest
of the code names them by role from the rule set (``rules.aspects.stop``, ``.guide``, ``.shunt`` ...).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

from liansuo.rules import RuleSet, load_rules
from liansuo.stations.schema import SignalKind, TurnoutPosition
from liansuo.stations.station import Station

if TYPE_CHECKING:
    from collections.abc import Callable, Iterable

    from liansuo.interlocking.table.route import Route, RouteTurnout

STOP = ("H", "A")
TRAIN_STOP = "H"
# An automatic block signal whose sections are clear, by the aspect of the signal ahead (anything else, or no signal
# ahead: L). A guide aspect (HB) ahead shows its red lamp: prepare to stop.
_BLOCK_FOLLOW = {"H": "U", "A": "U", "": "U", "HB": "U", "U": "LU", "UU": "U"}


def is_open(aspect: str) -> bool:
    return aspect not in STOP and aspect != ""


def stop_aspect(station: Station, signal: str) -> str:
    return "A" if station.signals[signal].kind is SignalKind.shunting else "H"


def block_aspect(ahead: str | None) -> str:
    """The aspect of an automatic block signal with its sections clear, by the aspect ``ahead`` (None: no signal)."""
    return "L" if ahead is None else _BLOCK_FOLLOW.get(ahead, "L")


def at_stop_or_dark(aspect: str | None) -> bool:
    """A train signal at stop, or dark: with its red lamp out, the block signal in rear shows stop (红灯转移)."""
    return aspect in (TRAIN_STOP, "")


def usu_allowed(station: Station, route: Route, rules: RuleSet) -> bool:
    sig = station.signals[route.signal]
    reverse = [t.id for t in route.turnouts if t.role == "route" and t.position is TurnoutPosition.reverse]
    return sig.usu and bool(reverse) and all(_usu_turnout(station, t, rules) for t in reverse)


def _usu_turnout(station: Station, turnout: str, rules: RuleSet) -> bool:
    """Its diverging track allows the USU speed (No. 18 and larger, or the file's own ``diverging_speed_kmh``)."""
    return station.diverging_speed_kmh(turnout, rules.design) >= rules.usu_min_diverging_kmh


def onward_allows_usu(station: Station, turnouts: Iterable[RouteTurnout], rules: RuleSet) -> bool:
    """The onward route (of the next signal) runs straight, or diverges over No. 18 or larger turnouts only (技规)."""
    return all(_usu_turnout(station, t.id, rules) for t in turnouts
               if t.role == "route" and t.position is TurnoutPosition.reverse)


def follow(next_aspect: str) -> str:
    """The aspect of a signal whose route runs straight, by the aspect of the next signal ('' when there is none)."""
    if next_aspect == "UU":
        return "U"
    if next_aspect in ("L", "LL", "LU", "USU"):
        return "L"
    if next_aspect == "U":
        return "LU"
    return "U"


def possible_aspects(station: Station, route: Route, rules: RuleSet | None = None,
                     onward: Iterable[Route] = (), onward_aspects: Callable[[Route], tuple[str, ...]] | None = None
                     ) -> tuple[str, ...]:
    """What the table lists: every proceed aspect the route's signal can show for it (``onward``: the train routes
    from its end signal; ``onward_aspects``: what the table lists for one of them). A straight route follows the next
    signal, so it lists only what follows from an aspect that signal can show, or from its stop."""
    rules = rules or load_rules()
    if route.kind == "shunt":
        return ("B",)
    diverging = any(t.role == "route" and t.position is TurnoutPosition.reverse for t in route.turnouts)
    if route.category == "departure":
        link = next((lk for lk in station.model.links if lk.id == route.exit_link), None)
        if link is not None and link.kind.value in ("64d", "station"):
            return (rules.semi_auto_departure,)  # no block signals: the whole line is clear, or the signal at stop
        if link is not None and station.link_running(link.id) == "inbound":
            return ("L",)  # against the running direction, after 改方: the whole line is one block
        return ("L", "LU", "U")
    if diverging:
        usu = usu_allowed(station, route, rules) and any(onward_allows_usu(station, o.turnouts, rules)
                                                         for o in onward)
        return ("UU", "USU") if usu else ("UU",)
    if onward_aspects is None or route.end_signal is None:
        return ("L", "LU", "U")
    nexts = {TRAIN_STOP, *(a for o in onward for a in onward_aspects(o))}
    shown = {follow(a) for a in nexts}
    return tuple(a for a in ("L", "LU", "U") if a in shown)


def select_aspect(station: Station, route: Route, next_aspect: str, clear_blocks: int | None,
                  usu_ready: bool, rules: RuleSet | None = None) -> str:
    """The aspect to show for an open route.

    ``next_aspect``: the aspect of the signal at the end of the route ('' if none).
    ``clear_blocks``: clear automatic block sections ahead of a departure (None on 64D and station-block lines).
    ``usu_ready``: the onward route is open, straight or over No. 18+ turnouts, and the flasher is healthy.
    """
    rules = rules or load_rules()
    if route.kind == "shunt":
        return "B"
    diverging = any(t.role == "route" and t.position is TurnoutPosition.reverse for t in route.turnouts)
    if route.category == "departure":
        if clear_blocks is None:
            return rules.semi_auto_departure
        if clear_blocks >= 3:
            return "L"
        if clear_blocks == 2:
            return "LU"
        if clear_blocks == 1:
            return "U"
        return "H"
    if diverging:
        if usu_allowed(station, route, rules) and usu_ready and next_aspect in ("L", "LU", "LL", "USU"):
            return "USU"
        return "UU"
    return follow(next_aspect)  # straight over the main line: follow the next signal


def downgrade(aspect: str, dark: set[str], rules: RuleSet | None = None) -> str:
    """The aspect actually commanded when lamps (or 'flasher') in ``dark`` are not proven; never more permissive."""
    rules = rules or load_rules()
    seen = set()
    while aspect not in seen:
        seen.add(aspect)
        table = rules.downgrade.get(aspect, {})
        hit = next((table[d] for d in sorted(dark) if d in table), None)
        if hit is None:
            return aspect
        aspect = hit
    return aspect

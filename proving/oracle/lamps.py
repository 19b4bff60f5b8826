"""What a driver sees: the aspect a signal shows, read from the lamps actually lit.

The reading goes by colour, as a driver reads a signal: one yellow is U whichever yellow lamp it is, two yellows are
UU (USU when the upper one flashes), red with moon-white is the guide aspect HB. Which lamps each aspect lights is
national rule data (``lamps`` in the rule set); the oracle inverts that table by colour, so a lamp combination no
rule defines reads as undefined, never as a proceed aspect.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Mapping

DARK = ""  # nothing lit: a driver takes it as stop
UNDEFINED = "?"  # a combination of lamps no aspect of the rule set lights

_COLOUR = {"L": "green", "U": "yellow", "H": "red", "B": "white", "A": "blue"}

# How permissive an aspect is, as the Technical Regulations order them: proceed at line speed (green), proceed and
# expect the next signal at caution (green-yellow, or the flashing yellow over a No. 18 diverging route), diverging
# prepare to stop (two yellows), prepare to stop (yellow), guide or shunting proceed, stop.
RANK = {"L": 6, "LL": 6, "LU": 5, "USU": 5, "UU": 4, "U": 3, "HB": 2, "B": 2, "H": 0, "A": 0, DARK: 0, UNDEFINED: 0}
TRAIN_PROCEED = frozenset({"L", "LL", "LU", "USU", "UU", "U"})


def colours(lamps: Iterable[str]) -> frozenset[tuple[str, int]]:
    """The colours lit, with how many lamps of each: ``{'U', 'U2'}`` -> {('yellow', 2)}."""
    return frozenset(Counter(_COLOUR[lamp[0]] for lamp in lamps).items())


class LampReader:
    """Reads aspects by colour from a rule set's table of lamps per aspect."""

    def __init__(self, lamps_per_aspect: Mapping[str, Iterable[str]]) -> None:
        self._seen: dict[tuple[frozenset[str], bool], str] = {}
        self.by_colours: dict[frozenset[tuple[str, int]], str] = {}
        self.flashing: dict[frozenset[tuple[str, int]], str] = {}
        for aspect, lamps in lamps_per_aspect.items():
            key = colours(lamps)
            if aspect == "USU":
                self.flashing[key] = aspect
            else:
                self.by_colours.setdefault(key, aspect)

    def read(self, lit: frozenset[str], flashing: bool = False) -> str:
        """The aspect shown by the lamps ``lit``; ``flashing``: the flashing lamp of USU is actually flashing."""
        hit = self._seen.get((lit, flashing))
        if hit is None:
            hit = DARK
            if lit:
                key = colours(lit)
                hit = self.flashing[key] if flashing and key in self.flashing else self.by_colours.get(key, UNDEFINED)
            self._seen[(lit, flashing)] = hit
        return hit


def is_proceed(aspect: str) -> bool:
    return RANK.get(aspect, 0) > 0

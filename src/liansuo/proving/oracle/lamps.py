"""What a driver sees: the aspect a signal shows, read from the lamps actually lit.

The reading goes by colour, as a driver reads a signal (by the Chinese rules: one yellow is U whichever yellow lamp it
is, two yellows are UU, USU when the upper one flashes, red with moon-white is the guide aspect HB). Which lamps each
aspect lights, their colours and which aspects flash are national rule data (``aspects.yaml`` of the rule set); the
oracle inverts that table by colour, so a lamp combination no rule defines reads as undefined, never as a proceed
aspect. How permissive an aspect is, is rule data too (``rank``): ``Aspects.is_proceed``.
"""

from __future__ import annotations

from collections import Counter
from collections.abc import Iterable, Mapping

from liansuo.rules import DARK, Aspects

UNDEFINED = "?"  # a combination of lamps no aspect of the rule set lights

__all__ = ["DARK", "UNDEFINED", "LampReader", "colours"]


def colours(lamps: Iterable[str], colour_of: Mapping[str, str]) -> frozenset[tuple[str, int]]:
    """The colours lit, with how many lamps of each: ``{'U', 'U2'}`` -> {('yellow', 2)} by the Chinese rules."""
    return frozenset(Counter(colour_of[lamp] for lamp in lamps).items())


class LampReader:
    """Reads aspects by colour from a rule set's table of lamps per aspect."""

    def __init__(self, aspects: Aspects) -> None:
        self.aspects = aspects
        self._seen: dict[tuple[frozenset[str], bool], str] = {}
        self.by_colours: dict[frozenset[tuple[str, int]], str] = {}
        self.flashing: dict[frozenset[tuple[str, int]], str] = {}
        for aspect, lamps in aspects.lamps.items():
            key = colours(lamps, aspects.colours)
            if aspect in aspects.flashing:
                self.flashing[key] = aspect
            else:
                self.by_colours.setdefault(key, aspect)

    def read(self, lit: frozenset[str], flashing: bool = False) -> str:
        """The aspect shown by the lamps ``lit``; ``flashing``: the signal's flashing lamp is actually flashing."""
        hit = self._seen.get((lit, flashing))
        if hit is None:
            hit = DARK
            if lit:
                key = colours(lit, self.aspects.colours)
                hit = self.flashing[key] if flashing and key in self.flashing else self.by_colours.get(key, UNDEFINED)
            self._seen[(lit, flashing)] = hit
        return hit

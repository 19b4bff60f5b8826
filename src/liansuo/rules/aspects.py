"""The aspects of a rule set (``aspects.yaml``): their lamps, their roles, how permissive each is.

Code outside the rule set names an aspect by its role here (``aspects.stop``, ``aspects.guide``, ``aspects.shunt``,
``aspects.flashing`` ...) and a lamp by its colour (``aspects.colours``), never by a national code such as "H".
"""

from __future__ import annotations

from collections.abc import Iterable
from typing import Annotated

from pydantic import BaseModel, ConfigDict, Field, PrivateAttr

from liansuo.rules.reader import Loc

DARK = ""  # what the interlocking and the field call a signal with no aspect: nothing lit, taken as stop

Aspect = Annotated[str, Field(min_length=1)]


class Aspects(BaseModel):
    """Every aspect a rule set knows, with what it lights and what it means."""

    model_config = ConfigDict(extra="forbid", frozen=True, allow_inf_nan=False)  # every number finite

    colours: dict[str, str]  # lamp -> colour, in the order the lamps stand on the mast from the joint outwards
    stop: Aspect  # a train signal at stop
    shunt_stop: Aspect  # a shunting signal at stop
    guide: Aspect  # the guide aspect
    shunt: Aspect  # shunting allowed
    clear: Aspect  # proceed at line speed
    caution: Aspect  # proceed, prepare to stop at the next signal
    diverging: list[Aspect]  # the aspects that tell a diverging route
    flashing: list[Aspect]  # aspects shown with the signal's flasher energised
    flasher_lamp: str  # the lamp the flasher makes flash
    rank: dict[str, Annotated[int, Field(ge=0, le=1000)]]  # how permissive (0: stop)
    rear: dict[str, str]  # straight path: the most a signal shows in rear of one showing this (else: caution)
    automatic_block: list[Aspect] = Field(min_length=2)  # departure aspect by clear block sections ahead
    semi_auto_departure: Aspect  # departure onto a semi-automatic (64D) line accepted by the neighbour
    lamps: dict[str, list[str]]  # aspect -> the lamps it lights
    downgrade: dict[str, dict[str, str]]  # aspect -> {dark lamp (or 'flasher'): the aspect shown instead}
    cab_codes: dict[str, str | None]  # aspect of the signal ahead -> the low-frequency cab code

    _closed: frozenset[str] = PrivateAttr(default=frozenset())
    _train_proceed: frozenset[str] = PrivateAttr(default=frozenset())
    _by_rank: tuple[str, ...] = PrivateAttr(default=())

    def model_post_init(self, context: object, /) -> None:
        self._closed = frozenset(a for a, r in self.rank.items() if r == 0) | {DARK}
        self._train_proceed = frozenset(a for a, r in self.rank.items() if r > 0) - {self.guide, self.shunt}
        listed = list(self.lamps)
        self._by_rank = tuple(sorted(listed, key=lambda a: (-self.rank.get(a, 0), listed.index(a))))

    # ---- what the code asks ---------------------------------------------------------------------------------------
    @property
    def closed(self) -> frozenset[str]:
        """The aspects a movement must stop at: every stop aspect and a dark signal."""
        return self._closed

    @property
    def train_proceed(self) -> frozenset[str]:
        """The aspects that let a train movement pass at its speed: proceed, but neither guide nor shunting."""
        return self._train_proceed

    @property
    def by_rank(self) -> tuple[str, ...]:
        """Every aspect, most permissive first (aspects of one rank in the order the rule set lists them)."""
        return self._by_rank

    @property
    def stop_lamp(self) -> str:
        """The lamp a train signal lights at stop (the first, if its stop aspect lights several)."""
        return self.lamps[self.stop][0]

    def rank_of(self, aspect: str) -> int:
        """How permissive ``aspect`` is; dark and anything the rule set does not know rank as stop (0)."""
        return self.rank.get(aspect, 0)

    def is_proceed(self, aspect: str) -> bool:
        return self.rank_of(aspect) > 0

    def can_show(self, aspect: str, lamps: Iterable[str]) -> bool:
        """Has a signal with ``lamps`` every lamp ``aspect`` lights?"""
        return aspect in self.lamps and set(self.lamps[aspect]) <= set(lamps)

    def colour(self, lamp: str) -> str:
        return self.colours.get(lamp, "")

    # ---- checked when the rule set is loaded -------------------------------------------------------------------
    def problems(self) -> list[tuple[Loc, str]]:
        """What the file gets wrong beyond its schema: every aspect named must be one with lamps, every lamp one with
        a colour, and a downgrade must never be more permissive."""
        out: list[tuple[Loc, str]] = []
        known = set(self.lamps)

        def aspect(loc: Loc, name: str | None) -> None:
            if name is not None and name not in known:
                out.append((loc, f"'{name}' is no aspect of this rule set (the aspects are those under 'lamps:')"))

        for role in ("stop", "shunt_stop", "guide", "shunt", "clear", "caution", "semi_auto_departure"):
            aspect((role,), getattr(self, role))
        for key in ("diverging", "flashing", "automatic_block"):
            for i, name in enumerate(getattr(self, key)):
                aspect((key, i), name)
        for key in ("rank", "rear", "downgrade", "cab_codes"):
            for name in getattr(self, key):
                aspect((key, name), name)
        for name, ahead in self.rear.items():
            aspect(("rear", name), ahead)
        for name, lamps in self.lamps.items():
            out += [(("lamps", name, i), f"lamp '{lamp}' has no colour under 'colours:'")
                    for i, lamp in enumerate(lamps) if lamp not in self.colours]
            if name not in self.rank:
                out.append((("lamps", name), f"aspect '{name}' has no rank under 'rank:'"))
        for role in ("stop", "shunt_stop"):
            if self.rank.get(getattr(self, role), 0) != 0:
                out.append(((role,), f"the {role.replace('_', ' ')} aspect must rank 0"))
        if all(name in self.flashing for name in self.diverging):
            out.append((("diverging",), "a diverging route needs a steady aspect: list one that does not flash"))
        for name in self.flashing:
            if self.flasher_lamp not in self.lamps.get(name, [self.flasher_lamp]):
                out.append((("flasher_lamp",), f"flashing aspect '{name}' does not light '{self.flasher_lamp}'"))
        for name, table in self.downgrade.items():
            for lamp, instead in table.items():
                aspect(("downgrade", name, lamp), instead)
                if lamp != "flasher" and lamp not in self.colours:
                    out.append((("downgrade", name), f"'{lamp}' is neither a lamp under 'colours:' nor 'flasher'"))
                if instead in known and name in known and self.rank_of(instead) >= self.rank_of(name) > 0:
                    out.append((("downgrade", name, lamp), f"'{name}' with '{lamp}' dark shows '{instead}', which is "
                                "not more restrictive"))
        return out

"""The shunts on each section, worked out only as far as its track circuit needs them.

A shunt is a wheelset joining the two rails: ``(distance from the section's low end in metres, ohm)``. A moving
train's wheelsets stand somewhere else every cycle, but a healthy track circuit with a standard shunt on it is down
by design (:mod:`.trackcircuits`): it needs to know only that it is shunted. So the field is told, for each group of
wheelsets that moves together (a train, :class:`WheelsetGroup`), the sections it shunts, and the shunts themselves
are listed only where they matter: a section with a fault, an axle counter, wheelsets shunting through more than the
standard resistance, or someone reading a voltage. Loose wheelsets (placed by hand) are listed as they are.
"""

from __future__ import annotations

from collections.abc import Mapping
from typing import Protocol

Shunt = tuple[float, float]  # (distance from the section's low end, m; shunt resistance, ohm)


class WheelsetGroup(Protocol):
    """Wheelsets that move together (a train), where they stand at one moment: whoever moves them gives the field
    a new group whenever any of them moved, and the same object while none did."""

    @property
    def sections(self) -> frozenset[str]:
        """The sections where at least one of them shunts."""

    @property
    def max_ohm(self) -> float:
        """The highest shunt resistance of any of them."""

    def shunts(self, section: str) -> list[Shunt]:
        """Their shunts on ``section`` (none if it is not one of ``sections``), in the order of the wheelsets."""


class OnTrack:
    """Every wheelset standing on the track: loose ones already listed by section, and groups (trains) by name."""

    def __init__(self) -> None:
        self.loose: dict[str, list[Shunt]] = {}
        self.groups: dict[str, WheelsetGroup] = {}

    def listed(self, section: str) -> list[Shunt]:
        """The shunts on ``section``: the loose wheelsets' first, then each group's in the groups' order."""
        out = list(self.loose.get(section, ()))
        for g in self.groups.values():
            if section in g.sections:
                out.extend(g.shunts(section))
        return out

    def occupies(self, section: str) -> bool:
        """Some wheelset shunts ``section``."""
        return section in self.loose or any(section in g.sections for g in self.groups.values())

    def standard(self, section: str, limit_ohm: float) -> bool:
        """At least one wheelset on ``section`` shunts through at most ``limit_ohm``."""
        if any(r <= limit_ohm for _, r in self.loose.get(section, ())):
            return True
        for g in self.groups.values():
            if section in g.sections:
                if g.max_ohm <= limit_ohm:  # it has a wheelset there, and each of them is good enough
                    return True
                if any(r <= limit_ohm for _, r in g.shunts(section)):
                    return True
        return False


class Shunts:
    """The shunts on one section as its track circuit reads them."""

    def listed(self) -> list[Shunt]:
        """Every shunt on the section."""
        raise NotImplementedError

    def count(self) -> int:
        """How many wheelsets shunt the section (what an axle counter counts)."""
        return len(self.listed())

    def standard(self, limit_ohm: float) -> bool:
        """At least one wheelset shunts through at most ``limit_ohm``."""
        return any(r <= limit_ohm for _, r in self.listed())


class Listed(Shunts):
    """Shunts given as a list, kept as they were given."""

    __slots__ = ("_shunts",)

    def __init__(self, shunts: list[Shunt]) -> None:
        self._shunts = shunts

    def listed(self) -> list[Shunt]:
        return self._shunts


class SectionShunts(Shunts):
    """What stands on one section of the field now: a live view, always as the field was last told."""

    __slots__ = ("_on", "section")

    def __init__(self, on: OnTrack, section: str) -> None:
        self._on = on
        self.section = section

    def listed(self) -> list[Shunt]:
        return self._on.listed(self.section)

    def standard(self, limit_ohm: float) -> bool:
        return self._on.standard(self.section, limit_ohm)


def changed_sections(on: OnTrack, loose: dict[str, list[Shunt]], groups: Mapping[str, WheelsetGroup],
                     settled: set[str]) -> set[str]:
    """The sections whose shunts may differ between ``on`` and the new ``loose`` and ``groups``, leaving out those
    of ``settled`` (sections whose circuits need only know they are shunted by a standard shunt) where only the
    positions of a group's wheelsets changed, not the sections it shunts nor its resistance."""
    was_loose = on.loose
    out = {s for s in loose.keys() | was_loose.keys() if loose.get(s) != was_loose.get(s)} if loose or was_loose \
        else set()
    old = on.groups
    for name, g in groups.items():
        was = old.get(name)
        if was is g:
            continue  # it has not moved
        now = g.sections
        if was is None:
            out |= now
            continue
        then = was.sections
        if (then is now or then == now) and was.max_ohm == g.max_ohm:
            if not now <= settled:
                out.update(now - settled)
            continue
        out |= now
        out |= then
    for name, was in old.items():
        if name not in groups:
            out |= was.sections
    return out


__all__ = ["Listed", "OnTrack", "SectionShunts", "Shunt", "Shunts", "WheelsetGroup", "changed_sections"]

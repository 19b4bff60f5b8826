"""The error of a query that names an element the station does not have (``sim.aspect("NOSUCH")``).

Every id-taking query of the world and of its query API (:mod:`.view`) raises :class:`UnknownId` for an id the
station does not know, instead of answering with a default that looks like a state ('' for an aspect, 'released' for
a route, 'occupied' for a section). It derives from :class:`KeyError`, so ``except KeyError`` keeps working, and it
names the kind, the id and the nearest ids the station does have.
"""

from __future__ import annotations

from collections.abc import Collection
from difflib import get_close_matches


class UnknownId(KeyError):
    """No element of this kind and id at the station: ``kind`` (signal, route, section, turnout, train, line,
    platform door), ``id`` as asked, ``matches`` the station's closest ids (possibly none)."""

    def __init__(self, kind: str, id: str, matches: Collection[str] = (), station: str = "") -> None:
        super().__init__(kind, id)
        self.kind = kind
        self.id = id
        self.matches = tuple(matches)
        self.station = station

    def __str__(self) -> str:
        where = f"station {self.station} has" if self.station else "the station has"
        names = [repr(m) for m in self.matches]
        either = f"{', '.join(names[:-1])} or {names[-1]}" if len(names) > 1 else "".join(names)
        hint = f"; did you mean {either}?" if names else ""
        return f"{where} no {self.kind} {self.id!r}{hint}"


def close_matches(id: str, known: Collection[str], n: int = 3) -> list[str]:
    """The known ids closest to ``id``, ignoring case (``x`` finds ``X``), best first."""
    by_folded: dict[str, str] = {}
    for k in known:
        by_folded.setdefault(k.casefold(), k)
    return [by_folded[m] for m in get_close_matches(id.casefold(), list(by_folded), n=n, cutoff=0.6)]


def require(kind: str, id: str, known: Collection[str], station: str = "") -> None:
    """Raise :class:`UnknownId` unless ``id`` is one of ``known`` (a set or a mapping: the check is a lookup)."""
    if id not in known:
        raise UnknownId(kind, id, close_matches(id, known), station)

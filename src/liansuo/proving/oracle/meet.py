"""When two movement authorities may not stand together: they share a track element, or they lead head-on onto
one track in a way the national rule set names an enemy (敌对进路)."""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass, field

from liansuo.proving.oracle.authority import Authority


@dataclass
class Extent:
    """What one authority holds at a moment: all or, for a movement under way, what is still ahead of it."""

    name: str  # 'X', or 'X (in use)'
    auth: Authority
    sections: set[str]  # path and overlap
    path_sections: set[str]
    overlap: set[str]
    diamonds: set[str]
    fouling: set[str] = field(default_factory=set)  # sections that must stay clear beside the path
    needed: dict[str, tuple[str, str]] = field(default_factory=dict)  # turnout -> (position, role)

    @staticmethod
    def whole(auth: Authority, name: str | None = None, fouling: set[str] | None = None) -> Extent:
        return Extent(name or auth.signal, auth, set(auth.all_sections), set(auth.sections),
                      set(auth.overlap_sections), set(auth.diamonds), fouling or set())


def continues(first: Extent, then: Extent, section: str) -> bool:
    """``then`` continues ``first`` in the same direction from its end signal, and ``section`` is in ``first``'s
    overlap (a through movement: the overlap is the onward route's to use)."""
    return (first.auth.direction is then.auth.direction and then.auth.signal == first.auth.end_signal
            and section in first.overlap)


def shared(x: Extent, y: Extent) -> list[str]:
    """Track elements both hold, other than an overlap the other continues over."""
    out = [f"section {s}" for s in sorted(x.sections & y.sections)
           if not continues(x, y, s) and not continues(y, x, s)]
    out += [f"diamond {d}" for d in sorted(x.diamonds & y.diamonds)]
    out += [f"fouling section {s}" for s in sorted((x.fouling & y.path_sections) | (y.fouling & x.path_sections))]
    return out


def head_on(x: Extent, y: Extent, enemies: Iterable[frozenset[str]]) -> str | None:
    """The track ``x`` and ``y`` lead onto from opposite ends, when their kinds make them enemies there."""
    if x.auth.direction is y.auth.direction or frozenset({x.auth.kind, y.auth.kind}) not in set(enemies):
        return None
    for a, b in ((x, y), (y, x)):
        track = a.auth.leads_into
        if track is not None and (track in b.path_sections or b.auth.leads_into == track):
            return track
    return None

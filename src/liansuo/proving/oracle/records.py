"""The safety oracle's records: a finding, a movement under way on its authority, and an extent held with what the
last check found about its turnouts."""

from __future__ import annotations

from dataclasses import dataclass

from liansuo.proving.oracle.authority import Authority
from liansuo.proving.oracle.meet import Extent


@dataclass(frozen=True)
class Finding:
    key: str  # the same key is the same finding; it is reported once while it lasts
    prop: str  # shared, head-on, turnout, flank, clear, aspect, doors, reopened, moved, lamps, invisible
    text: str
    hazard: bool = False
    delayed: bool = False  # caused by the world: the interlocking has some cycles to answer


@dataclass
class InUse:
    """An authority whose signal has closed behind the movement that entered it."""

    auth: Authority
    seen: list[bool]  # each path section has been occupied
    pre: set[int]  # sections already occupied before the movement entered (a red band under a guide aspect)
    passed: int = 0  # sections[:passed] are behind the movement
    reached_at: float | None = None  # the last path section was first occupied (starts the overlap time)
    operator: bool = False  # it was a guided movement the operator answers for (guide total lock)
    guided: bool = False  # it entered on the guide aspect: at sight, with no overlap beyond its end

    @property
    def sections(self) -> list[str]:
        return self.auth.sections


@dataclass
class Held(Extent):
    """An extent with what this check found about its turnouts."""

    unsettled: bool = False  # a turnout of it is not where it should be (the world's doing, being answered)
    operator: bool = False  # a guide aspect over turnouts without indication: the operator answers for the route
    guided: bool = False  # a guide aspect: its track circuits are not checked, the operator has looked at the way
    in_use: bool = False  # a movement under way (its signal has closed behind it)
    guided_in: bool = False  # under way, entered on a guide aspect

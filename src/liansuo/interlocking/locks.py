"""The lock ledger (锁闭): every lock the interlocking holds on a section or a turnout, who holds it and why.

One question has one answer here: *is this turnout locked, by whom, why?* A turnout is locked when something locks
it directly (a route or an overlap that runs over it or protects it, single lock 单锁, guide total lock 引导总锁闭)
or when the section it stands in is locked by a route, an overlap or the power-up lock (上电锁闭): a turnout in a
route-locked section is locked with it. A fouling section (侵限区段) a route checks is held too, but holding it
locks no turnout: several routes may check the same fouling section.
"""

from __future__ import annotations

from collections.abc import Iterable
from dataclasses import dataclass
from enum import StrEnum


class Hold(StrEnum):
    route = "route"  # 进路锁闭: a route's section or turnout
    overlap = "overlap"  # 延续进路
    fouling = "fouling"  # a fouling section a route checks
    single = "single"  # 单锁
    guide = "guide"  # 引导总锁闭 of a throat
    power_up = "power-up"  # 上电锁闭: since the interlocking started, until the power-up release


_LOCKS_TURNOUTS = frozenset({Hold.route, Hold.overlap, Hold.power_up})
_HOLDS_ROUTES = frozenset({Hold.route, Hold.overlap})


@dataclass(frozen=True)
class Lock:
    hold: Hold
    holder: str = ""  # route id, throat name, or '' (single lock, power-up)

    def words(self) -> str:
        """How a section or turnout is locked, to follow 'is locked': 'in route X-XI', ..."""
        return {Hold.route: f"in route {self.holder}", Hold.overlap: f"in route {self.holder} (its overlap)",
                Hold.fouling: f"in route {self.holder} (a fouling section)", Hold.single: "by single lock (单锁)",
                Hold.guide: f"by guide total lock (引导总锁闭) of throat {self.holder}",
                Hold.power_up: "since the interlocking started (上电锁闭)"}[self.hold]


class LockLedger:
    """``pairs``: crossover pairs (双动道岔), whose two turnouts move together: a lock on one holds both."""

    def __init__(self, turnout_section: dict[str, str], pairs: dict[str, list[str]] | None = None) -> None:
        self.turnout_section = turnout_section
        self.partner: dict[str, str] = {}
        for members in (pairs or {}).values():
            for t in members:
                self.partner.update({m: t for m in members if m != t})
        self.sections: dict[str, set[Lock]] = {}
        self.turnouts: dict[str, set[Lock]] = {}
        self.blocked: set[str] = set()  # 单封: no route over the turnout (not a lock: individual operation stays)
        self.version = 0  # counts changes, so a reader can tell when nothing changed
        # each lock -> the sections and turnouts it is on, so that giving a holder's locks back looks only at those
        self._on: dict[Lock, tuple[set[str], set[str]]] = {}

    # ---- taking and giving back -----------------------------------------------------------------------------------
    def lock_section(self, section: str, hold: Hold, holder: str = "") -> None:
        self._take(self.sections, 0, section, Lock(hold, holder))

    def unlock_section(self, section: str, hold: Hold, holder: str = "") -> None:
        self._give(self.sections, 0, section, Lock(hold, holder))

    def lock_turnout(self, turnout: str, hold: Hold, holder: str = "") -> None:
        self._take(self.turnouts, 1, turnout, Lock(hold, holder))

    def unlock_turnout(self, turnout: str, hold: Hold, holder: str = "") -> None:
        self._give(self.turnouts, 1, turnout, Lock(hold, holder))

    def release(self, hold: Hold, holder: str = "") -> None:
        """Give back every lock ``holder`` holds as ``hold``."""
        self._release(Lock(hold, holder))

    def release_all(self, hold: Hold) -> None:
        self.version += 1
        for lock in [lk for lk in self._on if lk.hold is hold]:
            self._release(lock)

    def _take(self, table: dict[str, set[Lock]], kind: int, key: str, lock: Lock) -> None:
        self.version += 1
        table.setdefault(key, set()).add(lock)
        self._on.setdefault(lock, (set(), set()))[kind].add(key)

    def _give(self, table: dict[str, set[Lock]], kind: int, key: str, lock: Lock) -> None:
        self.version += 1
        locks = table.get(key)
        if locks is not None:
            locks.discard(lock)
            if not locks:
                del table[key]
        on = self._on.get(lock)
        if on is not None:
            on[kind].discard(key)
            if not on[0] and not on[1]:
                del self._on[lock]

    def _release(self, lock: Lock) -> None:
        self.version += 1
        on = self._on.pop(lock, None)
        if on is None:
            return
        for table, keys in zip((self.sections, self.turnouts), on, strict=True):
            for key in keys:
                table[key].discard(lock)
                if not table[key]:
                    del table[key]

    # ---- questions ----------------------------------------------------------------------------------------------
    def section_locks(self, section: str) -> list[Lock]:
        """The locks on ``section`` in a fixed order (by kind, then holder), so that what is said of the first is the
        same in every process (a set's order follows the string hashing of its process)."""
        return sorted(self.sections.get(section, ()), key=_order)

    def section_locked(self, section: str) -> bool:
        return section in self.sections

    def section_holders(self, section: str, holds: Iterable[Hold] = (Hold.route, Hold.overlap)) -> list[str]:
        want = set(holds)
        return sorted(lk.holder for lk in self.sections.get(section, ()) if lk.hold in want)

    def _own_locks(self, turnout: str) -> list[tuple[Lock, str]]:
        """Locks through the turnout's section first (they name the section), then those on the turnout itself."""
        out: list[tuple[Lock, str]] = []
        sec = self.turnout_section.get(turnout)
        if sec is not None:
            out += [(lk, sec) for lk in sorted(self.sections.get(sec, ()), key=_order) if lk.hold in _LOCKS_TURNOUTS]
        return out + [(lk, "") for lk in sorted(self.turnouts.get(turnout, ()), key=_order)]

    def turnout_locks(self, turnout: str) -> list[tuple[Lock, str, str]]:
        """Every lock holding ``turnout``: (lock, section it comes through or '', the crossover partner it comes
        through or '')."""
        out = [(lk, sec, "") for lk, sec in self._own_locks(turnout)]
        partner = self.partner.get(turnout)
        if partner is not None:
            out += [(lk, sec, partner) for lk, sec in self._own_locks(partner)]
        return out

    def turnout_locked(self, turnout: str) -> bool:
        """As ``bool(turnout_locks(turnout))``, without putting the locks in order."""
        partner = self.partner.get(turnout)
        return self._held(turnout) or (partner is not None and self._held(partner))

    def _held(self, turnout: str) -> bool:
        if self.turnouts.get(turnout):
            return True
        sec = self.turnout_section.get(turnout)
        return sec is not None and any(lk.hold in _LOCKS_TURNOUTS for lk in self.sections.get(sec, ()))

    def why_turnout(self, turnout: str) -> str:
        """Why ``turnout`` may not move, in a signaller's words ('' when it may)."""
        locks = self.turnout_locks(turnout)
        if not locks:
            return ""
        lk, via, partner = locks[0]
        who = f"turnout {turnout}" if not partner else f"turnout {turnout} moves with {partner}, which"
        if lk.hold is Hold.single:
            return f"{who} is single-locked (单锁): unlock it first"
        if not via:
            return f"{who} is locked {lk.words()}"
        if lk.hold is Hold.route and (lk, "", partner) in locks:
            return f"{who} is locked {lk.words()}: it stands in section {via}, locked in that route"
        return f"{who} stands in section {via}, locked {lk.words()}"

    def holders(self, turnout: str) -> set[str]:
        """Routes that hold ``turnout`` directly (by route or overlap lock)."""
        return {lk.holder for lk in self.turnouts.get(turnout, ()) if lk.hold in _HOLDS_ROUTES}

    def held_by(self, turnout: str, route: str) -> bool:
        """``route`` holds ``turnout`` directly (``route in holders(turnout)``)."""
        return any(lk.holder == route and lk.hold in _HOLDS_ROUTES for lk in self.turnouts.get(turnout, ()))


_RANK = {h: i for i, h in enumerate(Hold)}


def _order(lk: Lock) -> tuple[int, str]:
    return (_RANK[lk.hold], lk.holder)

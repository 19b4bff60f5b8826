"""The lock ledger gives back a holder's locks from an index of where each lock is; whatever is taken and given back,
its sections and turnouts are those of the plain rule (every table looked through, here in the test)."""

from __future__ import annotations

from collections.abc import Callable

from hypothesis import given, settings
from hypothesis import strategies as st

from liansuo.interlocking.locks import Hold, Lock, LockLedger

SECTIONS = ["1DG", "IG"]  # few names, so that the same lock is taken, given back and released again often
TURNOUTS = ["1"]
HOLDERS = ["X-XI", "S-SII"]

Op = tuple[str, str, Hold, str]
ops = st.lists(st.tuples(st.sampled_from(["lock_section", "unlock_section", "lock_turnout", "unlock_turnout",
                                          "release", "release_all"]),
                         st.sampled_from(SECTIONS + TURNOUTS), st.sampled_from([Hold.route, Hold.single]),
                         st.sampled_from(HOLDERS)), min_size=4, max_size=40)


class Plain:
    """The ledger's tables, kept the plain way."""

    def __init__(self) -> None:
        self.tables: tuple[dict[str, set[Lock]], dict[str, set[Lock]]] = ({}, {})

    def apply(self, op: Op) -> None:
        what, key, hold, holder = op
        lock = Lock(hold, holder)
        if what in ("lock_section", "lock_turnout"):
            self.tables[what == "lock_turnout"].setdefault(key, set()).add(lock)
        elif what in ("unlock_section", "unlock_turnout"):
            self._drop(self.tables[what == "unlock_turnout"], lambda lk, k: k == key and lk == lock)
        else:
            for table in self.tables:
                self._drop(table, (lambda lk, k: lk == lock) if what == "release" else (lambda lk, k: lk.hold is hold))

    @staticmethod
    def _drop(table: dict[str, set[Lock]], gone: Callable[[Lock, str], bool]) -> None:
        for k in list(table):
            table[k] = {lk for lk in table[k] if not gone(lk, k)}
            if not table[k]:
                del table[k]


@settings(max_examples=300, deadline=None, derandomize=True)
@given(ops)
def test_the_ledger_keeps_the_tables_of_the_plain_rule(steps: list[Op]) -> None:
    ledger, plain = LockLedger({t: SECTIONS[i] for i, t in enumerate(TURNOUTS)}), Plain()
    for op in steps:
        what, key, hold, holder = op
        version = ledger.version
        if what == "release":
            ledger.release(hold, holder)
        elif what == "release_all":
            ledger.release_all(hold)
        else:
            getattr(ledger, what)(key, hold, holder)
        plain.apply(op)
        assert (ledger.sections, ledger.turnouts) == plain.tables, op
        assert ledger.version > version  # every change is counted (the engine's memos compare it)


def test_a_route_released_leaves_the_others_locks() -> None:
    ledger = LockLedger({"1": "1DG"})
    ledger.lock_section("1DG", Hold.route, "X-XI")
    ledger.lock_section("1DG", Hold.route, "S-SII")
    ledger.lock_turnout("1", Hold.overlap, "X-XI")
    ledger.release(Hold.route, "X-XI")
    assert ledger.sections == {"1DG": {Lock(Hold.route, "S-SII")}}
    assert ledger.turnouts == {"1": {Lock(Hold.overlap, "X-XI")}}
    ledger.release(Hold.overlap, "X-XI")
    ledger.release(Hold.route, "S-SII")
    assert ledger.sections == {} and ledger.turnouts == {}


def test_a_sections_locks_come_in_the_same_order_however_they_were_taken() -> None:
    """What a refusal names first (the first lock) does not follow the order of taking, nor the process's hashing."""
    taken = [(Hold.overlap, "X-XI"), (Hold.route, "S-SII"), (Hold.fouling, "D1-D3"), (Hold.route, "D5-D7")]
    seen = []
    for order in (taken, taken[::-1], taken[1:] + taken[:1]):
        ledger = LockLedger({})
        for hold, holder in order:
            ledger.lock_section("1DG", hold, holder)
        seen.append(ledger.section_locks("1DG"))
    assert seen[0] == seen[1] == seen[2]
    assert [(lk.hold, lk.holder) for lk in seen[0]] == [(Hold.route, "D5-D7"), (Hold.route, "S-SII"),
                                                        (Hold.overlap, "X-XI"), (Hold.fouling, "D1-D3")]

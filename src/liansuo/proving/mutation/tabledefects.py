"""Seeded defects of the interlocking table: conflicts, diamonds, flank protection, run-ons, overlaps and
approach sections left out or cut short."""

from __future__ import annotations

from contextlib import ExitStack
from typing import Any

import liansuo.interlocking.core as core
import liansuo.interlocking.table.approach as approach
import liansuo.interlocking.table.conflicts as conflicts
import liansuo.interlocking.table.derive as derive
import liansuo.interlocking.table.flank as flank
import liansuo.interlocking.table.runon as runon
from liansuo.interlocking.state import RouteState
from liansuo.interlocking.table.route import Route
from liansuo.proving.mutation.patching import patch, wrap


# ---- ---------------------------------------------------------------------------------------------
def no_head_on(s: ExitStack) -> None:
    wrap(s, derive, "derive_conflicts",
          lambda real: lambda routes, rules, is_track: real(routes, rules.model_copy(update={"enemy_onto_track": []}),
                                                            is_track))


def no_diamonds(s: ExitStack) -> None:
    def build(real: Any) -> Any:
        def without(self: Any) -> Any:
            saved, self.st.crossings = self.st.crossings, {}
            try:
                return real(self)
            finally:
                self.st.crossings = saved
        return without
    wrap(s, derive._Builder, "build", build)


def no_protection(s: ExitStack) -> None:
    wrap(s, flank.Flank, "of", lambda real: lambda self, *a: ({}, real(self, *a)[1]))


def guide_over_lost_indication(s: ExitStack) -> None:
    def blind(real: Any) -> Any:
        def open_blocker(self: Any, rs: RouteState, *, guide: bool = False, **kw: Any) -> str:
            why = real(self, rs, guide=guide, **kw)
            return "" if guide and why.startswith("turnout") else why
        return open_blocker
    wrap(s, core.Core, "open_blocker", blind)


def no_run_on(s: ExitStack) -> None:
    patch(s, runon.RunOns, "of", lambda self, end, d, tracks, turnouts: (None, ()))


def no_overlap(s: ExitStack) -> None:
    def add(real: Any) -> Any:
        def without(self: Any, routes: dict[str, Route], *args: Any) -> None:
            before = set(routes)
            real(self, routes, *args)
            for rid in set(routes) - before:
                routes[rid].overlap_sections, routes[rid].overlap_turnouts = (), ()
        return without
    wrap(s, derive._Builder, "_add", add)


def approach_one_section(s: ExitStack) -> None:
    def one(st: Any, rules: Any, signal: str) -> tuple[str, ...]:
        rear = st.signal_rear_track(signal)
        return (st.tracks[rear].section,) if rear else ()
    patch(s, approach, "sections", one)


def no_conflict_table(s: ExitStack) -> None:
    patch(s, conflicts, "_bulk", lambda routes, en, simple: None)
    patch(s, conflicts, "_with_run_on", lambda routes, en: None)

"""Cycles at rest are skipped, and what is skipped changes nothing.

The interlocking at rest (``interlocking/quiet.py``) runs no cycle; each cycle it skips, run here all the same,
must change nothing.

Whatever the interlocking keeps is pickled before and after the real cycle and the two compared, byte for byte:
every route, turnout, signal and line state, the lock ledger, the outputs, the alarms and the events. Only the
clock, the cycle count and the route memos (caches of what a route's check read, with the cycle they held through)
are left out. Nothing here reads the rest's own reasoning (which timers it knows, what it counts as a change), so a
timer it forgets or a change it misses shows here. It runs on the hub full of trains, on every bundled example
script, and through the interlocking test of a third of the routes of stations with each kind of line liaison,
screen doors and USU.

The world at rest (``World.rest``: the interlocking at rest, no trains, only switch machines running on) runs a
stretch of cycles in one go. The interlocking test of those routes and their pairs is run with it and cycle by
cycle, and the whole world (field, relays, interlocking, neighbours, clocks, the oracle's count of cycles) compared,
pickled, before every command of every probe.
"""

from __future__ import annotations

import hashlib
import io
import pickle
from collections.abc import Iterator
from pathlib import Path
from typing import Any

import pytest
from test_shortcuts_same import EXAMPLE_STATIONS, EXAMPLES, _hub_with_trains

from liansuo.cli.main import main
from liansuo.interlocking.cbi import Interlocking
from liansuo.interlocking.io import Outputs
from liansuo.interlocking.state import OpenMemo, Reads, ReleaseMemo, SettingMemo
from liansuo.interlocking.table.build import build_table
from liansuo.proving.verify import verify_station
from liansuo.proving.verify.probe import Probe
from liansuo.rules import RuleSet
from liansuo.simulation.world import World
from liansuo.stations.loader import load
from liansuo.stations.station import Station

pytestmark = pytest.mark.slow  # make test-slow (CI runs it after make test)

_LEFT_OUT = (OpenMemo, SettingMemo, ReleaseMemo, Reads)  # caches of a route's reads, by the cycle
_CLOCK = ("now", "cycles")
_CACHES = ("_door_sections", "_throat_platforms")  # filled on first use: a lookup, not a state


class _Shared(pickle.Pickler):
    """Pickles an interlocking's own state: what it shares with every interlocking of the station (the station,
    the table, the rules, the derived indices) and the route memos are named, not written."""

    def persistent_id(self, obj: Any) -> Any:
        if isinstance(obj, _LEFT_OUT):
            return "memo"
        if isinstance(obj, (Station, RuleSet)) or type(obj).__name__ in ("InterlockingTable", "Index", "AutoBlock"):
            return f"shared:{type(obj).__name__}"
        return None


def state_of(il: Interlocking) -> bytes:
    core = il.core
    kept = {k: v for k, v in vars(core).items() if k not in _CLOCK and k not in _CACHES}
    buf = io.BytesIO()
    _Shared(buf).dump(kept)
    return buf.getvalue()


class QuietChecked:
    """``Interlocking.cycle`` with every cycle the rest would skip run for real and compared."""

    def __init__(self) -> None:
        self.real = Interlocking.cycle
        self.quiet = 0
        self.cycles = 0

    def __call__(self, il: Interlocking, t: float) -> Outputs:
        self.cycles += 1
        q = il.quiet
        if q is None or il.core.board.pending() or not q.holds(t):
            return self.real(il, t)
        self.quiet += 1
        before = state_of(il)
        il.quiet = None  # run it for real
        out = self.real(il, t)
        after = state_of(il)
        assert after == before, f"a cycle skipped at rest at t = {t:g} s changes the interlocking: {_diff(il, t)}"
        return out


def _diff(il: Interlocking, t: float) -> str:
    """A hint at what changed, for the failure message (the assertion itself compares bytes)."""
    return f"routes {[(r.id, r.stage.value) for r in il.core.routes.values()]}, events {list(il.core.events)[-3:]}"


def every_third_route(station: str) -> list[str]:
    """A third of the station's routes, spread over its table (the whole test of each is run: the suite's time)."""
    return list(build_table(load(station)).routes)[::3]


@pytest.fixture
def checked(monkeypatch: pytest.MonkeyPatch) -> Iterator[QuietChecked]:
    c = QuietChecked()
    monkeypatch.setattr(Interlocking, "cycle", lambda il, t: c(il, t))
    monkeypatch.setattr(World, "rest", lambda self, limit: 0)  # every cycle through the interlocking's own
    yield c


def test_at_rest_on_a_hub_full_of_trains(checked: QuietChecked) -> None:
    _hub_with_trains(1200)
    assert checked.quiet > 600, (checked.quiet, checked.cycles)


@pytest.mark.parametrize("station", ["gaotie", "jiaopei", str(EXAMPLE_STATIONS / "danxian.yaml")],
                         ids=["automatic-block-doors-usu", "64d", "station-block"])
def test_at_rest_through_the_interlocking_test_of_a_station(station: str, checked: QuietChecked) -> None:
    report = verify_station(station, routes=every_third_route(station), pairs=False)
    assert report.ok and checked.quiet > 0.5 * checked.cycles, (checked.quiet, checked.cycles)


@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_at_rest_in_every_example_script(script: Path, checked: QuietChecked,
                                         capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["test", str(script)]) == 0
    capsys.readouterr()


# ---- whole cycles at rest (World.rest): the same world as cycle by cycle ------------------------------------------
def world_state(sim: World) -> bytes:
    """Everything a simulation without trains keeps that a cycle can change, with its clocks and cycle counts."""
    buf = io.BytesIO()
    field = {k: v for k, v in vars(sim.field).items() if k not in ("station", "rules")}
    _Shared(buf).dump((sim.t, sim.interlocking.core.now, sim.interlocking.core.cycles, state_of(sim.interlocking),
                       field, vars(sim.neighbours), sim.wiring.commands))
    return buf.getvalue()


def _traced_verify(station: str, monkeypatch: pytest.MonkeyPatch, rest: bool) -> tuple[list[str], Any]:
    """The world's state (hashed) before every command of every probe of a whole verify run, in order."""
    trace: list[str] = []
    with monkeypatch.context() as m:
        if not rest:
            m.setattr(World, "rest", lambda self, limit: 0)
        do = Probe.do

        def traced(p: Probe, line: str) -> Any:
            trace.append(hashlib.sha1(world_state(p.sim) + repr((p.watch.cycles, p.lines)).encode()).hexdigest())
            return do(p, line)

        m.setattr(Probe, "do", traced)
        report = verify_station(station, routes=every_third_route(station))
    return trace, (report.ok, report.checks, [f.as_dict() for f in report.failures])


@pytest.mark.parametrize("station", ["gaotie", "jiaopei", str(EXAMPLE_STATIONS / "danxian.yaml")],
                         ids=["automatic-block-doors-usu", "64d", "station-block"])
def test_cycles_at_rest_leave_the_world_as_cycle_by_cycle(station: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The interlocking test (of a third of the routes, with their pairs) with stretches at rest run in one go, and
    cycle by cycle: the same world (field,
    relays, interlocking, neighbours, clocks, the oracle's count of cycles, the script so far) before every command
    of every probe, and the same report."""
    rested = {"n": 0}
    real = World.rest

    def counted(self: World, limit: int) -> int:
        n = real(self, limit)
        rested["n"] += n
        return n

    monkeypatch.setattr(World, "rest", counted)
    fast, fast_report = _traced_verify(station, monkeypatch, rest=True)
    slow, slow_report = _traced_verify(station, monkeypatch, rest=False)
    assert fast_report == slow_report and fast_report[0]
    assert len(fast) == len(slow) and rested["n"] > 2_000
    first = next((i for i, (a, b) in enumerate(zip(fast, slow, strict=True)) if a != b), None)
    assert first is None, f"the worlds part before command {first} of the run"

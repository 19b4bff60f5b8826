"""Safety properties: random operation of the bundled stations (console commands, occupancy, faults, wheelsets and
trains) never breaks them, and the checker does catch an interlocking that breaks each one."""

from __future__ import annotations

import random
from collections.abc import Callable

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from interlocking.engine import Engine
from interlocking.io import RelayBoard
from interlocking.operations import Interlocking
from interlocking.state import RouteStage, RouteState
from simulation.safety import SafetyChecker
from simulation.sim import Simulation
from simulation.soak import StepGenerator


def random_run(station: str, rnd: random.Random, steps: int) -> tuple[SafetyChecker, list[str]]:
    sim = Simulation(station)
    checker = SafetyChecker(sim)
    gen = StepGenerator(sim, rnd)
    script: list[str] = []
    for _ in range(steps):
        lines, cycles = gen.next()
        for line in lines:
            script.append(line)
            sim.command(line)
        script.append(f"run {cycles * 250}ms")
        sim.run(cycles * 0.25)
        if checker.violations:
            break
    return checker, script


@pytest.mark.parametrize("station", ["jiaopei", "gaotie"])
@settings(max_examples=10, deadline=None, derandomize=True, suppress_health_check=[HealthCheck.too_slow])
@given(rnd=st.randoms(use_true_random=False))
def test_random_operation_keeps_every_safety_property(station: str, rnd: random.Random) -> None:
    checker, script = random_run(station, rnd, 80)
    assert not checker.violations, f"{checker.violations[0]}\nsteps:\n" + "\n".join(script)


# ---- the checker catches a broken interlocking ---------------------------------------------------------------------
def run_lines(station: str, *lines: str) -> SafetyChecker:
    sim = Simulation(station)
    checker = SafetyChecker(sim)
    for line in lines:
        sim.command(line)
    return checker


def props(checker: SafetyChecker) -> set[str]:
    return {v.prop for v in checker.violations}


def test_no_violation_in_ordinary_operation() -> None:
    checker = run_lines("jiaopei", "route X XI", "run 2s", "route XI S", "block-line SL request", "run 5s",
                        "occupy IAG", "run 1s", "occupy 7DG", "run 1s", "vacate IAG", "occupy 1DG", "run 1s",
                        "vacate 7DG", "occupy IG", "run 1s", "vacate 1DG", "run 1s", "occupy 2DG", "run 1s",
                        "vacate IG", "occupy 6DG", "run 1s", "vacate 2DG", "occupy IIAG", "vacate 6DG", "run 30s")
    assert checker.cycles > 100 and checker.violations == []


def test_conflicting_routes_locked_together_are_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(Interlocking, "route_blocker", lambda self, r: "")
    checker = run_lines("jiaopei", "route X XI", "run 2s", "route S SI", "run 2s")
    v = next(v for v in checker.violations if v.prop == "conflict")
    assert "held by both" in v.text or "held normal by" in v.text or "held reverse by" in v.text
    assert v.t > 0


def test_an_open_signal_over_an_occupied_section_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    real = Engine.open_blocker

    def blind(self: Engine, rs: RouteState, *, guide: bool = False, sections: bool = True) -> str:
        why = real(self, rs, guide=guide, sections=sections)
        return "" if why.endswith("is occupied") else why  # an engine blind to occupancy

    monkeypatch.setattr(Engine, "open_blocker", blind)
    checker = run_lines("jiaopei", "route X XI", "run 2s", "occupy IG", "run 1s")
    assert [v.text for v in checker.violations] == ["signal X shows U but section IG of route X-XI is occupied"]


def test_a_locked_turnout_that_moves_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    real: Callable[..., object] = Interlocking.throw

    def careless(self: Interlocking, name: str, position: str) -> object:  # forgets the route's lock
        ts = self.turnouts[name]
        saved, ts.locks = ts.locks, set()
        try:
            return real(self, name, position)
        finally:
            ts.locks = saved

    monkeypatch.setattr(Interlocking, "throw", careless)
    checker = run_lines("jiaopei", "route X XI", "run 2s", "throw 7 reverse", "run 2s")
    assert [v.text for v in checker.violations] == ["locked turnout 7 moved: rails normal -> normal, driven to reverse"]


def test_a_signal_reopening_by_itself_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    real = Engine._advance

    def forgetful(self: Engine, rs: RouteState) -> None:
        if rs.stage is RouteStage.locked and rs.needs_reopen:
            rs.needs_reopen = rs.opened_once = False
        real(self, rs)

    monkeypatch.setattr(Engine, "_advance", forgetful)
    checker = run_lines("jiaopei", "route X XI", "run 2s", "fault no-indication 1", "run 1s",
                        "repair no-indication 1", "run 2s")
    assert props(checker) == {"reopened"}
    # with the operator's reopen command it is no violation
    monkeypatch.setattr(Engine, "_advance", real)
    assert run_lines("jiaopei", "route X XI", "run 2s", "fault no-indication 1", "run 1s", "repair no-indication 1",
                     "run 2s", "reopen X", "run 2s").violations == []


def test_an_aspect_kept_with_its_lamp_dark_is_caught(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(Engine, "_proven", lambda self, signal, aspect: aspect)
    checker = run_lines("jiaopei", "route XI S", "block-line SL request", "run 5s", "fault filament XI lamp=L",
                        "run 1s")
    assert [v.prop for v in checker.violations] == ["aspect"]
    assert "signal XI shows L" in checker.violations[0].text


def test_usu_needs_the_flash_check(monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setattr(RelayBoard, "flasher_ok", lambda self, signal: True)  # an interlocking deaf to SNJJ
    checker = run_lines("gaotie", "route X X3", "route X3 XFCK", "run 10s", "expect signal X USU",
                        "fault flasher X", "run 5s")
    assert [v.text for v in checker.violations] == ["signal X shows USU; for route X-X3 the rules give at most UU"]

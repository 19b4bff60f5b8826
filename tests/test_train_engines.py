"""The same behaviour whichever engine moves the trains: the built-in kinematic engine and Eclipse SUMO (libsumo in a
worker process). The SUMO variants skip, saying why, only where the ``sumo`` extra (libsumo, eclipse-sumo) is not
installed; ``make test`` installs it."""

from __future__ import annotations

from collections.abc import Callable, Iterator
from pathlib import Path

import pytest
from conftest import Driver

from liansuo.proving.scenario import parse_scenario, run_scenario
from liansuo.simulation.sim import Simulation
from liansuo.simulation.trains.sumo import sumo_installed

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
SCENARIOS = sorted((PKG / "examples" / "scenarios").glob("*.yaml"))
SUMO_MISSING = sumo_installed()


def need(engine: str) -> None:
    if engine == "sumo" and SUMO_MISSING:
        pytest.skip(f"SUMO engine tests need the sumo extra: {SUMO_MISSING}")


@pytest.fixture(params=["kinematic", "sumo"])
def engine(request: pytest.FixtureRequest) -> str:
    need(str(request.param))
    return str(request.param)


Make = Callable[[str], Driver]


@pytest.fixture
def make(engine: str) -> Iterator[Make]:
    """Simulations of a station on the engine under test, closed (the SUMO worker stopped) after the test."""
    sims: list[Simulation] = []

    def build(station: str) -> Driver:
        sim = Simulation(station, engine=engine)
        sims.append(sim)
        return Driver(sim)

    yield build
    for sim in sims:
        sim.close()


def no_engine_alarm(d: Driver) -> None:
    assert not [a for a in d.sim.alarm_texts() if "engine failed" in a]


def test_receiving_train_stops_short_of_the_closed_starting_signal_and_the_route_releases(make: Make) -> None:
    d = make("jiaopei")
    d("train T1 at IAG mode=signal length=200", "route X XI", "run 2min")
    v = d.sim.train_views()[0]
    assert v.sections == ("IG",) and v.speed_kmh == 0.0
    assert 1000.0 < v.head_m < 1020.0  # short of starting signal XI at 1020 m
    order = [e.split("section ")[1].split(" ")[0] for e in d.sim.event_texts() if "released (X-XI)" in e]
    assert order == ["7DG", "1DG", "IG"]  # section by section behind the train
    d("expect route X XI released", "expect signal X H")
    no_engine_alarm(d)


def test_departure_leaves_the_station(make: Make) -> None:
    d = make("jiaopei")
    d("train T1 at IG mode=signal length=200", "route XI S", "block-line SL request", "run 5s", "expect signal XI L",
      "run 3min", "expect block-line SL idle")
    assert d.sim.train_views() == []
    assert any("train T1 has left the station" in e for e in d.sim.event_texts())
    no_engine_alarm(d)


def test_manual_train_passing_a_red_signal_raises_the_spad_alarm(make: Make) -> None:
    d = make("jiaopei")
    d("train T1 at IAG length=100 back=60", "drive T1 20", "run 30s", "expect alarm signal X passed at danger")
    assert d.sim.train_views()[0].speed_kmh == pytest.approx(20.0, abs=0.01)
    no_engine_alarm(d)


def test_platform_stop_within_the_stopping_window(make: Make) -> None:
    d = make("gaotie")
    d("train G2 at IAG kind=emu mode=signal back=900 stop=P3", "route X X3", "run 150s")
    g = d.sim.fleet.trains["G2"]
    assert g.platform_stop is not None and g.platform_stop.state == "doors_open"
    stop = next(e for e in d.sim.event_texts() if "stopped at platform P3" in e)
    offset = float(stop.split(", ")[1].split(" m from")[0])
    assert abs(offset) <= 0.5, stop  # within the window of ±0.5 m
    no_engine_alarm(d)


def test_facing_move_onto_a_moving_turnout_derails(make: Make) -> None:
    d = make("jiaopei")
    d("fault high-resistance 1", "throw 1 reverse", "train T1 at 7DG length=40 back=10", "drive T1 20", "run 20s",
      "expect alarm derailed at turnout 1")
    assert d.sim.train_views()[0].speed_kmh == 0.0
    no_engine_alarm(d)


def test_train_stops_at_the_buffer_stop(make: Make) -> None:
    d = make("jiaopei")
    d("train L1 at QXG kind=shunter dir=up back=30", "drive L1 10", "run 90s")
    assert any("train L1 stopped at buffer stop BQX" in e for e in d.sim.event_texts())
    v = d.sim.train_views()[0]
    assert v.speed_kmh == 0.0 and v.head_m == pytest.approx(120.0, abs=0.01)
    no_engine_alarm(d)


def test_shunter_draws_back_after_reversing_and_the_route_releases(make: Make) -> None:
    d = make("jiaopei")
    d("train L1 at QXG kind=shunter mode=signal back=30", "shunt D1 SI", "run 5s", "expect signal D1 B",
      "drive L1 10", "run 25s", "stop L1", "run 10s", "expect section 7DG occupied", "reverse L1", "drive L1 10",
      "run 30s", "stop L1", "run 5s", "expect section 7DG free", "expect route D1 SI released")
    no_engine_alarm(d)


@pytest.mark.parametrize("scenario", SCENARIOS, ids=[p.stem for p in SCENARIOS])
def test_every_example_scenario_runs_without_a_refused_step(scenario: Path, engine: str) -> None:
    out: list[str] = []
    status, sim = run_scenario(parse_scenario(scenario), out=out, engine=engine)
    try:
        assert status == 0, "\n".join(out[-15:])
        assert not [line for line in out if "refused" in line or "engine failed" in line]
    finally:
        sim.close()


def test_both_engines_stop_the_train_at_the_same_place() -> None:
    need("sumo")
    heads = []
    for engine in ("kinematic", "sumo"):
        sim = Simulation("jiaopei", engine=engine)
        Driver(sim)("train T1 at IAG mode=signal length=300", "route X XI", "run 100s")
        heads.append(sim.train_views()[0].head_m)
        sim.close()
    assert heads[0] == pytest.approx(heads[1], abs=0.05)


def test_unknown_engine_is_refused_with_the_choices() -> None:
    with pytest.raises(ValueError, match="kinematic or sumo"):
        Simulation("jiaopei", engine="steam")

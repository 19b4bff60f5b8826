"""The shortcuts of the trains' cycle never change what happens, each checked against the path it replaces:

- a driver's target speed worked out in one pass (``drivers.aim``) against the rule written plainly here, at
  every step of every train, also for the kinds of movement the train is not (shunting, stopping at the boundary),
  and with the way ahead worked out afresh;
- a route's cycle skipped while nothing it reads changed (in use: ``ReleaseMemo``, setting: ``SettingMemo``, open:
  ``OpenMemo``): every skip is followed by the stage's handler itself, which must then change nothing (with the
  interlocking's whole cycle skipped at rest switched off here, so that every route's cycle is asked for; the rest
  has its own test, tests/test_quiet_same.py);
- the odometer worked out only when read (``OdometerFeed``) against one fed step by step.

They run on the hub full of trains of the benchmark and on every bundled example script (shunting, automatic
shunting, guide aspects, section fault release, faults, SPAD, platform stops); the skipped routes also through the
whole interlocking test of stations with each kind of line liaison."""

from __future__ import annotations

import random
from collections import Counter
from dataclasses import dataclass
from math import sqrt
from pathlib import Path
from typing import Any

import pytest

from liansuo.bench.trains import _Dispatcher, train_slots
from liansuo.cli.main import main
from liansuo.interlocking.cbi import Interlocking
from liansuo.interlocking.lifecycle import RouteLifecycle
from liansuo.interlocking.state import RouteState
from liansuo.interlocking.table.build import build_table
from liansuo.proving.verify import verify_station
from liansuo.simulation.sim import Simulation
from liansuo.simulation.trains import fleet as fleet_module
from liansuo.simulation.trains.drivers import Lookout
from liansuo.simulation.trains.movement import Position, TrackGeometry
from liansuo.simulation.trains.odometerfeed import MAX_PENDING, OdometerFeed
from liansuo.simulation.trains.odometry import Odometer
from liansuo.stations.hubgen import generate_hub
from liansuo.stations.loader import load_text
from liansuo.stations.schema import EndKind

EXAMPLES = sorted((Path(__file__).parent.parent / "src" / "liansuo" / "examples" / "scripts").glob("*.yaml"))
EXAMPLE_STATIONS = Path(__file__).parent.parent / "src" / "liansuo" / "examples" / "stations"


def _hub_with_trains(cycles: int) -> Simulation:
    station = load_text(generate_hub(20, 8), "<hub20>")
    table = build_table(station)
    sim = Simulation(station, table=table)
    dispatchers = [_Dispatcher(sim, f"B{i + 1}", r, d) for i, (r, d) in enumerate(train_slots(table, 4))]
    for cycle in range(cycles):
        if cycle % 4 == 0:
            for d in dispatchers:
                d.tick()
        sim.step()
    assert sum(d.departures for d in dispatchers) > 0
    return sim


# ---- the driver's target in one pass -------------------------------------------------------------------------------
@dataclass(frozen=True)
class Ahead:
    """A thing ahead a driver must heed: the distance to it and the speed allowed there (0: stop)."""

    distance_m: float
    speed_ms: float
    what: str


def look_ahead(track: TrackGeometry, pos: Position, lookout: Lookout, aspects: dict[str, str], horizon: float,
               margin: float, *, shunting: bool, boundary_stops: bool) -> list[Ahead]:
    """Signals, buffer stops and (optionally) the boundary ahead along the rails as they lie now, up to the first
    stop: a closed signal (less ``margin``), a buffer stop or the boundary (less the buffer margin)."""
    out: list[Ahead] = []
    closed, speeds_kmh, ends = lookout.closed, lookout.speeds_kmh, lookout.station.ends
    direction = pos.moves[-1][1]
    for dist, node, _move in track.ahead(pos, horizon):
        for sig in lookout.heeded(node, direction, shunting):
            aspect = aspects.get(sig.id, "")
            if aspect in closed:
                out.append(Ahead(dist - margin, 0.0, f"signal {sig.id} at {aspect or 'dark'}"))
                return out
            limit = speeds_kmh.get(aspect)
            if limit is not None:
                out.append(Ahead(dist, limit / 3.6, f"signal {sig.id} at {aspect}"))
        end = ends.get(node)
        if end is not None and (end.kind is EndKind.buffer or boundary_stops):
            out.append(Ahead(dist - lookout.buffer_margin_m, 0.0, f"{end.kind.value} {node}"))
            return out
    return out


def target_speed(current_limit_ms: float, vmax_ms: float, ahead: list[Ahead], brake_ms2: float,
                 lead_m: float) -> tuple[float, str]:
    """The lowest of line speed, the current aspect's limit, and what lets the train meet every limit ahead."""
    v = min(vmax_ms, current_limit_ms)
    why = ""
    for a in ahead:
        allowed = sqrt(a.speed_ms ** 2 + 2.0 * brake_ms2 * max(a.distance_m - lead_m, 0.0))
        if a.speed_ms == 0.0 and a.distance_m <= 0.5:
            allowed = 0.0
        if allowed < v:
            v, why = allowed, a.what
    return v, why


class AimChecked:
    """``drivers.aim`` as the fleet calls it, each answer compared with the reference path."""

    def __init__(self) -> None:
        self.calls = 0
        self.bound = 0  # answers limited by something ahead (a signal, a buffer stop, the boundary)
        self.real = fleet_module.aim

    def __call__(self, track: TrackGeometry, pos: Position, aspects: dict[str, str], lookout: Lookout, horizon: float,
                 margin: float, shunting: bool, boundary_stops: bool, current_limit_ms: float, vmax_ms: float,
                 brake_ms2: float, lead_m: float) -> tuple[float, str]:
        got = self.real(track, pos, aspects, lookout, horizon, margin, shunting, boundary_stops, current_limit_ms,
                        vmax_ms, brake_ms2, lead_m)
        self.calls += 1
        self.bound += got[1] != ""
        fresh = Position(list(pos.moves), pos.front_s)  # nothing kept on it
        for s, b in {(shunting, boundary_stops), (not shunting, boundary_stops), (shunting, not boundary_stops)}:
            for p in (pos, fresh):
                ahead = look_ahead(track, p, lookout, aspects, horizon, margin, shunting=s, boundary_stops=b)
                want = target_speed(current_limit_ms, vmax_ms, ahead, brake_ms2, lead_m=lead_m)
                mine = self.real(track, p, aspects, lookout, horizon, margin, s, b, current_limit_ms, vmax_ms,
                                 brake_ms2, lead_m)
                assert repr(mine) == repr(want), (pos, s, b)  # the very same floats (and signs of zero)
        return got


def _aim_checked(monkeypatch: pytest.MonkeyPatch) -> AimChecked:
    checked = AimChecked()
    monkeypatch.setattr(fleet_module, "aim", checked)
    return checked


def test_the_target_in_one_pass_on_a_hub_full_of_trains(monkeypatch: pytest.MonkeyPatch) -> None:
    checked = _aim_checked(monkeypatch)
    _hub_with_trains(900)
    assert checked.calls > 1500 and checked.bound > 50


# ---- a route's cycle skipped while nothing it reads changed -------------------------------------------------------
class SkipChecked:
    """``RouteLifecycle.unchanged`` as ``advance_all`` asks it: every route it skips (in use, setting or open) gets
    its stage handler run all the same, there and then, which must change nothing: no stage, mark, timer, aspect,
    lock, alarm or event. The memos are put back as they were, so the run goes on as it would have."""

    def __init__(self) -> None:
        self.skipped: Counter[str] = Counter()
        self.real = RouteLifecycle.unchanged

    def __call__(self, lc: RouteLifecycle, rs: RouteState) -> bool:
        if not self.real(lc, rs):
            return False
        self.skipped[rs.stage.value] += 1
        memo = rs.memo
        before = self._state(lc, rs)
        lc.advance(rs)
        assert self._state(lc, rs) == before, (rs.id, rs.stage, lc.core.now)
        rs.memo = memo
        return True

    @staticmethod
    def _state(lc: RouteLifecycle, rs: RouteState) -> Any:
        il = lc.core
        marks = (rs.stage, rs.entered, list(rs.released), list(rs.was_occupied), rs.overlap_release_at,
                 rs.release_at, rs.since, il.routes.get(rs.id) is rs)
        return (marks, dict(il.out.signals), il.locks.version, sorted(il.alarms), len(il.events),
                il.events[-1] if il.events else None, dict(il.overlap_pending), il.codes_dirty, set(il.usu_failed))


def _skip_checked(monkeypatch: pytest.MonkeyPatch) -> SkipChecked:
    checked = SkipChecked()
    monkeypatch.setattr(Interlocking, "skip_quiet", False)  # every cycle runs, so the routes' skips are all seen
    monkeypatch.setattr(RouteLifecycle, "unchanged", lambda lc, rs: checked(lc, rs))
    return checked


def test_skipped_routes_on_a_hub_full_of_trains(monkeypatch: pytest.MonkeyPatch) -> None:
    checked = _skip_checked(monkeypatch)
    _hub_with_trains(1200)
    assert checked.skipped["in_use"] > 1000 and checked.skipped["open"] > 100 and checked.skipped["setting"] > 30, \
        checked.skipped


@pytest.mark.parametrize("station", ["gaotie", "jiaopei", str(EXAMPLE_STATIONS / "danxian.yaml")],
                         ids=["automatic-block-doors-usu", "64d", "station-block"])
def test_skipped_routes_through_the_interlocking_test_of_a_station(
        station: str, monkeypatch: pytest.MonkeyPatch) -> None:
    """The whole interlocking test (every fault, release and aspect it tries) on stations with each kind of line
    liaison, screen doors and USU, each skip followed by its handler; every compatible pair simulated, those apart
    too, so the interlocking is driven through all verify can make it do."""
    checked = _skip_checked(monkeypatch)
    report = verify_station(station, simulate_all=True)
    assert report.ok and checked.skipped["open"] > 500 and checked.skipped["setting"] > 500, checked.skipped


@pytest.mark.parametrize("watch", [_aim_checked, _skip_checked], ids=["aim", "skip"])
@pytest.mark.parametrize("script", EXAMPLES, ids=lambda p: p.stem)
def test_each_shortcut_matches_its_plain_path_in_every_example_script(
        script: Path, watch: Any, monkeypatch: pytest.MonkeyPatch, capsys: pytest.CaptureFixture[str]) -> None:
    """The drivers' target and the skipped release checks, followed by their plain paths through every example
    script (each check asserts as it goes)."""
    watch(monkeypatch)
    assert main(["test", str(script)]) == 0
    capsys.readouterr()


def test_a_hub_runs_the_same_with_and_without_skipping() -> None:
    def run(skip: bool) -> list[Any]:
        station = load_text(generate_hub(20, 8), "<hub20>")
        table = build_table(station)
        sim = Simulation(station, table=table)
        sim.interlocking.lifecycle.skip_unchanged = skip
        sim.interlocking.skip_quiet = skip  # and no cycle skipped at rest (interlocking/quiet.py)
        dispatchers = [_Dispatcher(sim, f"B{i + 1}", r, d) for i, (r, d) in enumerate(train_slots(table, 4))]
        seen: list[Any] = []
        for cycle in range(1200):
            if cycle % 4 == 0:
                for d in dispatchers:
                    d.tick()
            if cycle == 700 and sim.view.routes():  # a section fault release (区故解) on a route in use
                rv = next((r for r in sim.view.routes() if r.state == "in_use"), None)
                if rv is not None:
                    assert sim.command(f"fault-release {table.routes[rv.id].sections[0]}").message
            sim.step()
            seen.append((sorted((r.id, r.state) for r in sim.view.routes()), dict(sim.view.outputs.signals),
                         [(t.name, t.speed_ms, t.pos.front_s) for t in sim.fleet.trains.values()]))
        seen.append(sim.event_texts())
        return seen

    assert run(True) == run(False)


# ---- the odometer worked out when read -----------------------------------------------------------------------------
def _odometer_state(o: Odometer) -> Any:
    return (o.position_m, o.speed_ms, o.slipping, o.sliding, o.t, list(o.episodes), list(o.corrections))


@pytest.mark.parametrize("seed", range(6))
def test_the_odometer_worked_out_when_read_is_the_one_fed_step_by_step(seed: int) -> None:
    rng = random.Random(seed)
    eager, feed = Odometer(), OdometerFeed()
    v = 0.0
    for step in range(3 * MAX_PENDING // 2):
        v = max(0.0, v + rng.uniform(-0.4, 0.35))
        wheel = v * (1.0 + (rng.uniform(-0.6, 0.8) if 300 < step % 900 < 340 else 0.0))  # slips and slides
        accel = rng.uniform(-1.0, 1.0)
        eager.update(0.25, wheel, accel_ms2=accel)
        feed.update(0.25, wheel, accel)
        if rng.random() < 0.02:
            at = eager.position_m + rng.uniform(-3.0, 3.0)
            eager.section_transition(at, since_s=0.1)
            feed.section_transition(at, since_s=0.1)
        if rng.random() < 0.01:
            at = eager.position_m + 1.0
            eager.correct(at, "balise", since_s=0.05)
            feed.correct(at, "balise", since_s=0.05)
        if rng.random() < 0.003:  # read now and then, else only at the end (and when too much is kept)
            assert _odometer_state(feed.odometer) == _odometer_state(eager)
            assert feed.pending == 0
        assert feed.pending < MAX_PENDING
    assert _odometer_state(feed.odometer) == _odometer_state(eager)
    assert feed.error_m(100.0) == eager.error_m(100.0) and feed.position_m == eager.position_m
    assert feed.episodes and feed.corrections  # it did slip or slide, and was corrected


def test_a_step_the_odometer_could_not_take_is_refused_at_once() -> None:
    with pytest.raises(ValueError):
        OdometerFeed().update(0.0, 1.0)

"""``liansuo explore``: the search saturates a small bounded model, every explored sequence replays to the state it
was keyed as, the reduction loses no state, each seeded defect of the issue's kind is found with a shortest sequence
that replays as a failing test, and the report says what a user needs. Long explorations are ``liansuo bench
--explore``'s (docs/benchmark.md)."""

from __future__ import annotations

import json
from pathlib import Path

import pytest

from liansuo.cli.main import main
from liansuo.proving.explore.actions import Bounds
from liansuo.proving.explore.key import state_key
from liansuo.proving.explore.report import script
from liansuo.proving.explore.search import Expander, Trace, expand_here, search
from liansuo.proving.mutation.mutants import MUTANTS
from liansuo.proving.scripts import parse_script, run_script
from liansuo.rules import load_rules
from liansuo.stations.loader import load

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
MINIMAL = str(PKG / "examples" / "stations" / "minimal.yaml")
PODAO = str(PKG / "examples" / "stations" / "podao.yaml")
SMALL = Bounds(routes=1, faults=0, occupied=1, turnout_marks=0, guide_locks=0)


def explore(station: str, depth: int, bounds: Bounds = SMALL, *, reduce: bool = True, mutant: str = "",
            first: bool = False) -> tuple[Expander, object]:
    m = next((x for x in MUTANTS if x.name == mutant), None)
    st = load(station)
    if m is None:
        ex = Expander(st, load_rules(), bounds=bounds, reduce=reduce)
        return ex, search(st, expand_here(ex), ex.root_key, depth, first=first)
    with m.applied():
        ex = Expander(st, load_rules(), bounds=bounds, reduce=reduce)
        return ex, search(st, expand_here(ex), ex.root_key, depth, first=first)


@pytest.mark.slow  # make test-slow (CI runs it after make test)
def test_the_bounded_model_of_the_minimal_station_saturates_with_no_violation() -> None:
    _, out = explore(MINIMAL, 40)
    assert out.saturated and out.findings == {}  # type: ignore[attr-defined]
    assert 1000 < out.states < 20000  # type: ignore[attr-defined]


def test_the_sound_interlocking_gives_explore_nothing_to_find_at_the_default_bounds() -> None:
    """Every sequence of four steps on the minimal station, two routes, a fault, two occupied sections, a turnout
    mark and guide total lock at once: it found a guide aspect given under guide total lock before the power-up
    release, now refused."""
    _, out = explore(MINIMAL, 4, Bounds())
    assert out.findings == {} and out.states > 1000  # type: ignore[attr-defined]


def test_a_snapshot_takes_every_part_of_the_oracles_memory() -> None:
    """What the oracle learns as it watches must go into a snapshot, or branches of the search leak into each other;
    everything else it holds is the station's, fixed once it is made (a new attribute must be put in one list)."""
    from liansuo.proving.explore.snapshot import _MEMORY
    from liansuo.proving.oracle import Watch
    from liansuo.simulation.sim import Simulation

    fixed = {"aspects", "ceiling", "cycle_s", "doors", "flank", "kind", "lamps", "lines", "onto_track", "pair_of",
             "reaction", "reader", "rear", "role", "section_of", "st", "tracer", "turnout_section",
             "turnout_sections", "turnout_tracks"}
    oracle = Watch(Simulation(MINIMAL), judge=True).oracle
    assert set(vars(oracle)) - set(_MEMORY) == fixed


def levels(station: str, depth: int, bounds: Bounds, reduce: bool) -> tuple[set[bytes], list[Trace]]:
    ex = Expander(load(station), load_rules(), bounds=bounds, reduce=reduce)
    seen, frontier, every = {ex.root_key}, [()], []
    for _ in range(depth):
        new = []
        for trace in frontier:
            for key, child in ex.expand(trace).children:
                every.append(child)
                if key not in seen:
                    seen.add(key)
                    new.append(child)
        frontier = new
    return seen, every


def test_every_explored_sequence_replays_on_a_fresh_simulation_to_the_state_it_was_keyed_as() -> None:
    bounds = Bounds(routes=1, faults=1, occupied=2, turnout_marks=1, guide_locks=1)
    ex = Expander(load(MINIMAL), load_rules(), bounds=bounds)
    fresh = Expander(load(MINIMAL), load_rules(), bounds=bounds)
    frontier: list[Trace] = [()]
    checked = 0
    for _ in range(4):
        new = []
        for trace in frontier:
            for key, child in ex.expand(trace).children:
                fresh._path = [((), fresh.root)]  # from the start, every step replayed
                fresh.goto(child)
                assert state_key(fresh.sim, fresh.watch) == key, [s.line for s in child]
                checked += 1
                new.append(child)
        frontier = new[::4]
    assert checked > 200


@pytest.mark.slow  # make test-slow (CI runs it after make test)
@pytest.mark.parametrize("station", [MINIMAL, PODAO])
def test_the_partial_order_reduction_reaches_every_state_the_full_search_does(station: str) -> None:
    bounds = Bounds(routes=2, faults=1, occupied=2, turnout_marks=1, guide_locks=1)
    depth = 4 if station == MINIMAL else 2
    reduced, _ = levels(station, depth, bounds, True)
    full, _ = levels(station, depth, bounds, False)
    assert reduced == full and len(full) > 100


@pytest.mark.parametrize(("mutant", "station", "depth", "bounds", "found"), [
    ("overlap-from-the-yard", PODAO, 2, SMALL, "turnout"),
    ("home-ignores-line-direction", PODAO, 3, SMALL, "line"),
    ("direction-change-ignores-guide", PODAO, 3, Bounds(2, 0, 0, 0, 1), "line"),
    ("cancel-ignores-approach", MINIMAL, 4, SMALL, "cancel"),
    ("no-release-delay", MINIMAL, 4, SMALL, "release"),
])
def test_explore_finds_a_seeded_defect_by_itself_with_a_shortest_sequence(
        mutant: str, station: str, depth: int, bounds: Bounds, found: str, tmp_path: Path) -> None:
    _, out = explore(station, depth, bounds, mutant=mutant, first=True)
    findings = out.findings  # type: ignore[attr-defined]
    assert findings, f"{mutant} not found by depth {depth}"
    key, f = min(findings.items(), key=lambda kv: len(kv[1].trace))
    assert f.violation.prop == found, key
    # the reproducer fails under the mutant with the violation, at its last step; on the sound interlocking nothing
    # unsafe happens: it passes, or stops at the command the sound interlocking refuses
    path = tmp_path / "repro.yaml"
    path.write_text(script(station, f), encoding="utf-8")
    sound = run_script(parse_script(path))
    m = next(x for x in MUTANTS if x.name == mutant)
    with m.applied():
        broken = run_script(parse_script(path))
    (b,) = broken
    last = len(path.read_text(encoding="utf-8").splitlines())  # the file ends with the last step's lines
    assert not b.passed and "safety violation" in b.failure, b.log
    assert last - len(f.trace[-1].line.split("; ")) < b.line <= last, b.log
    (ok,) = sound
    assert ok.passed or "refused" in ok.failure, ok.failure
    assert "safety violation" not in ok.failure


def test_the_report_says_how_far_it_got_and_writes_each_reproducer(capsys: pytest.CaptureFixture[str],
                                                                     tmp_path: Path) -> None:
    code = main(["explore", MINIMAL, "--depth", "3", "--routes", "1", "--faults", "0", "--occupied", "1",
                 "--marks", "0", "--guide-locks", "0", "--format", "json", "--out", str(tmp_path)])
    rep = json.loads(capsys.readouterr().out)
    assert code == 0 and rep["ok"] and rep["depth"] == 3 and not rep["saturated"] and rep["violations"] == []
    assert rep["bounds"] == {"routes": 1, "faults": 0, "occupied": 1, "turnout_marks": 0, "guide_locks": 0}
    assert [lv["depth"] for lv in rep["levels"]] == [1, 2, 3] and rep["states"] > 50 and rep["abstractions"]
    assert list(tmp_path.iterdir()) == []
    assert main(["explore", MINIMAL, "--depth", "1"]) == 0
    text = capsys.readouterr().out
    assert "not saturated" in text and "0 violations" in text


def test_a_violation_fails_the_command_and_its_reproducer_is_written_to_the_folder(
        capsys: pytest.CaptureFixture[str], tmp_path: Path) -> None:
    m = next(x for x in MUTANTS if x.name == "overlap-from-the-yard")
    with m.applied():
        code = main(["explore", PODAO, "--depth", "2", "--routes", "1", "--faults", "0", "--occupied", "1",
                     "--marks", "0", "--guide-locks", "0", "--out", str(tmp_path / "found")])
        written = sorted((tmp_path / "found").iterdir())
        assert code == 1 and written and all(p.name.startswith("explore-podao-") for p in written)
        assert main(["test", str(written[0])]) == 1  # it replays, from any folder, and fails under the defect
    out = capsys.readouterr().out
    assert f"{len(written)} violations" in out and "FAIL" in out and "safety violation" in out

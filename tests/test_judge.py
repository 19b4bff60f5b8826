"""The reference judge of commands and releases (``proving/judge``): what the oracle has no view of (approach
locking, release timing, the power-up lock, reopening, the guide aspect closing, the overlap's time). Each seeded
defect below passes the oracle alone and is found by the judge with the property that breaks, while the sound
interlocking gives it nothing to say. Its independence of the interlocking is held by ``tests/test_oracle.py``
(imports)."""

from __future__ import annotations

from contextlib import nullcontext
from pathlib import Path
from unittest import mock

import pytest

from liansuo.interlocking import operations
from liansuo.proving.mutation.mutants import MUTANTS
from liansuo.proving.oracle import Watch
from liansuo.proving.oracle.watch import Violation
from liansuo.simulation.sim import Simulation

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
MINIMAL = str(PKG / "examples" / "stations" / "minimal.yaml")
DANXIAN = str(PKG / "examples" / "stations" / "danxian.yaml")

CASES = [
    ("cancel-ignores-approach", MINIMAL, "route X XI; run 3s; occupy IAG; run 1s; cancel X; run 1s", "cancel"),
    ("no-release-delay", MINIMAL, "route X XI; run 3s; occupy IAG; run 1s; release X; run 1s", "release"),
    ("fault-release-cuts-time-release", MINIMAL, "route X XI; run 3s; occupy IAG; run 1s; release X; run 1s; "
     "vacate IAG; run 1s; fault-release 1DG; run 1s", "release"),
    ("no-power-up-lock", MINIMAL, "restart; run 1s; route X XI; run 3s", "power-up"),
    ("guide-stays-open", "jiaopei", "route X XI; run 5s; occupy IG; run 1s; guide X; run 1s; occupy IAG; run 1s; "
     "occupy 7DG; run 3s", "guide"),
    ("overlap-released-at-once", DANXIAN, "route X XI; run 5s; occupy IAG; run 1s; occupy 1DG; run 1s; vacate IAG; "
     "run 1s; occupy IG; run 1s; vacate 1DG; run 5s", "overlap-time"),
    ("release-delay-a-tenth", MINIMAL, "route X XI; run 3s; occupy IAG; run 1s; release X; run 20s", "release"),
    ("reopen-without-conditions", MINIMAL, "route X XI; run 3s; occupy 1DG; run 1s; reopen X; run 1s", "reopen"),
    ("guide-never-times-out", "jiaopei", "route X XI; run 5s; occupy IG; run 1s; guide X; run 70s", "guide"),
]


def watched(station: str, lines: str, mutant: str = "", *, judge: bool = True) -> list[Violation]:
    m = next((x for x in MUTANTS if x.name == mutant), None)
    with m.applied() if m is not None else nullcontext():
        sim = Simulation(station)
        watch = Watch(sim, judge=judge)
        for line in (x.strip() for x in lines.split(";")):
            sim.command(line)
        return watch.violations


@pytest.mark.parametrize(("mutant", "station", "lines", "prop"), CASES, ids=[c[0] for c in CASES])
def test_the_judge_finds_what_the_oracle_cannot_see(mutant: str, station: str, lines: str, prop: str) -> None:
    assert watched(station, lines) == []  # the sound interlocking: nothing to say
    assert watched(station, lines, mutant, judge=False) == []  # the oracle alone: blind to it
    found = watched(station, lines, mutant)
    assert found and {(v.source, v.prop) for v in found} == {("judge", prop)}, [v.text for v in found]


def test_a_finding_is_reported_once_while_it_lasts_and_says_what_went_wrong() -> None:
    (v,) = watched(MINIMAL, "route X XI; run 3s; occupy IAG; run 1s; release X; run 10s", "no-release-delay")
    assert v.as_dict()["source"] == "judge" and v.key == "release:X"
    assert "released 179" in v.text and "before the end of its time release" in v.text


def test_the_judge_takes_its_times_from_the_station_file_and_the_rule_set_not_from_the_interlocking(
        tmp_path: Path) -> None:
    """X's own release time (``release_s: 60``) is the published figure for it: the interlocking keeping it is sound;
    an interlocking that reads the rule set's shunting 30 s instead is found, although it is its own number."""
    own = "lamps: [U, L, H, U2, B], buttons: [train]"
    text = Path(MINIMAL).read_text(encoding="utf-8").replace(own + "}", own + ", release_s: 60}")
    station = tmp_path / "minimal-60.yaml"
    station.write_text(text, encoding="utf-8")
    lines = "route X XI; run 3s; occupy IAG; run 1s; release X; run 58s; run 3s"
    assert watched(str(station), lines) == []
    with mock.patch.object(operations.Operator, "release_delay", lambda self, r: 30.0):
        found = watched(str(station), lines)
    assert [(v.source, v.prop) for v in found] == [("judge", "release")] and "30.0 s before" in found[0].text


@pytest.mark.parametrize("lines", [
    # a guided train entering as its guide aspect lights: it has entered, not stood on a red band
    "occupy IAG; run 0.25s; throw 1 reverse; run 0.75s; guide X XI; run 4s; occupy 1DG; run 0.75s; vacate 1DG; "
    "run 0.25s; fault-release 1DG; run 1s",
    # the guide aspect given again over its route after its red lamp failed: the operator's (a hazard), not two
    # movements the interlocking let into one route
    "occupy IAG; occupy 1DG; run 0.5s; guide X XI; run 0.75s; fault filament X lamp=H which=both; run 0.75s; "
    "repair filament X; run 0.5s; guide X; run 0.5s; fault filament X lamp=H which=both; run 0.75s",
    # cancelling a guide aspect under guide total lock with a train approaching: no route to release
    "guide-lock X; run 0.25s; guide X; run 0.5s; occupy IAG; run 0.25s; cancel X; run 0.5s",
])
def test_sequences_explore_found_on_the_sound_interlocking_are_not_violations(lines: str) -> None:
    """Each of these was a finding of 'liansuo explore' on the minimal station that was the checks' mistake."""
    assert watched(MINIMAL, lines) == []

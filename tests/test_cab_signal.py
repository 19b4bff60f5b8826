"""The cab signal on every train, ATP braking on code loss or a wrong carrier, and the traction-current leakage
through a long dead zone that flickers the next section's relay (issue 15, item 4)."""

from __future__ import annotations

from pathlib import Path

import pytest

from liansuo.circuits.cabcurrent import CabCurrents
from liansuo.circuits.field import Field
from liansuo.circuits.leakage import Flicker, long_dead_zones
from liansuo.cli.main import main
from liansuo.rules import load_rules
from liansuo.simulation.sim import Simulation
from liansuo.simulation.trains.cabsignal import CabReader
from liansuo.stations.loader import load

EXAMPLES = Path(__file__).parent.parent / "src" / "liansuo" / "examples"


def test_scenario_shows_the_atp_braking_on_a_wrong_carrier(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["run", str(EXAMPLES / "scenarios" / "gaotie-cab-atp.yaml")]) == 0
    out = capsys.readouterr().out
    assert ("train T1: ATP brakes to a stand: read carrier 2300-2 of 1-7DG in the 11.2 m dead zone of joint J-13, "
            "expected 2600-2 of 3-5DG") in out
    assert "alarm    ATP braked train T1" in out
    assert "train T1: emergency stop from atp released" in out


def test_script_shows_code_loss_wrong_carrier_and_flicker(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["test", str(EXAMPLES / "scripts" / "cab-signal.yaml")]) == 0
    assert capsys.readouterr().out.strip().splitlines()[-1] == "3 passed, 0 failed"


def test_a_failing_cab_expectation_says_what_the_cab_reads(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "t.yaml"
    f.write_text("station: gaotie\ntests:\n  - name: cab\n    steps:\n      - route X XI\n      - run 10s\n"
                 "      - train T1 at 1-7DG kind=emu\n      - run 1s\n      - expect cab T1 lost\n", encoding="utf-8")
    assert main(["test", str(f)]) == 1
    out = capsys.readouterr().out
    assert "the cab of T1 reads HU on 1-7DG carrier 2300-2" in out and "expected\n        lost" in out
    sim = Simulation("gaotie")
    assert sim.command("expect cab T9 lost").message == "there is no train 'T9' in the yard"


def _wrong_carrier_run() -> Simulation:
    sim = Simulation("gaotie")
    for c in ("route X BA1 XI", "run 20s", "train T1 at IAG kind=emu mode=signal", "run 6s"):
        assert sim.command(c).ok
    return sim


def test_cab_reads_code_carrier_and_level_and_the_atp_brakes_to_a_stand() -> None:
    sim = _wrong_carrier_run()
    cab = sim.train_view("T1").cab
    assert (cab.state, cab.section, cab.code, cab.carrier, cab.atp_braking) == ("code", "1-7DG", "HU", "2300-2", False)
    assert cab.level_mA is not None and cab.level_mA > 500.0
    seen = set()
    for _ in range(30 * 4):
        sim.step()
        seen.add(sim.train_view("T1").cab.state)
    v = sim.train_view("T1")
    assert "wrong-carrier" in seen
    assert v.speed_kmh == 0.0 and v.cab.atp_braking and v.head_track == "t-3a"  # stood on 3-5DG
    assert sim.fleet.trains["T1"].why == "emergency stop (atp)"
    assert sim.command("estop-release T1 atp").ok
    sim.run(10)
    assert sim.train_view("T1").speed_kmh > 0.0


def test_a_shunting_movement_is_not_braked_by_the_atp() -> None:
    sim = Simulation("gaotie")
    for c in ("route X BA1 XI", "run 20s", "train T1 at IAG kind=emu mode=signal movement=shunt"):
        assert sim.command(c).ok
    sim.run(40)
    assert not any("ATP" in a for a in sim.alarm_texts())
    assert not sim.train_view("T1").cab.atp_braking


def test_the_cab_works_only_when_its_stretch_code_or_faults_change(monkeypatch: pytest.MonkeyPatch) -> None:
    calls: list[int] = []
    original = CabReader._work_out

    def counting(self: CabReader, *args: object) -> object:
        calls.append(1)
        return original(self, *args)  # type: ignore[arg-type]

    monkeypatch.setattr(CabReader, "_work_out", counting)
    sim = Simulation("gaotie")
    for c in ("route X XI", "run 10s", "train T1 at 1-7DG kind=emu", "drive T1 40"):
        assert sim.command(c).ok
    sim.run(60)  # 240 steps over 1-7DG, 9-15DG and into IG
    assert sim.train_view("T1").cab.section == "IG"
    assert len(calls) < 30


def test_a_trolley_in_the_dead_zone_leaks_nothing_and_a_locomotive_does() -> None:
    sim = Simulation("gaotie")
    assert sim.command("train M1 at t-3r front=4577.5 kind=trolley dir=down").ok
    assert sim.fleet.leaking() == set()
    sim.run(0.5)
    assert sim.section_state("1-7DG") == "free" and sim.section_state("3-5DG") == "free"
    assert sim.command("train M1 remove").ok
    assert sim.command("train M2 at t-3r front=4585 kind=shunter dir=down").ok
    assert sim.fleet.leaking() == {"1-7DG"}
    states = []
    for _ in range(16):
        sim.step()
        states.append(sim.section_state("1-7DG"))
    assert states == (["occupied"] * 3 + ["free"] * 4 + ["occupied"] * 4 + ["free"] * 4 + ["occupied"])


def test_flicker_pattern_is_deterministic_in_simulated_time() -> None:
    f = Flicker(period_s=2.0, down_s=1.0)
    assert f.leak({"A"}, 10.0) == {"A"}
    assert [f.down("A", t) for t in (10.0, 10.75, 11.0, 11.75, 12.0, 13.5)] == [True, True, False, False, True, False]
    assert f.leak(set(), 14.0) == {"A"} and not f.down("A", 14.0)


def test_long_dead_zones_are_those_past_the_rule_sets_length() -> None:
    st = load("gaotie")
    rule = load_rules().design.dead_zone_long_m
    assert rule == 6.3
    zones = {z.joint: z for zs in long_dead_zones(st, rule).values() for z in zs}
    assert sorted(zones) == ["J-13", "J-57"]
    assert zones["J-13"].sections == ("1-7DG", "3-5DG") and zones["J-13"].other("3-5DG") == "1-7DG"
    assert long_dead_zones(st, 12.0) == {}


def test_cab_current_is_sent_from_the_end_the_train_runs_to() -> None:
    fld = Field(load("gaotie"))
    cc = CabCurrents()
    ig = fld.circuits["IG"]
    need = cc.model(ig, "upper").cab_min_mA
    for end in ("upper", "lower"):
        assert min(cc.profile(ig, end, 0.01)[1]) > need  # healthy: the code is read everywhere
    ig.faults.capacitors[6] = "short"  # capacitor 6 is 550 m from IG's lower end
    assert cc.at(ig, 100.0, "upper", 0.01) < need  # a down train behind the short loses the code
    assert cc.at(ig, 100.0, "lower", 0.01) > need  # an up train, fed from the lower end, does not

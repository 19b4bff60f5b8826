"""Every number of every command within its range (stations/limits.py): a number out of range is refused with the
range allowed, changes nothing, and the simulation keeps cycling after it (issue 17, item 2; docs/robustness.md)."""

from __future__ import annotations

from typing import Any

import pytest

from liansuo.circuits.faults import KINDS, PARAM_LIMITS
from liansuo.simulation.recording.recorder import snapshot
from liansuo.simulation.sim import Simulation


def state(sim: Simulation) -> dict[str, Any]:
    return {"t": sim.t, "relays": snapshot(sim), "routes": sim.view.routes(), "trains": sim.train_views(),
            "faults": sorted(sim.field.faults), "alarms": sim.alarm_texts()}


# (station, lines that set the scene, the line refused, what the refusal says)
REFUSED = [
    ("jiaopei", ["train T1 at 3G"], "drive T1 nan", "speed must be a finite number of km/h, not 'nan'"),
    ("jiaopei", [], "train T1 at IAG vmax=nan", "vmax must be a finite number, not 'nan'"),
    ("jiaopei", [], "train T1 at IAG vmax=1e308", "vmax must be above 0 and up to 400 km/h, not '1e308'"),
    ("jiaopei", [], "fault low-ballast 1DG ohm_km=0", "ohm_km must be above 0 ohm*km, not '0'"),
    ("jiaopei", [], "fault low-ballast 1DG ohm_km=1e-300", "ohm_km must be from 0.05 to 1000 ohm*km, not '1e-300'"),
    ("gaotie", [], "fault low-ballast IG ohm_km=1e-300", "ohm_km must be from 0.05 to 1000 ohm*km"),
    ("jiaopei", [], "train T1 at 1DG length=nan", "length must be a finite number, not 'nan'"),
    ("jiaopei", [], "train T1 at 1DG axles=inf", "axles must be a finite number, not 'inf'"),
    ("jiaopei", [], "train T1 at 1DG length=1e9", "length must be above 0 and up to 4000 m, not '1e9'"),
    ("jiaopei", [], "train T1 at 1DG axles=1e9", "axles must be a whole number from 2 to 1200, not '1e9'"),
    ("jiaopei", [], "train T1 at 1DG axles=2.5", "axles must be a whole number from 2 to 1200, not '2.5'"),
    ("jiaopei", [], "train T1 at 1DG back=nan", "back must be a finite number, not 'nan'"),
    ("jiaopei", [], "train T1 at 1DG back=1e308", "back must be above 0 and up to 200000 m, not '1e308'"),
    ("jiaopei", [], "fault broken-rail 1DG at=nan", "at must be a finite number, not 'nan'"),
    ("jiaopei", [], "fault broken-rail 1DG at=1e308", "at must be from 0 to 100 m, not '1e308'"),
    ("jiaopei", [], "fault broken-rail 1DG at=-5", "at must be from 0 to 100 m, not '-5'"),
    ("jiaopei", [], "fault poor-shunt 1DG ohm=1e308", "ohm must be from 0 to 1000 ohm, not '1e308'"),
    ("jiaopei", [], "fault obstruction 1 mm=1e308", "mm must be from 0 to 200 mm, not '1e308'"),
    ("jiaopei", [], "fault high-resistance 1 N=-1", "N must be from 0 to 100000 N, not '-1'"),
    ("gaotie", [], "fault capacitor IG n=99", "n must be a whole number from 1 to 7, not '99'"),
    ("gaotie", [], "fault capacitor IG n=1.5", "n must be a whole number from 1 to 7, not '1.5'"),
    ("gaotie", [], "fault capacitor 1-7DG n=1", "section 1-7DG has no compensation capacitors"),
    ("jiaopei", [], "run 168h", "a run must be from 0 to 3600 s, not '168h'"),
    ("jiaopei", [], "run " + "9" * 400 + "s", "a run must be from 0 to 3600 s"),
    ("jiaopei", ["train T1 at 3G"], "slip T1 0.3 2h", "the slip's duration must be above 0 and up to 3600 s"),
    ("jiaopei", ["train T1 at 3G"], "expect odometry T1 within nan", "the bound must be from 0 to 200000 m"),
]


@pytest.mark.parametrize(("station", "setup", "line", "said"), REFUSED, ids=[r[2][:40] for r in REFUSED])
def test_a_number_out_of_range_is_refused_and_changes_nothing(station: str, setup: list[str], line: str,
                                                              said: str) -> None:
    sim = Simulation(station)
    for s in [*setup, "route X XI", "run 2s"]:
        assert sim.command(s).ok, s
    before = state(sim)
    result = sim.command(line)
    assert not result.ok and said in result.message, result.message
    assert state(sim) == before
    sim.run(5)  # later cycles run: before, some of these crashed every cycle after them
    assert sim.t == before["t"] + 5


def test_run_allows_what_the_bundled_scripts_use_and_an_hour() -> None:
    sim = Simulation("jiaopei")
    for line in ("run 7min", "run 3600s", "run 1h", "run 250ms", "run 0"):
        assert sim.command(line).ok, line


def test_train_numbers_at_their_limits_are_accepted() -> None:
    sim = Simulation("jiaopei")
    assert sim.command("train T1 at IG length=4000 vmax=400").ok
    assert sim.command("train T2 at 3G axles=2 back=1").ok
    sim.run(2)


def test_every_numeric_fault_parameter_has_a_range() -> None:
    numeric = {p for k in KINDS.values() for p, default in k.params.items() if isinstance(default, float)}
    assert numeric - {"at"} <= set(PARAM_LIMITS)  # 'at' is bounded by its section


def test_a_scenario_until_past_a_day_is_refused(tmp_path: Any, capsys: pytest.CaptureFixture[str]) -> None:
    from liansuo.cli.main import main

    path = tmp_path / "long.yaml"
    path.write_text("station: jiaopei\nsteps:\n  - route X XI\nuntil: 9999999h\n", encoding="utf-8")
    code = main(["run", str(path)])
    err = capsys.readouterr().err
    assert code == 3 and "until must be from 0 to 86400 s, not '9999999h'" in err
    assert main(["run", "src/liansuo/examples/scenarios/jiaopei-receive-depart.yaml", "--until", "48h"]) == 2
    assert "--until must be from 0 to 86400 s, not '48h'" in capsys.readouterr().err

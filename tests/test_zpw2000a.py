"""ZPW-2000A transmission-line model: the figures of TB/T 3206 and 维规, the capacitor-fault trends of Luo Ying 2023
(docs/references.md), the vectorised sweep against single evaluations, hysteresis, faults, and ``liansuo zpw``."""

from __future__ import annotations

import csv
import json
import math
import re
from pathlib import Path

import numpy as np
import pytest

from liansuo.bench import report, zpw
from liansuo.circuits.zpw.adjust import station_warnings
from liansuo.circuits.zpw.model import (
    NO_FAULTS,
    ZpwCircuit,
    ZpwFaults,
    ZpwState,
    capacitor_positions,
    layout_params,
    section_circuit,
    standard_positions,
)
from liansuo.circuits.zpw.params import CARRIERS, DEFAULT_PARAMS, carrier_frequency_Hz
from liansuo.circuits.zpw.sweep import SweepResult, single_faults, sweep
from liansuo.cli.main import main
from liansuo.kit.jsonreport import version
from liansuo.stations.library import bundled
from liansuo.stations.loader import load, load_text

P = DEFAULT_PARAMS
# Luo Ying 2023 (docs/references.md) tables 1 (open) and 2 (-50 %), over every carrier: the largest fall / rise in
# percent.
PAPER_ADJUSTMENT_FALL = {"open": (11.6, 23.8, 18.9, 20.3), "half": (4.0, 9.0, 8.0, 9.3)}  # 客专, 普速, 站内 x2
PAPER_CAB_FALL = {"open": (19.3, 24.5, 21.5, 38.4), "half": (4.1, 0.6, 4.6, 38.4)}
PAPER_RESIDUAL_RISE = {"open": (30.3, 31.7, 41.7, 26.0), "half": (15.3, 19.0, 26.6, 17.6)}


@pytest.fixture(scope="module")
def long_line() -> SweepResult:
    """Luo Ying's open-line case: 1400 m, every carrier, design ballast, every single capacitor fault."""
    return sweep([1400.0])[0]


@pytest.fixture(scope="module")
def station_track() -> SweepResult:
    """Luo Ying's station case: 650 m."""
    return sweep([650.0])[0]


def changes(result: SweepResult, mode: str, figure: str) -> np.ndarray:
    """Per carrier and fault case of ``mode``: relative change (%) of a figure against no fault."""
    values = {"adjustment": result.adjustment_mV, "residual": result.max_shunt_residual_mV,
              "cab": result.min_cab_current_mA}[figure][:, 0]
    cases = [k for k, f in enumerate(result.faults) if f and next(iter(f.values())) == mode]
    return np.asarray((values[:, cases] / values[:, :1] - 1.0) * 100.0)


def cab(circuit: ZpwCircuit, x: float, faults: ZpwFaults | None = None) -> float:
    """Cab current (mA) with the standard shunt at ``x``."""
    current = circuit.evaluate([(x, P.standard_shunt_ohm)], faults).cab_current_mA
    assert current is not None
    return current


# ---- standard figures and the station ------------------------------------------------------------------------------
def test_carriers_and_capacitor_layout() -> None:
    assert carrier_frequency_Hz("1700-1") == pytest.approx(1701.4)
    assert carrier_frequency_Hz("2600-2") == pytest.approx(2598.7)
    with pytest.raises(ValueError, match="carrier"):
        carrier_frequency_Hz("1800-1")
    assert standard_positions(300.0) == []  # only sections over 300 m
    assert standard_positions(1400.0) == [50.0 + 100.0 * k for k in range(14)]  # half spacing at the ends
    assert standard_positions(1010.0) == pytest.approx([(k + 0.5) * 1010 / 11 for k in range(11)])
    assert standard_positions(600.0, count=4) == [75.0, 225.0, 375.0, 525.0]


def test_capacitor_positions_from_the_station_file() -> None:
    station = load("gaotie")  # a passenger-dedicated line: X2JG (2300 Hz, on the line) has one every 80 m
    assert capacitor_positions(station, "X2JG") == standard_positions(1400.0, count=18)
    assert capacitor_positions(station, "X2JG") == standard_positions(1400.0, params=layout_params(
        "passenger-line", "2300-1"))
    assert capacitor_positions(station, "1-7DG") == []  # no capacitors described
    text = Path(bundled()["gaotie"]).read_text(encoding="utf-8")
    text = re.sub(r"(\{id: X2JG,[^\n]*?capacitors: )\{rule: standard\}", r"\1{count: 10, capacitance_uF: 50}", text)
    text = re.sub(r"(\{id: IG,[^\n]*?capacitors: )\{rule: standard\}", r"\1{positions: [500, 100, 300]}", text)
    edited = load_text(text, "<gaotie edited>")
    assert capacitor_positions(edited, "X2JG") == standard_positions(1400.0, count=10)
    assert capacitor_positions(edited, "IG") == [100.0, 300.0, 500.0]
    circuit = section_circuit(edited, "X2JG")
    assert circuit.capacitance_uF == 50 and len(circuit.capacitors_m) == 10


@pytest.mark.parametrize("section", [s.id for s in load("gaotie").model.sections])
def test_every_gaotie_section_meets_the_design_figures(section: str) -> None:
    station = load("gaotie")
    circuit = section_circuit(station, section)
    assert circuit.adjustment().voltage_mV >= P.pickup_mV
    assert circuit.adjustment().relay_up
    assert circuit.max_shunt_residual_mV() < P.drop_mV  # 0.15 ohm anywhere drops the relay
    if circuit.min_cab_current_mA() < circuit.cab_min_mA:  # 500 mA (450 mA at 2600 Hz)
        # longer than level 1 feeds through 10 km of cable at 1 ohm*km: `liansuo check` says so
        assert station.section_length(section) >= 1500.0
        assert any(f"'{section}'" in d.message and "longer than its transmitter feeds" in d.message
                   for d in station_warnings(station))
    if station.section_length(section) > P.capacitor_min_section_m:
        assert circuit.capacitors_m


def test_a_train_anywhere_drops_the_relay_and_the_cab_reads_the_leading_wheelset() -> None:
    circuit = ZpwCircuit(1400.0, "2600-1", standard_positions(1400.0))
    assert circuit.evaluate().cab_current_mA is None
    for x in np.linspace(0.0, 1400.0, 57):
        state = circuit.evaluate([(float(x), 0.15)])
        assert not state.relay_up and not state.relay_up_after(True)
    # a 16-car train: wheelsets every 2.5 m from 600 m to 760 m; the cab reads the one nearest the transmitter
    train = [(600.0 + 2.5 * k, 0.15) for k in range(65)]
    lead = circuit.evaluate([(760.0, 0.15)]).cab_current_mA
    state = circuit.evaluate(train)
    assert state.cab_current_mA == pytest.approx(lead, rel=0.05)  # the axles behind add a little load
    assert circuit.evaluate(train[::-1]).cab_current_mA == state.cab_current_mA  # order does not matter
    # the cab current grows towards the transmitter (upper end)
    assert cab(circuit, 1350.0) > 3 * cab(circuit, 50.0)
    assert circuit.evaluate([(-5.0, 0.15), (1405.0, 0.15)]) == circuit.adjustment()  # outside the section


def test_transmitter_at_the_lower_end_mirrors_the_section() -> None:
    caps = [120.0, 400.0, 700.0, 950.0]
    upper = ZpwCircuit(1000.0, "2000-2", caps)
    lower = ZpwCircuit(1000.0, "2000-2", [1000.0 - x for x in caps], transmitter_end="lower")
    for x in (0.0, 130.0, 560.0, 1000.0):
        a, b = upper.evaluate([(x, 0.15)]), lower.evaluate([(1000.0 - x, 0.15)])
        assert a.voltage_mV == pytest.approx(b.voltage_mV) and a.cab_current_mA == pytest.approx(b.cab_current_mA)
    assert upper.adjustment(ZpwFaults(capacitors={1: "open"})).voltage_mV == pytest.approx(
        lower.adjustment(ZpwFaults(capacitors={4: "open"})).voltage_mV)


# ---- Luo Ying's capacitor-fault trends ---------------------------------------------------------------------------
def test_open_capacitor_lowers_the_adjustment_like_the_paper(long_line: SweepResult) -> None:
    fall = -changes(long_line, "open", "adjustment")
    assert (fall > 0).all()  # open line: the adjustment voltage only falls (Luo Ying: 客专 and 普速 columns)
    assert min(PAPER_ADJUSTMENT_FALL["open"][:2]) - 2 <= fall.max() <= max(PAPER_ADJUSTMENT_FALL["open"]) + 5
    assert fall.min() < 10.0  # some capacitors matter much less than others


def test_half_capacitance_is_the_same_trend_but_milder(long_line: SweepResult) -> None:
    half, open_ = -changes(long_line, "half", "adjustment"), -changes(long_line, "open", "adjustment")
    assert half.min() > -5.0 and half.max() < open_.max()  # falls; a rise of a few percent at most (客专: 有升有降)
    assert 2.0 <= half.max() <= max(PAPER_ADJUSTMENT_FALL["half"]) + 3
    assert np.abs(changes(long_line, "half", "cab")).max() < np.abs(changes(long_line, "open", "cab")).max()


def test_shunt_residual_moves_but_stays_under_the_drop_threshold(long_line: SweepResult,
                                                                station_track: SweepResult) -> None:
    for result in (long_line, station_track):
        healthy = [k for k, f in enumerate(result.faults) if not f or next(iter(f.values())) != "short"]
        assert result.max_shunt_residual_mV[:, :, healthy].max() < P.drop_mV  # Luo Ying: all under 153 mV
        for mode in ("open", "half"):
            change = changes(result, mode, "residual")
            assert change.max() <= max(PAPER_RESIDUAL_RISE[mode]) + 5
            assert change.min() >= -40.0


def test_cab_current_changes_by_tens_of_percent(long_line: SweepResult, station_track: SweepResult) -> None:
    for result in (long_line, station_track):
        change = changes(result, "open", "cab")
        assert min(PAPER_CAB_FALL["open"]) - 5 <= np.abs(change).max() <= max(PAPER_CAB_FALL["open"]) + 7
        assert change.min() < -15.0


def test_station_track_adjustment_falls_like_the_paper(station_track: SweepResult) -> None:
    fall = -changes(station_track, "open", "adjustment")
    assert 10.0 <= fall.max() <= max(PAPER_ADJUSTMENT_FALL["open"][2:]) + 5
    assert -changes(station_track, "half", "adjustment").max() <= max(PAPER_ADJUSTMENT_FALL["half"][2:]) + 2


def test_a_shorted_capacitor_is_a_red_band(long_line: SweepResult) -> None:
    shorts = [k for k, f in enumerate(long_line.faults) if f and next(iter(f.values())) == "short"]
    assert len(shorts) == 14
    assert long_line.adjustment_mV[:, :, shorts].max() < P.drop_mV
    circuit = ZpwCircuit(1400.0, "1700-1", standard_positions(1400.0))
    for k in range(1, 15):
        assert not circuit.adjustment(ZpwFaults(capacitors={k: "short"})).relay_up_after(True)


# ---- vectorised sweep == one evaluation at a time ------------------------------------------------------------------
def test_sweep_equals_single_evaluations() -> None:
    ballasts = (1.0, 2.5, math.inf)
    result = sweep([900.0], carriers=("1700-2", "2300-1", "2600-1"), ballasts=ballasts)[0]
    assert result.adjustment_mV.shape == (3, 3, 1 + 3 * 9)
    assert result.residual_mV.shape == (3, 3, 28, len(result.positions_m))
    assert result.configurations == 3 * 3 * 28 * len(result.positions_m)
    rng = np.random.default_rng(4)
    for _ in range(60):
        c, b, f, p = (int(rng.integers(n)) for n in result.residual_mV.shape)
        circuit = ZpwCircuit(900.0, result.carriers[c], result.capacitors_m)
        faults = ZpwFaults(capacitors=dict(result.faults[f]), ballast_ohm_km=ballasts[b])
        assert circuit.adjustment(faults).voltage_mV == pytest.approx(result.adjustment_mV[c, b, f], rel=1e-9)
        state = circuit.evaluate([(float(result.positions_m[p]), P.standard_shunt_ohm)], faults)
        assert state.voltage_mV == pytest.approx(result.residual_mV[c, b, f, p], rel=1e-9)
        assert state.cab_current_mA == pytest.approx(result.cab_current_mA[c, b, f, p], rel=1e-9)


@pytest.mark.parametrize("faults", [NO_FAULTS, ZpwFaults(broken_rail_at_m=333.0), ZpwFaults(insulation_short=True),
                                    ZpwFaults(capacitors={2: "half", 5: "open"}, ballast_ohm_km=3.0)])
def test_profile_equals_single_evaluations(faults: ZpwFaults) -> None:
    circuit = ZpwCircuit(800.0, "2000-1", standard_positions(800.0))
    positions, residual, cab = circuit.profile(faults)
    for x, v, i in zip(positions, residual, cab, strict=True):
        state = circuit.evaluate([(float(x), 0.15)], faults)
        assert state.voltage_mV == pytest.approx(v, rel=1e-9, abs=1e-9)
        assert state.cab_current_mA == pytest.approx(i, rel=1e-9, abs=1e-9)


def test_single_faults_and_bad_faults() -> None:
    assert single_faults(2) == [{}, {1: "open"}, {2: "open"}, {1: "half"}, {2: "half"}, {1: "short"}, {2: "short"}]
    circuit = ZpwCircuit(700.0, "2300-2", standard_positions(700.0))
    with pytest.raises(ValueError, match="capacitor 8 does not exist"):
        circuit.evaluate([], ZpwFaults(capacitors={8: "open"}))
    with pytest.raises(ValueError, match="open, half or short"):
        circuit.evaluate([], ZpwFaults(capacitors={1: "gone"}))
    with pytest.raises(ValueError, match="within the section"):
        ZpwCircuit(200.0, "2300-2", [250.0])


# ---- relay, hysteresis and other faults ---------------------------------------------------------------------------
def test_hysteresis() -> None:
    between = ZpwState(voltage_mV=180.0, cab_current_mA=None, pickup_mV=210.0, drop_mV=153.0)
    assert not between.relay_up
    assert between.relay_up_after(True) and not between.relay_up_after(False)
    assert ZpwState(210.0, None, 210.0, 153.0).relay_up_after(False)
    assert not ZpwState(152.9, None, 210.0, 153.0).relay_up_after(True)


def test_open_capacitor_leaves_the_relay_up_until_the_first_train() -> None:
    """2300 Hz, 1400 m, capacitor 3 open: about 190 mV, between drop and pick-up: an up relay holds, but once a
    train has dropped it, it does not pick up again (red band behind the train)."""
    circuit = ZpwCircuit(1400.0, "2300-1", standard_positions(1400.0))
    fault = ZpwFaults(capacitors={3: "open"})
    assert P.drop_mV < circuit.adjustment(fault).voltage_mV < P.pickup_mV
    up = False  # the relay starts down (fail-safe); each evaluation decides from the previous state
    for shunts, faults, then in (([], None, True),  # picks up
                                  ([], fault, True),  # the fault alone does not drop it
                                  ([(700.0, 0.15)], fault, False),
                                  ([], fault, False),  # the train has gone: still down
                                  ([], None, True)):  # capacitor replaced
        up = circuit.evaluate(shunts, faults).relay_up_after(up)
        assert up is then


def test_broken_rail_insulation_short_and_ballast() -> None:
    circuit = ZpwCircuit(1400.0, "1700-1", standard_positions(1400.0))
    assert not circuit.adjustment(ZpwFaults(broken_rail_at_m=612.0)).relay_up_after(True)
    assert not circuit.adjustment(ZpwFaults(insulation_short=True)).relay_up_after(True)
    wet = circuit.adjustment(ZpwFaults(ballast_ohm_km=0.6)).voltage_mV
    dry = circuit.adjustment(ZpwFaults(ballast_ohm_km=5.0)).voltage_mV
    assert wet < P.adjust_mV < dry  # adjusted at the design 1.0 ohm*km
    # a train beyond the break (towards the transmitter) still gets the cab signal; one behind it does not
    broken = ZpwFaults(broken_rail_at_m=612.0)
    assert cab(circuit, 900.0, broken) > 500.0
    assert cab(circuit, 300.0, broken) < 1.0
    for faults in (broken, ZpwFaults(broken_rail_at_m=1312.0, capacitors={14: "half"})):  # no train = open shunt
        assert circuit.adjustment(faults).voltage_mV == pytest.approx(
            circuit.evaluate([(400.0, 1e15)], faults).voltage_mV, rel=1e-9)
    # a poor shunt (rusty rail) leaves more voltage than the standard shunt
    assert circuit.evaluate([(700.0, 0.5)]).voltage_mV > circuit.evaluate([(700.0, 0.15)]).voltage_mV


# ---- liansuo zpw ---------------------------------------------------------------------------------------------------
def test_cli_text(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["zpw", "gaotie"]) == 0
    out = capsys.readouterr().out
    assert "X2JG" in out and "2300-1" in out and "adjust_mV" in out and "min_cab_mA" in out
    rows = [line for line in out.splitlines() if line.split()[0] in load("gaotie").sections]
    assert len(rows) == len(load("gaotie").sections)


def test_cli_json_with_faults(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["zpw", "gaotie", "--format", "json", "--fault", "X2JG:capacitor:3:open",
                 "--fault", "S2LQG:capacitor:1:short"]) == 0
    report = json.loads(capsys.readouterr().out)
    assert report["station"] == "gaotie"
    rows = {r["id"]: r for r in report["sections"]}
    assert set(rows) == set(load("gaotie").sections)
    x2 = rows["X2JG"]
    assert x2["fault"] == "C3 open" and x2["capacitors"] == 18 and x2["length_m"] == 1400.0
    assert x2["adjustment_mV"] < x2["healthy"]["adjustment_mV"]
    assert rows["S2LQG"]["relay"] == "down" and rows["S2LQG"]["fault"] == "C1 short"
    assert rows["IAG"]["fault"] is None and rows["IAG"]["relay"] == "up" and "healthy" not in rows["IAG"]


def test_cli_csv(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    """``--format csv`` as ``table`` spells it: on stdout, or in the file ``-o`` names."""
    target = tmp_path / "zpw.csv"
    assert main(["zpw", "gaotie", "--format", "csv", "-o", str(target), "--fault", "IG:capacitor:7:half"]) == 0
    assert capsys.readouterr().out == f"wrote {target}\n"
    assert main(["zpw", "gaotie", "--format", "csv", "--fault", "IG:capacitor:7:half"]) == 0
    assert capsys.readouterr().out == target.read_bytes().decode("utf-8")
    with target.open(encoding="utf-8") as f:
        rows = list(csv.DictReader(f))
    assert len(rows) == len(load("gaotie").sections)
    assert {"id", "carrier", "length_m", "capacitors", "adjustment_mV", "max_shunt_residual_mV",
            "min_cab_current_mA"} <= set(rows[0])
    assert next(r for r in rows if r["id"] == "IG")["fault"] == "C7 half"


@pytest.mark.parametrize(("spec", "message"), [
    ("X2JG:cap:3:open", "SECTION:capacitor:N"), ("X2JG:capacitor:19:open", "capacitors 1-18"),
    ("X2JG:capacitor:2:melted", "open, half or short"), ("NOPE:capacitor:1:open", "no section 'NOPE'"),
    ("1-7DG:capacitor:1:open", "no compensation capacitors"), ("X2JG:capacitor:x:open", "whole number"),
])
def test_cli_bad_fault(spec: str, message: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["zpw", "gaotie", "--fault", spec]) == 2
    captured = capsys.readouterr()
    assert captured.out == "" and message in captured.err
    assert len(captured.err.strip().splitlines()) == 1 and "Traceback" not in captured.err


def test_cli_station_without_zpw_sections(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["zpw", "jiaopei"]) == 0
    assert "no ZPW-2000A sections" in capsys.readouterr().out
    assert main(["zpw", "jiaopei", "--format", "json"]) == 0
    assert json.loads(capsys.readouterr().out) == {"liansuo": version(), "schema": 1, "ok": True,
                                                   "station": "jiaopei", "sections": []}
    assert main(["zpw", "jiaopei", "--fault", "IG:capacitor:1:open"]) == 2
    assert "not a ZPW-2000A section" in capsys.readouterr().err


# ---- the benchmark figure ------------------------------------------------------------------------------------------
def test_bench_reports_zpw_configs_per_s() -> None:
    figure = zpw.measure_zpw(repeats=1)
    assert figure["configurations"] == len(CARRIERS) * len(zpw.ZPW_BALLASTS) * 43 * 141
    assert figure["zpw_configs_per_s"] > 0 and math.isfinite(figure["zpw_configs_per_s"])
    rep = report.run_bench(report.Sizes.tiny(), stations=())
    assert rep["zpw"]["zpw_configs_per_s"] > 0
    assert any(t["figure"] == "zpw_configs_per_s" for t in rep["targets"])
    assert "zpw configs/s" in report.as_text(rep)

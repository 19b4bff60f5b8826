"""The ZPW-2000A adjustment table (circuits/zpw/adjust.py): the stored table is the model's, every bundled section
adjusted by it detects a standard-shunted train over the design ballast range or `liansuo check` warns for it, and
the live circuits and `liansuo zpw` apply it (issue 15, item 3)."""

from __future__ import annotations

import itertools
import json
import math
from pathlib import Path

import pytest

from liansuo.circuits.cabcurrent import CabCurrents
from liansuo.circuits.trackcircuits import build_circuit
from liansuo.circuits.zpw.adjust import (
    adjusted_circuit,
    check_circuit,
    derive_row,
    load_table,
    section_circuit,
    station_verdicts,
    table,
)
from liansuo.circuits.zpw.model import LAYOUTS, ZpwFaults, layout_params, standard_positions
from liansuo.circuits.zpw.sweep import sweep_section
from liansuo.cli.main import main
from liansuo.stations.library import bundled
from liansuo.stations.loader import load


def test_stored_table_is_the_models() -> None:
    """The YAML rows are what the model gives for its settings (rebuild with python -m liansuo.circuits.zpw.adjust):
    every layout and carrier, at a short, a middle, the article's and the longest band (the whole table takes a
    minute to derive)."""
    stored = load_table()
    for row in stored.rows:
        if row.to_m in (350.0, 1000.0, 1400.0, 2000.0):
            assert derive_row(stored, row.layout, row.cable_km, row.carrier, row.from_m, row.to_m) == row


def test_table_rows_cover_every_carrier_and_length() -> None:
    t = table()
    for layout, base in itertools.product(LAYOUTS, ("1700", "2000", "2300", "2600")):
        rows = [r for r in t.rows if r.carrier == base and r.layout == layout]
        assert rows[0].from_m == 0 and rows[-1].to_m == t.max_length_m
        assert all(a.to_m == b.from_m for a, b in itertools.pairwise(rows))
        assert all(1 <= r.level <= 5 and r.adjust_mV >= t.adjust_floor_mV for r in rows)
        # short sections need less transmitter output than long ones
        assert rows[0].level >= rows[-1].level
    assert t.ballasts(1.0)[0] == 1.0 and math.isinf(t.ballasts_ohm_km[-1])
    assert t.ballasts(2.0) == (2.0, 3.0, 5.0, 10.0, 20.0, 50.0, 100.0, 1000.0, math.inf)


def _sweep_figures(length_m: float, carrier: str, layout: str = "conventional") -> tuple[float, float, float]:
    """(healthy adjustment at the design minimum, worst residual healthy, worst residual with single faults) of a
    standard section of ``layout`` adjusted by the table, by an independent sweep over its design ballast range."""
    figures = layout_params(layout, carrier)
    c = adjusted_circuit(length_m, carrier, standard_positions(length_m, params=figures), layout=layout)
    res = sweep_section(length_m, c.capacitors_m, [carrier], table().ballasts(figures.ballast_ohm_km),
                        params=c.params)
    worst = res.max_shunt_residual_mV[0]  # (B, F)
    return float(res.adjustment_mV[0, 0, 0]), float(worst[:, 0].max()), float(worst.max())


@pytest.mark.parametrize("name", sorted(bundled()))
def test_bundled_sections_detect_a_train_or_check_warns(name: str, capsys: pytest.CaptureFixture[str]) -> None:
    """Over the design ballast range, every ZPW-2000A section adjusted by the table picks up at the design minimum
    and leaves <= 153 mV under a 0.15 ohm shunt, healthy and with any one capacitor fault; where the physics cannot,
    `liansuo check` names the section with its figures."""
    station = load(name)
    assert main(["check", name, "--format", "json"]) == 0
    warnings = json.loads(capsys.readouterr().out)["warnings"]
    warned = {w["message"].split("'")[1] for w in warnings if "cannot be adjusted over the design ballast" in
              w["message"]}
    for v in station_verdicts(station):
        c = section_circuit(station, v.section)
        res = sweep_section(c.length_m, c.capacitors_m, [c.carrier], table().ballasts(c.params.ballast_ohm_km),
                            params=c.params, capacitance_uF=c.capacitance_uF)
        worst = res.max_shunt_residual_mV[0]
        assert worst[:, 0].max() <= c.params.drop_mV, v.section  # healthy: always detected
        assert res.adjustment_mV[0, 0, 0] >= c.params.pickup_mV, v.section
        if worst.max() > c.params.drop_mV:
            assert v.section in warned and not v.ok
        else:
            assert v.ok and v.section not in warned


def test_adjustable_rows_hold_over_the_ballast_range() -> None:
    """For lengths the table calls adjustable, an independent sweep finds pick-up at the layout's design minimum and
    <= 153 mV everywhere, with every single capacitor fault (checked at each row's longest length; every row of the
    conventional layout, every other one of the passenger-dedicated line's)."""
    t = table()
    for row in t.rows:
        if row.to_m < 300 or (row.layout != "conventional" and row.to_m % 100):
            continue
        carrier = f"{row.carrier}-1"
        adjust, _healthy, faulted = _sweep_figures(row.to_m, carrier, row.layout)
        assert adjust == pytest.approx(row.adjust_mV)
        if row.adjustable:
            assert adjust >= 210.0 and faulted <= 153.0, row


def test_generated_long_section_cannot_be_adjusted() -> None:
    """A generated 1900 m 2600 Hz section: no setting both picks up and detects; the verdict says so with figures."""
    v = check_circuit(adjusted_circuit(1900.0, "2600-1", standard_positions(1900.0)), "LONG")
    assert not v.ok and v.worst_residual_mV > 153.0 and v.adjustment_mV >= 210.0
    assert math.isinf(v.worst_ballast_ohm_km) and "open" in v.worst_fault


def _conventional_gaotie(tmp_path: Path) -> Path:
    """gaotie with its sections on a conventional line (普速 figures: 1 ohm*km, 100 m capacitors), line for line."""
    text = (bundled()["gaotie"]).read_text(encoding="utf-8").replace("line_class: passenger, ", "")
    path = tmp_path / "gaotie-conventional.yaml"
    path.write_text(text, encoding="utf-8")
    return path


def test_check_warns_for_a_section_that_cannot_be_adjusted(tmp_path: Path,
                                                          capsys: pytest.CaptureFixture[str]) -> None:
    """On a conventional line S2LQG (2600-1, 1400 m) cannot be adjusted over 1 ohm*km to dry with one capacitor
    open: warned at its line in the file, with the figures; exit 0."""
    path = _conventional_gaotie(tmp_path)
    assert main(["check", str(path), "--format", "json"]) == 0
    warnings = json.loads(capsys.readouterr().out)["warnings"]
    w = next(w for w in warnings if "'S2LQG'" in w["message"] and "cannot be adjusted" in w["message"])
    assert w["file"].endswith("gaotie-conventional.yaml") and w["line"] == 166 and w["column"] == 5
    assert w["severity"] == "warning"
    assert w["message"].startswith("ZPW-2000A section 'S2LQG' (2600-1, 1400 m) cannot be adjusted over the design "
                                   "ballast range: set to 215 mV at 1 ohm*km (pick-up 210 mV), a 0.15 ohm shunt "
                                   "leaves up to 178 mV (drop 153 mV) in dry ballast (infinite resistance) with C6 "
                                   "open")
    assert main(["check", str(path)]) == 0
    assert "warning: ZPW-2000A section 'S2LQG'" in " ".join(capsys.readouterr().out.split())  # lines wrap


def test_a_passenger_dedicated_line_is_adjusted_with_its_own_figures(tmp_path: Path,
                                                                      capsys: pytest.CaptureFixture[str]) -> None:
    """The same sections as 客专 (gaotie as shipped): from 2 ohm*km, 25 uF every 60 m (1700 / 2000 Hz) or 80 m
    (2300 / 2600 Hz) on the line and every 100 m in the station; the table adjusts every one to 240 mV, and an
    independent sweep finds each within 153 mV with any one capacitor fault, over 2 ohm*km to dry."""
    station = load("gaotie")
    s2 = section_circuit(station, "S2LQG")
    assert s2.params.ballast_ohm_km == 2.0 and len(s2.capacitors_m) == 18 and s2.capacitance_uF is None
    assert s2.params.capacitance_uF == (25.0,) * 4
    assert len(section_circuit(station, "X2LQG").capacitors_m) == 24  # 1700 Hz: every 60 m
    assert len(section_circuit(station, "IG").capacitors_m) == 7  # in the station: every 100 m
    for v in station_verdicts(station):
        assert v.ok and v.feeds_cab and v.adjustment_mV == pytest.approx(240.0), v
    cabs = CabCurrents()  # what a train's cab reads: a clean wheelset anywhere, either direction, keeps the code
    for v in station_verdicts(station):
        live = build_circuit(station, v.section, station.section_length(v.section))
        for end in ("upper", "lower"):
            assert min(cabs.profile(live, end, 0.01)[1]) >= v.cab_min_mA, (v.section, end)
    assert main(["check", "gaotie"]) == 0
    out = capsys.readouterr().out
    assert "cannot be adjusted" not in out and "longer than its transmitter feeds" not in out
    conventional = load(_conventional_gaotie(tmp_path))
    unadjustable = {v.section for v in station_verdicts(conventional) if not v.ok}
    assert unadjustable == {"IAG", "X2LQG", "IIAG", "S2JG", "X2JG", "X3LQG", "S2LQG", "S3JG", "X1LQG", "X3JG",
                            "S1LQG", "S3LQG"}


def test_a_line_class_belongs_to_zpw_sections(capsys: pytest.CaptureFixture[str]) -> None:
    text = (bundled()["jiaopei"]).read_text(encoding="utf-8")
    first = next(line for line in text.splitlines() if "type: 25hz" in line)
    edited = text.replace(first, first.replace("type: 25hz", "type: 25hz, line_class: passenger"), 1)
    from liansuo.stations.loader import StationError, load_text

    with pytest.raises(StationError) as err:
        load_text(edited, "edited.yaml")
    assert "a line class belongs to ZPW-2000A sections" in str(err.value)


def test_live_circuit_applies_the_table() -> None:
    """build_circuit adjusts a section as the table says for its layout: X3JG (1600 m, passenger-dedicated line) at
    the row's setting and transmitter level, so a standard shunt drops the relay even in dry ballast."""
    station = load("gaotie")
    live = build_circuit(station, "X3JG", station.section_length("X3JG"))
    model = live.model
    row = table().row("1700-1", 1600.0, layout="passenger-line")
    assert model.adjustment().voltage_mV == pytest.approx(row.adjust_mV)  # type: ignore[attr-defined]
    assert model.params.transmitter_V == model.params.transmitter_levels_V[row.level - 1]  # type: ignore[attr-defined]
    assert model.params.ballast_ohm_km == 2.0  # type: ignore[attr-defined]
    dry = ZpwFaults(ballast_ohm_km=math.inf)
    for x in (0.0, 400.0, 800.0, 1200.0, 1600.0):
        assert model.evaluate([(x, 0.15)], dry).voltage_mV < 153.0  # type: ignore[attr-defined]


def test_zpw_command_prints_the_tables_settings(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["zpw", "gaotie", "--format", "json"]) == 0
    rows = {r["id"]: r for r in json.loads(capsys.readouterr().out)["sections"]}
    assert rows["X3JG"]["adjustment_mV"] == table().row("1700-1", 1600.0, layout="passenger-line").adjust_mV
    assert rows["IG"]["adjustment_mV"] == table().row("2300-1", 700.0, layout="passenger-station").adjust_mV
    assert {r["ballast_ohm_km"] for r in rows.values()} == {2.0}
    assert all(r["min_cab_current_mA"] >= r["cab_min_mA"] for r in rows.values())
    # the same sections on a conventional line: the three longest are longer than level 1 feeds (check warns)
    path = _conventional_gaotie(tmp_path)
    assert main(["zpw", str(path), "--format", "json"]) == 0
    rows = {r["id"]: r for r in json.loads(capsys.readouterr().out)["sections"]}
    assert rows["X3JG"]["adjustment_mV"] == table().row("1700-1", 1600.0).adjust_mV
    short = {k for k, r in rows.items() if r["min_cab_current_mA"] < r["cab_min_mA"]}
    assert short == {"X3JG", "S3LQG", "S1LQG"}  # 1500-1600 m
    conventional = load(path)
    assert all(v.level == 1 and not v.feeds_cab for v in station_verdicts(conventional) if v.section in short)


def test_station_without_zpw_has_no_such_warning(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", "jiaopei"]) == 0
    assert "cannot be adjusted" not in capsys.readouterr().out

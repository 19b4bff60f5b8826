"""The ZPW-2000A adjustment table (circuits/zpwadjust.py): the stored table is the model's, every bundled section
adjusted by it detects a standard-shunted train over the design ballast range or `liansuo check` warns for it, and
the live circuits and `liansuo zpw` apply it (issue 15, item 3)."""

from __future__ import annotations

import itertools
import json
import math

import pytest

from liansuo.circuits.trackcircuits import build_circuit
from liansuo.circuits.zpw2000a import ZpwFaults, standard_positions, sweep_section
from liansuo.circuits.zpwadjust import (
    adjusted_circuit,
    check_circuit,
    derive_table,
    load_table,
    section_circuit,
    station_verdicts,
    table,
)
from liansuo.cli.main import main
from liansuo.stations.library import bundled
from liansuo.stations.loader import load


def test_stored_table_is_the_models() -> None:
    """The YAML rows are what derive_table gives for its settings: rebuild with python -m liansuo.circuits.zpwadjust."""
    assert load_table().rows == derive_table().rows


def test_table_rows_cover_every_carrier_and_length() -> None:
    t = table()
    for base in ("1700", "2000", "2300", "2600"):
        rows = [r for r in t.rows if r.carrier == base]
        assert rows[0].from_m == 0 and rows[-1].to_m == t.max_length_m
        assert all(a.to_m == b.from_m for a, b in itertools.pairwise(rows))
        assert all(1 <= r.level <= 5 and r.adjust_mV >= t.adjust_floor_mV for r in rows)
        # short sections need less transmitter output than long ones
        assert rows[0].level >= rows[-1].level
    assert t.ballast_min_ohm_km == 1.0 and math.isinf(t.ballasts_ohm_km[-1])


def _sweep_figures(length_m: float, carrier: str) -> tuple[float, float, float]:
    """(healthy adjustment at the design minimum, worst residual healthy, worst residual with single faults) of a
    standard section adjusted by the table, by an independent sweep over the design ballast range."""
    c = adjusted_circuit(length_m, carrier, standard_positions(length_m))
    res = sweep_section(length_m, c.capacitors_m, [carrier], table().ballasts_ohm_km, params=c.params)
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
        res = sweep_section(c.length_m, c.capacitors_m, [c.carrier], table().ballasts_ohm_km, params=c.params,
                            capacitance_uF=c.capacitance_uF)
        worst = res.max_shunt_residual_mV[0]
        assert worst[:, 0].max() <= c.params.drop_mV, v.section  # healthy: always detected
        assert res.adjustment_mV[0, 0, 0] >= c.params.pickup_mV, v.section
        if worst.max() > c.params.drop_mV:
            assert v.section in warned and not v.ok
        else:
            assert v.ok and v.section not in warned


def test_adjustable_rows_hold_over_the_ballast_range() -> None:
    """For lengths the table calls adjustable, an independent sweep finds pick-up at 1 ohm*km and <= 153 mV
    everywhere, with every single capacitor fault (checked at each row's longest length)."""
    t = table()
    for row in t.rows:
        if row.to_m < 300:
            continue
        carrier = f"{row.carrier}-1"
        adjust, _healthy, faulted = _sweep_figures(row.to_m, carrier)
        assert adjust == pytest.approx(row.adjust_mV)
        if row.adjustable:
            assert adjust >= 210.0 and faulted <= 153.0, row


def test_generated_long_section_cannot_be_adjusted() -> None:
    """A generated 1900 m 2600 Hz section: no setting both picks up and detects; the verdict says so with figures."""
    v = check_circuit(adjusted_circuit(1900.0, "2600-1", standard_positions(1900.0)), "LONG")
    assert not v.ok and v.worst_residual_mV > 153.0 and v.adjustment_mV >= 210.0
    assert math.isinf(v.worst_ballast_ohm_km) and "open" in v.worst_fault


def test_check_warns_for_a_section_that_cannot_be_adjusted(capsys: pytest.CaptureFixture[str]) -> None:
    """`liansuo check gaotie`: S2LQG (2600-1, 1400 m) warned at its line in the file, with the figures; exit 0."""
    assert main(["check", "gaotie", "--format", "json"]) == 0
    warnings = json.loads(capsys.readouterr().out)["warnings"]
    w = next(w for w in warnings if "'S2LQG'" in w["message"])
    assert w["file"].endswith("gaotie.yaml") and w["line"] == 166 and w["column"] == 5
    assert w["severity"] == "warning"
    assert w["message"].startswith("ZPW-2000A section 'S2LQG' (2600-1, 1400 m) cannot be adjusted over the design "
                                   "ballast range: set to 215 mV at 1 ohm*km (pick-up 210 mV), a 0.15 ohm shunt "
                                   "leaves up to 178 mV (drop 153 mV) in dry ballast (infinite resistance) with C6 "
                                   "open")
    assert main(["check", "gaotie"]) == 0
    assert "warning: ZPW-2000A section 'S2LQG'" in capsys.readouterr().out


def test_live_circuit_applies_the_table() -> None:
    """build_circuit adjusts a section as the table says: 215 mV on X3JG (1600 m) instead of a fixed 240 mV, so a
    standard shunt drops the relay even in dry ballast, and the transmitter level comes from the table."""
    station = load("gaotie")
    live = build_circuit(station, "X3JG", station.section_length("X3JG"))
    model = live.model
    row = table().row("1700-1", 1600.0)
    assert model.adjustment().voltage_mV == pytest.approx(row.adjust_mV)  # type: ignore[attr-defined]
    assert model.params.transmitter_V == model.params.transmitter_levels_V[row.level - 1]  # type: ignore[attr-defined]
    dry = ZpwFaults(ballast_ohm_km=math.inf)
    for x in (0.0, 400.0, 800.0, 1200.0, 1600.0):
        assert model.evaluate([(x, 0.15)], dry).voltage_mV < 153.0  # type: ignore[attr-defined]


def test_zpw_command_prints_the_tables_settings(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["zpw", "gaotie", "--format", "json"]) == 0
    rows = {r["id"]: r for r in json.loads(capsys.readouterr().out)["sections"]}
    assert rows["X3JG"]["adjustment_mV"] == table().row("1700-1", 1600.0).adjust_mV
    assert rows["IG"]["adjustment_mV"] == table().row("2300-1", 700.0).adjust_mV
    short = {k for k, r in rows.items() if r["min_cab_current_mA"] < r["cab_min_mA"]}
    assert short == {"X3JG", "S3LQG", "S1LQG"}  # 1500-1600 m: longer than level 1 feeds (check warns)
    assert all(v.level == 1 and not v.feeds_cab for v in station_verdicts(load("gaotie")) if v.section in short)


def test_station_without_zpw_has_no_such_warning(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["check", "jiaopei"]) == 0
    assert "cannot be adjusted" not in capsys.readouterr().out

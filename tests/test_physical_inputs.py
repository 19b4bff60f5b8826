"""Bad physical inputs are refused with a clear message, and where the physics cannot answer the section shows
occupied (issue 15, item 5): ballast <= 0 or NaN, positions that are not finite numbers, a 25 Hz section past the
model's range. Each way a value enters is tried as a user would: the command language, a station file through
``liansuo check``, the Python constructors."""

from __future__ import annotations

import math
from pathlib import Path

import pytest
from conftest import Driver, edit

from liansuo.circuits.phase25.model import MAX_LENGTH_M, Phase25HzCircuit, Phase25HzFaults, Phase25HzParams
from liansuo.circuits.railgeometry import Axle
from liansuo.circuits.zpw.model import ZpwCircuit, ZpwFaults, standard_positions
from liansuo.circuits.zpw.params import ZpwParams
from liansuo.circuits.zpw.sweep import sweep
from liansuo.cli.main import main
from liansuo.simulation.sim import Simulation

ROOT = Path(__file__).resolve().parents[1]
PKG = ROOT / "src" / "liansuo"
MINIMAL = (PKG / "examples" / "stations" / "minimal.yaml").read_text(encoding="utf-8")
BAD_BALLAST = [0.0, -1.0, math.nan]


# ---- ballast: the Python API -------------------------------------------------------------------------------------
@pytest.mark.parametrize("ohm_km", BAD_BALLAST)
def test_25hz_model_refuses_a_ballast_at_or_below_zero_or_nan(ohm_km: float) -> None:
    with pytest.raises(ValueError, match="ballast_ohm_km"):
        Phase25HzParams(ballast_ohm_km=ohm_km)
    with pytest.raises(ValueError, match=r"ballast_ohm_km (must be above 0 ohm\*km|is not a number)"):
        Phase25HzFaults(ballast_ohm_km=ohm_km)


@pytest.mark.parametrize("ohm_km", BAD_BALLAST)
def test_zpw_model_refuses_a_ballast_at_or_below_zero_or_nan(ohm_km: float) -> None:
    with pytest.raises(ValueError, match="ballast_ohm_km"):
        ZpwParams(ballast_ohm_km=ohm_km)
    with pytest.raises(ValueError, match="ballast_ohm_km"):
        ZpwFaults(ballast_ohm_km=ohm_km)
    with pytest.raises(ValueError, match="ballasts"):
        sweep([650.0], carriers=("1700-1",), ballasts=(1.0, ohm_km), faults=[{}])


def test_infinite_ballast_is_dry_ballast_and_accepted() -> None:
    state = Phase25HzCircuit(600).adjustment(Phase25HzFaults(ballast_ohm_km=math.inf))
    assert math.isfinite(state.voltage_V) and state.relay_up
    zpw = ZpwCircuit(650.0, "2300-1", standard_positions(650.0))
    assert math.isfinite(zpw.adjustment(ZpwFaults(ballast_ohm_km=math.inf)).voltage_mV)


# ---- ballast: the command language -----------------------------------------------------------------------------------
@pytest.mark.parametrize("value", ["0", "-0.3", "nan", "inf"])
def test_low_ballast_fault_refuses_a_value_that_is_not_a_resistance(jiaopei: Driver, value: str) -> None:
    message = jiaopei.refused(f"fault low-ballast IG ohm_km={value}", "fault low-ballast: ohm_km must be")
    assert value in message and "\n" not in message
    jiaopei("faults", "expect section IG free")
    assert jiaopei.sim.command("faults").message == "no active faults"


def test_low_ballast_fault_on_a_zpw_section_refuses_zero() -> None:
    gaotie = Driver(Simulation("gaotie"))
    gaotie.refused("fault low-ballast X2JG ohm_km=0", "ohm_km must be above 0 ohm*km")
    gaotie("fault low-ballast X2JG ohm_km=0.3")


def test_broken_rail_at_nan_is_refused(jiaopei: Driver) -> None:
    jiaopei.refused("fault broken-rail IG at=nan", "at must be a finite number")


# ---- positions ------------------------------------------------------------------------------------------------------
@pytest.mark.parametrize("value", ["nan", "inf", "-inf"])
def test_axles_command_refuses_a_position_that_is_not_a_number(jiaopei: Driver, value: str) -> None:
    jiaopei.refused(f"axles car t-IG 600 {value}", f"position '{value}' is not a number of metres")
    jiaopei("expect section IG free")
    assert "car" not in jiaopei.sim.parked


@pytest.mark.parametrize("option", ["length=nan", "front=nan", "back=inf", "vmax=nan"])
def test_train_placement_refuses_keys_that_are_not_numbers(jiaopei: Driver, option: str) -> None:
    key = option.partition("=")[0]
    jiaopei.refused(f"train T1 at IG {option}", f"{key} must be a finite number")
    assert "T1" not in jiaopei.sim.fleet.trains


def test_drive_refuses_a_speed_that_is_not_a_number(jiaopei: Driver) -> None:
    jiaopei("train T1 at IG")
    jiaopei.refused("drive T1 nan", "speed must be a finite number of km/h")


def test_field_refuses_a_wheelset_at_nan_and_changes_nothing(jiaopei: Driver) -> None:
    field = jiaopei.sim.field
    with pytest.raises(ValueError, match="track t-IG must stand at a finite number of metres, got nan"):
        field.set_axles([Axle("t-IG", math.nan)])
    assert field.track_up("IG") and field.axles == []


def test_a_wheelset_at_an_unknown_place_leaves_its_section_occupied(jiaopei: Driver) -> None:
    """Fail-safe below the refusals: the geometry puts it on its track's section, the circuit drops its relay,
    even with a poor shunt that a model would let through."""
    field = jiaopei.sim.field
    geometry = field.geometry
    assert geometry.shunts_of([Axle("t-IG", math.nan)]) == {"IG": [(pytest.approx(math.nan, nan_ok=True), 0.01)]}
    shunt = geometry.shunt(Axle("t-IG", math.inf))
    assert shunt is not None and shunt.section == "IG"
    circuit = field.circuits["IG"]
    circuit.faults.poor_shunt_ohm = 5.0  # a poor shunt no model would detect
    assert circuit.update([(300.0, 5.0)])  # the model: clear
    assert not circuit.update([(math.nan, 5.0)])  # unknown place: occupied


def test_models_refuse_a_shunt_at_nan() -> None:
    with pytest.raises(ValueError, match="shunt position must be a finite number of metres, got nan"):
        Phase25HzCircuit(600).evaluate([(math.nan, 0.06)])
    with pytest.raises(ValueError, match="shunt position must be a finite number of metres, got inf"):
        ZpwCircuit(650.0, "2300-1", standard_positions(650.0)).evaluate([(math.inf, 0.15)])
    with pytest.raises(ValueError, match="broken_rail_at_m"):
        Phase25HzFaults(broken_rail_at_m=math.nan)
    with pytest.raises(ValueError, match="length_m must be a positive number of metres"):
        ZpwCircuit(math.nan, "2300-1")


@pytest.mark.parametrize("value", [".nan", ".inf"])
def test_station_file_with_a_position_that_is_not_a_number_is_refused(tmp_path: Path, value: str,
                                                                       capsys: pytest.CaptureFixture[str]) -> None:
    path = tmp_path / "bad.yaml"
    path.write_text(edit(MINIMAL, ("{id: J-XI, at: 900}", f"{{id: J-XI, at: {value}}}")), encoding="utf-8")
    assert main(["check", str(path)]) == 3
    err = capsys.readouterr().err
    assert f"{path}:24:20: error: joints.3.at: Input should be a finite number" in err
    assert "Traceback" not in err


# ---- a 25 Hz section past the model's range ----------------------------------------------------------------------
def test_25hz_model_is_safe_to_its_range_and_unsafe_past_it() -> None:
    """Why the range: at 1500 m a standard shunt leaves <= 7.4 V even in dry ballast; at 2500 m it holds the relay."""
    dry = Phase25HzFaults(ballast_ohm_km=math.inf)
    at_limit = Phase25HzCircuit(MAX_LENGTH_M)
    assert at_limit.max_residual_V(faults=dry) <= at_limit.params.residual_max_V
    past = Phase25HzCircuit(2500, beyond_range=True)
    assert past.evaluate([(2500.0, past.params.standard_shunt_ohm)], dry).relay_up_after(True)


def test_25hz_model_refuses_a_section_past_its_range() -> None:
    with pytest.raises(ValueError, match=r"length_m 2500 m is past the 25 Hz model's range \(1500 m\)"):
        Phase25HzCircuit(2500)


def _long_25hz_station(tmp_path: Path) -> Path:
    path = tmp_path / "long25.yaml"
    path.write_text(edit(MINIMAL, ("{id: J-XI, at: 900}", "{id: J-XI, at: 2800}"),
                         ("{id: SB, kind: boundary, at: 1200}", "{id: SB, kind: boundary, at: 3100}")),
                    encoding="utf-8")
    return path


def test_check_says_a_long_25hz_section_is_held_occupied(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    path = _long_25hz_station(tmp_path)
    assert main(["check", str(path)]) == 0
    out = " ".join(capsys.readouterr().out.split())
    assert "warning: 25 Hz section 'IG' is 2500 m long (limit about 1500 m)" in out
    assert "the simulation holds it occupied (red band)" in out


def test_a_long_25hz_section_is_held_occupied_with_an_alarm(tmp_path: Path) -> None:
    sim = Driver(Simulation(_long_25hz_station(tmp_path)))
    sim("expect section IG occupied", "expect section 1DG free",
        "expect alarm 25 Hz section IG is 2500 m long, past the track-circuit model")
    sim.refused("route X XI", "section IG is occupied")
    sim("axles car t-IG 1500", "axles car clear", "expect section IG occupied")

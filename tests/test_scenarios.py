"""`liansuo run`: every shipped scenario runs without a refused or failed step; bad scenarios are explained."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

from liansuo.cli.main import main
from liansuo.proving.scenario import parse_scenario, run_scenario

SCENARIOS = sorted((Path(__file__).parent.parent / "src" / "liansuo" / "examples" / "scenarios").glob("*.yaml"))


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_example_scenario_runs(path: Path) -> None:
    out: list[str] = []
    status, _ = run_scenario(parse_scenario(path), out=out)
    assert status == 0, "\n".join(out[-15:])
    assert out[-1].startswith("-- end of scenario")


def test_receiving_then_departure_releases_route_by_route() -> None:
    out: list[str] = []
    status, _ = run_scenario(parse_scenario(next(p for p in SCENARIOS if p.stem == "jiaopei-receive-depart")), out=out)
    assert status == 0
    released = [line.split("section ")[1].split(" ")[0] for line in out if " released (" in line]
    assert released == ["7DG", "1DG", "IG", "2DG", "6DG"]
    assert any("has left the station" in line for line in out)


def test_run_command_prints_the_event_log(capsys: pytest.CaptureFixture[str]) -> None:
    path = next(p for p in SCENARIOS if p.stem == "gaotie-dead-zone-train")
    assert main(["run", str(path)]) == 0
    out = capsys.readouterr().out
    assert "signal SII opened: L" in out and "signal SII closed: section 3-5DG is occupied" in out


def test_refused_step_stops_the_run_with_file_and_line(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "s.yaml"
    f.write_text("station: jiaopei\nsteps:\n  - occupy 1DG\n  - route X XI\n", encoding="utf-8")
    assert main(["run", str(f)]) == 1
    assert f"{f}:4: 'route X XI' refused: section 1DG is occupied" in capsys.readouterr().out


def test_malformed_scenario(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    f = tmp_path / "s.yaml"
    f.write_text("station: jiaopei\nsteps:\n  - fly X\nspeed: 3\n", encoding="utf-8")
    assert main(["run", str(f)]) == 3  # a bad input file
    err = capsys.readouterr().err
    assert err.splitlines()[-1] == "2 errors; the scenario was not loaded"
    assert f"{f}:3:5: error: unknown command 'fly'" in err and f"{f}:4:1: error: unknown key 'speed'" in err
    assert "Traceback" not in err


def test_the_event_log_is_the_same_in_every_process() -> None:
    """A scenario's log is the same from one run to the next: turnouts reaching their positions in one cycle are
    logged in the same order whatever the process's string hashing (PYTHONHASHSEED), which orders its sets. Four
    turnouts of gaotie's X-XI come into reverse in the same cycle."""
    path = str(next(p for p in SCENARIOS if p.name == "gaotie-cab-atp.yaml"))
    logs = set()
    for seed in ("1", "2", "3", "4"):
        env = {**os.environ, "PYTHONHASHSEED": seed}
        out = subprocess.run([sys.executable, "-m", "liansuo.cli", "run", path], capture_output=True, text=True,
                             env=env, check=True).stdout
        assert "turnout 13 in reverse" in out
        logs.add(out)
    assert len(logs) == 1

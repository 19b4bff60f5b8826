"""The plots (``--plot FILE``, ``--plot-csv FILE``) of ``liansuo zpw``, ``liansuo 25hz`` and ``liansuo run``, run as a
user runs them: each writes a PNG and its CSV, the CSV agrees with the model called directly, matplotlib is loaded
only for a plot, and without it a plot fails with exit status 2 and one line."""

from __future__ import annotations

import csv
import itertools
import subprocess
import sys
from pathlib import Path

import pytest

from liansuo.circuits.phase25.model import Phase25HzFaults
from liansuo.circuits.phase25.sweep import section_model
from liansuo.circuits.zpw.adjust import section_circuit  # as `liansuo zpw` adjusts it (the table)
from liansuo.circuits.zpw.model import ZpwFaults
from liansuo.cli.main import main
from liansuo.kit.plotfiles import NEED_MATPLOTLIB
from liansuo.stations.loader import load

ROOT = Path(__file__).resolve().parent.parent
PKG = ROOT / "src" / "liansuo"
SCENARIO = PKG / "examples" / "scenarios" / "jiaopei-receive-depart.yaml"
PNG_SIGNATURE = b"\x89PNG\r\n\x1a\n"


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(list(argv))
    out, err = capsys.readouterr()
    return code, out, err


def assert_png(path: Path) -> None:
    data = path.read_bytes()
    assert data[:8] == PNG_SIGNATURE
    assert len(data) > 20_000, "the figure is almost empty"
    width, height = int.from_bytes(data[16:20], "big"), int.from_bytes(data[20:24], "big")
    assert (width, height) == (900, 500)


def read_csv(path: Path) -> tuple[list[str], list[dict[str, str]]]:
    with path.open(encoding="utf-8", newline="") as f:
        reader = csv.DictReader(f)
        return list(reader.fieldnames or []), list(reader)


def test_zpw_plot_and_csv_agree_with_the_model(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    png, data = tmp_path / "x2jg.png", tmp_path / "x2jg.csv"
    code, out, err = run(capsys, "zpw", "gaotie", "--section", "X2JG", "--fault", "X2JG:capacitor:3:open",
                         "--fault", "X2JG:capacitor:7:half", "--plot", str(png), "--plot-csv", str(data))
    assert (code, err) == (0, "")
    assert out.endswith(f"wrote {png}\nwrote {data}\n") and "X2JG" in out  # the table, then the files
    assert_png(png)
    columns, rows = read_csv(data)
    assert columns == ["section", "case", "position_m", "shunt_residual_mV", "cab_current_mA", "adjustment_mV"]
    assert list(dict.fromkeys(r["case"] for r in rows)) == ["healthy", "C3 open", "C7 half"]
    circuit = section_circuit(load("gaotie"), "X2JG")
    for case, faults in (("healthy", ZpwFaults()), ("C3 open", ZpwFaults(capacitors={3: "open"}))):
        row = next(r for r in rows if r["case"] == case and float(r["position_m"]) == 700.0)
        _, residual, cab = circuit.profile(faults, positions_m=[700.0])
        assert float(row["shunt_residual_mV"]) == pytest.approx(float(residual[0]), abs=1e-3)
        assert float(row["cab_current_mA"]) == pytest.approx(float(cab[0]), abs=1e-3)
        assert float(row["adjustment_mV"]) == pytest.approx(circuit.adjustment(faults).voltage_mV, abs=1e-3)
    positions = [float(r["position_m"]) for r in rows if r["case"] == "healthy"]
    assert positions[0] == 0.0 and positions[-1] == pytest.approx(circuit.length_m)


def test_zpw_plot_without_faults_takes_the_open_capacitors(tmp_path: Path,
                                                            capsys: pytest.CaptureFixture[str]) -> None:
    data = tmp_path / "ig.csv"
    code, out, _ = run(capsys, "zpw", "gaotie", "--section", "IG", "--plot-csv", str(data), "--format", "json")
    assert code == 0 and "wrote" not in out  # JSON on stdout stays JSON
    _, rows = read_csv(data)
    cases = list(dict.fromkeys(r["case"] for r in rows))
    assert cases == ["healthy"] + [f"C{k} open" for k in range(1, 8)]  # IG has 7 capacitors: every one
    code, _, _ = run(capsys, "zpw", "gaotie", "--plot-csv", str(data))  # 16 capacitors on X3JG: the worst few
    assert code == 0
    _, rows = read_csv(data)
    assert {r["section"] for r in rows} == {"X3JG"}
    assert 2 <= len({r["case"] for r in rows}) - 1 <= 6


@pytest.mark.parametrize(("argv", "message"), [
    (["--section", "IG"], "--section chooses the section to plot: give --plot FILE or --plot-csv FILE with it"),
    (["--section", "1DG", "--plot-csv", "{d}/a.csv"], "--section 1DG: gaotie has no section '1DG'"),
    (["--fault", "IG:capacitor:2:open", "--fault", "X2JG:capacitor:1:open", "--plot-csv", "{d}/a.csv"],
     "the faults name sections IG, X2JG: plot one, with --section"),
    (["--section", "IG", "--fault", "X2JG:capacitor:1:open", "--plot-csv", "{d}/a.csv"],
     "--fault 'X2JG:capacitor:1:open': the plot is of section IG; give faults on it only"),
    (["--plot", "{d}/no/such/a.png"], "cannot write {d}/no/such/a.png: no folder {d}/no/such; create it or give "
     "--plot a file in a folder that exists"),
    (["--plot-csv", "{d}"], "cannot write {d}: it is a folder; give --plot-csv a file name"),
    (["--plot", "{d}/a.txt"], "cannot draw {d}/a.txt: give --plot a file ending in .png, .svg or .pdf"),
])
def test_zpw_plot_refusals_are_one_line_with_status_2(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                      argv: list[str], message: str) -> None:
    code, out, err = run(capsys, "zpw", "gaotie", *(a.format(d=tmp_path) for a in argv))
    assert (code, out) == (2, "")
    assert err == f"liansuo zpw: {message.format(d=tmp_path)}\n"
    assert list(tmp_path.iterdir()) == []  # nothing written


def test_zpw_plot_of_a_station_without_zpw(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, _, err = run(capsys, "zpw", "jiaopei", "--plot", str(tmp_path / "a.png"))
    assert (code, err) == (2, "liansuo zpw: jiaopei has no ZPW-2000A section to plot\n")
    assert list(tmp_path.iterdir()) == []


def test_25hz_plot_and_csv_agree_with_the_model(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    png, data = tmp_path / "ig.png", tmp_path / "ig.csv"
    code, out, err = run(capsys, "25hz", "jiaopei", "--section", "IG", "--plot", str(png), "--plot-csv", str(data))
    assert (code, err) == (0, "")
    assert "IG: 25 Hz phase-sensitive" in out and out.endswith(f"wrote {png}\nwrote {data}\n")
    assert_png(png)
    columns, rows = read_csv(data)
    assert columns == ["section", "ballast_ohm_km", "voltage_V", "phase_deg", "phase_error_deg", "effective_V",
                       "relay", "max_residual_V"]
    ballast = [float(r["ballast_ohm_km"]) for r in rows]
    assert ballast == sorted(ballast) and ballast[0] == 0.1 and ballast[-1] == 100.0 and 0.6 in ballast
    model = section_model(load("jiaopei"), "IG")
    for b in (0.1, 0.6, 10.0):
        row = next(r for r in rows if float(r["ballast_ohm_km"]) == b)
        state = model.adjustment(Phase25HzFaults(ballast_ohm_km=b))
        assert float(row["voltage_V"]) == pytest.approx(state.voltage_V, abs=1e-4)
        assert float(row["phase_deg"]) == pytest.approx(state.phase_deg, abs=1e-3)
        residual = model.max_residual_V(points=61, faults=Phase25HzFaults(ballast_ohm_km=b))
        assert float(row["max_residual_V"]) == pytest.approx(residual, abs=1e-4)
    design = next(r for r in rows if float(r["ballast_ohm_km"]) == 0.6)
    assert design["relay"] == "up" and float(design["voltage_V"]) >= 18.0  # adjusted at the design ballast
    assert next(r for r in rows if float(r["ballast_ohm_km"]) == 0.1)["relay"] == "holds"  # wet ballast


def test_25hz_json_and_refusals(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "25hz", "jiaopei", "--section", "IG", "--format", "json")
    assert code == 0 and '"schema": 1' in out and '"feed_tap_V"' in out
    code, out, err = run(capsys, "25hz", "gaotie", "--section", "X2JG", "--plot", str(tmp_path / "a.png"))
    assert (code, out) == (2, "")
    assert err.startswith("liansuo 25hz: --section X2JG: not a 25 Hz section") and err.count("\n") == 1
    code, _, err = run(capsys, "25hz", "jiaopei", "--section", "XX", "--plot-csv", str(tmp_path / "a.csv"))
    assert (code, err) == (2, "liansuo 25hz: --section XX: jiaopei has no section 'XX'\n")
    assert list(tmp_path.iterdir()) == []


def test_run_plot_and_csv_follow_the_trains(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    png, data = tmp_path / "run.png", tmp_path / "run.csv"
    code, out, err = run(capsys, "run", str(SCENARIO), "--plot", str(png), "--plot-csv", str(data))
    assert (code, err) == (0, "")
    assert "-- end of scenario" in out and out.endswith(f"wrote {png}\nwrote {data}\n")
    assert_png(png)
    columns, rows = read_csv(data)
    assert columns == ["t_s", "train", "head_track", "head_m", "speed_kmh", "direction", "state"]
    assert {r["train"] for r in rows} == {"T1"}
    times = [float(r["t_s"]) for r in rows]
    assert times[0] == 0.25 and all(b - a == pytest.approx(0.25) for a, b in itertools.pairwise(times))
    first = rows[0]
    assert (first["head_track"], float(first["head_m"])) == ("t-IAG", pytest.approx(295.0, abs=0.1))
    stopped = [r for r in rows if r["state"] == "running" and float(r["speed_kmh"]) == 0.0 and float(r["t_s"]) > 60]
    assert stopped, "the train stops at XI before it departs"
    assert rows[-1]["state"] == "leaving" and rows[-1]["head_m"] == ""  # then it runs out of the station
    heads = [float(r["head_m"]) for r in rows if r["head_m"]]
    assert heads == sorted(heads)  # a down train only moves on


def test_run_json_keeps_stdout_json(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    data = tmp_path / "run.csv"
    code, out, _ = run(capsys, "run", str(SCENARIO), "--plot-csv", str(data), "--format", "json")
    assert code == 0 and out.lstrip().startswith("{") and "wrote" not in out
    assert data.stat().st_size > 1000


def test_run_plot_refused_before_the_run(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys, "run", str(SCENARIO), "--plot", str(tmp_path / "no" / "run.png"))
    assert (code, out) == (2, "")  # nothing ran: no event log
    assert err.startswith(f"liansuo run: cannot write {tmp_path / 'no' / 'run.png'}: no folder")


@pytest.mark.parametrize("argv", [
    ["zpw", "gaotie", "--plot", "{d}/a.png"],
    ["25hz", "jiaopei", "--section", "IG", "--plot", "{d}/a.png"],
    ["run", str(SCENARIO), "--plot", "{d}/a.png"],
], ids=["zpw", "25hz", "run"])
def test_without_matplotlib_a_plot_is_refused(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                              monkeypatch: pytest.MonkeyPatch, argv: list[str]) -> None:
    for name in [m for m in sys.modules if m == "matplotlib" or m.startswith("matplotlib.")]:
        monkeypatch.delitem(sys.modules, name)
    monkeypatch.setitem(sys.modules, "matplotlib", None)  # import matplotlib raises ImportError, as when missing
    code, out, err = run(capsys, *(a.format(d=tmp_path) for a in argv))
    assert (code, out) == (2, "")
    assert err == f"liansuo {argv[0]}: {NEED_MATPLOTLIB}\n"
    assert NEED_MATPLOTLIB == "the plots need matplotlib: pip install 'liansuo[plot]'"
    assert list(tmp_path.iterdir()) == []


def test_without_matplotlib_the_csv_is_still_written(tmp_path: Path, capsys: pytest.CaptureFixture[str],
                                                     monkeypatch: pytest.MonkeyPatch) -> None:
    monkeypatch.setitem(sys.modules, "matplotlib", None)
    code, _, err = run(capsys, "zpw", "gaotie", "--section", "IG", "--plot-csv", str(tmp_path / "ig.csv"))
    assert (code, err) == (0, "")
    assert (tmp_path / "ig.csv").stat().st_size > 1000


def test_matplotlib_is_loaded_only_for_a_plot() -> None:
    code = ("import sys; from liansuo.cli.main import main; main(['zpw', 'gaotie']); "
            "main(['25hz', 'jiaopei', '--section', 'IG']); print('matplotlib' in sys.modules)")
    done = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True, cwd=ROOT, check=True)
    assert done.stdout.strip().splitlines()[-1] == "False"


def test_the_figures_in_the_docs_are_made_by_their_commands() -> None:
    """Every image under docs/images/ is shown in the docs with the command that drew it."""
    images = sorted((ROOT / "docs" / "images").glob("*.png"))
    assert images
    docs = "".join(p.read_text(encoding="utf-8") for p in (ROOT / "docs").glob("*.md"))
    shots = ROOT / "tests" / "classroom_screenshots.py"  # the classroom's pictures, taken in a headless browser
    for image in images:
        assert f"images/{image.name})" in docs, f"{image.name} is not shown"
        if image.name.startswith("classroom-"):
            assert image.name in shots.read_text(encoding="utf-8"), f"{image.name} is not taken by {shots.name}"
            assert f"python tests/{shots.name} docs/images" in docs, f"no command for {image.name}"
        else:
            assert f"--plot docs/images/{image.name}" in docs, f"no command for {image.name}"
        assert image.read_bytes()[:8] == PNG_SIGNATURE

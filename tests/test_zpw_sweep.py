"""``liansuo zpw sweep``: a parameter study of one ZPW-2000A section, run as a user runs it: the summary, the rows
as CSV and JSON, a Monte Carlo of tolerances, the refusals, and one row of the capacitor-fault article reproduced end
to end (the same figures as ``liansuo zpw validate``)."""

from __future__ import annotations

import csv
import io
import json

import pytest

from liansuo.circuits.zpw.study import COLUMNS, Study, run_study
from liansuo.circuits.zpw.validate import validate
from liansuo.cli.main import main


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["zpw", "sweep", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def test_the_articles_conventional_line_row_end_to_end(capsys: pytest.CaptureFixture[str]) -> None:
    """Table 1, 普速区间: every capacitor of a 1400 m section open in turn, on the four carriers; the largest rise and
    fall of each quantity are the validate table's row."""
    code, out, err = run(capsys, "--faults", "single-open", *[a for c in ("1700", "2000", "2300", "2600")
                                                                for a in ("--carrier", c)])
    assert code == 0 and err == ""
    rows = {r["quantity"]: r for r in validate() if (r["table"], r["section"]) == (1, "conventional-line")}
    names = {"adjustment_voltage": "adjustment_mV", "min_cab_current": "min_cab_current_mA",
             "max_shunt_residual": "max_residual_mV", "small_track_voltage": "small_track_mV"}
    for quantity, r in rows.items():
        line = next(line for line in out.splitlines() if line.startswith(names[quantity]))
        assert line.endswith(f"↑{r['model_rise_pct']:.1f} % ↓{r['model_fall_pct']:.1f} %"), (quantity, line)
    assert "60 rows" in out and "cab current under its minimum in 50 rows" in out


def test_rows_as_csv_and_json(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, _ = run(capsys, "--faults", "single", "--carrier", "2600-1", "--ballast", "1", "--ballast", "2",
                       "--format", "csv")
    assert code == 0
    rows = list(csv.DictReader(io.StringIO(out)))
    assert list(rows[0]) == list(COLUMNS) and len(rows) == 2 * (1 + 2 * 14)
    assert rows[0]["case"] == "none" and rows[1]["case"] == "C1 open" and rows[15]["case"] == "C1 half"
    code, out, _ = run(capsys, "--length", "650", "--format", "json")
    data = json.loads(out)
    assert (data["schema"], data["ok"], data["summary"]["rows"]) == (1, True, 4)
    assert all(r["residual_ok"] for r in data["rows"])


def test_a_monte_carlo_of_tolerances_is_seeded() -> None:
    a = run_study(Study(samples=100, carriers=("1700-1",), seed=3))
    b = run_study(Study(samples=100, carriers=("1700-1",), seed=3))
    c = run_study(Study(samples=100, carriers=("1700-1",), seed=4))
    assert a[0] == b[0] and a[0] != c[0]
    rows = a[0]
    assert len(rows) == 100 and {r["case"] for r in rows} == {"sample"}
    ballasts = {r["ballast_ohm_km"] for r in rows}
    assert len(ballasts) == 10 and all(0.8 <= x <= 1.2 for x in ballasts)  # the design minimum +-20 %
    adjustment = [r["adjustment_mV"] for r in rows]
    assert max(adjustment) - min(adjustment) > 10.0  # the tolerances move the figures


def test_refusals(capsys: pytest.CaptureFixture[str]) -> None:
    for argv, said in ((["--faults", "single", "--samples", "10"], "give --samples or --faults, not both"),
                       (["--carrier", "9999"], "give a ZPW-2000A carrier"),
                       (["--length", "0"], "give 1 to 5000 metres"),
                       (["--fault", "IG:capacitor:1:open"], "--fault does not go with 'sweep'"),
                       (["--ballast-tolerance", "1.5", "--samples", "4"], "tolerances are fractions")):
        code, out, err = run(capsys, *argv)
        assert code == 2 and out == "" and said in err, (argv, err)
    assert main(["zpw", "jiaopei", "--samples", "3"]) == 2
    assert "--samples goes with 'liansuo zpw sweep'" in capsys.readouterr().err


def test_profiles_along_the_section_as_csv_and_a_plot(tmp_path, capsys: pytest.CaptureFixture[str]) -> None:
    """--plot-csv: the healthy section and the worst fault cases of the first carrier, point by point; --plot draws
    them (with matplotlib, the plot extra)."""
    target = tmp_path / "profiles.csv"
    code, out, err = run(capsys, "--faults", "single-open", "--carrier", "2600-1", "--plot-csv", str(target))
    assert code == 0 and err == "" and f"wrote {target}" in out
    rows = list(csv.DictReader(target.open(encoding="utf-8")))
    cases = list(dict.fromkeys(r["case"] for r in rows))
    assert cases[0] == "healthy" and 2 <= len(cases) <= 7 and all(c.endswith(" open") for c in cases[1:])
    healthy = [r for r in rows if r["case"] == "healthy"]
    assert len(healthy) == 141 and float(healthy[0]["position_m"]) == 0.0  # every 10 m over 1400 m
    pytest.importorskip("matplotlib")
    png = tmp_path / "profiles.png"
    code, out, err = run(capsys, "--samples", "100", "--plot", str(png))
    assert code == 0 and png.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"

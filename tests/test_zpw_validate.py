"""``liansuo zpw validate`` (issue 15, item 2): the ZPW-2000A model beside the capacitor-fault article (Luo Ying
2023, docs/references.md), run as a user runs it: the JSON shape, the article's rows as transcribed, the trend rule,
the exit status, the text and its copy in docs/zpw2000a.md."""

from __future__ import annotations

import json
import re
from pathlib import Path

import pytest

from liansuo.circuits.zpw.model import ZpwCircuit, ZpwFaults, layout_params, standard_positions
from liansuo.circuits.zpw.validate import QUANTITIES, TARGET_SHARE, read_article, trend_ok
from liansuo.cli.main import main
from liansuo.kit.fit import columns
from liansuo.kit.jsonreport import SCHEMAS, version

ROOT = Path(__file__).resolve().parent.parent
KEYS = ["table", "section", "fault", "quantity", "paper_rise_pct", "paper_fall_pct", "model_rise_pct",
        "model_fall_pct", "trend_ok"]
SECTIONS = ("passenger-line", "conventional-line", "station-no-selection", "station-selection")


def run(capsys: pytest.CaptureFixture[str], *argv: str) -> tuple[int, str, str]:
    code = main(["zpw", "validate", *argv])
    out, err = capsys.readouterr()
    return code, out, err


def json_report(capsys: pytest.CaptureFixture[str]) -> dict[str, object]:
    code, out, err = run(capsys, "--format", "json")
    assert code == 0 and err == ""  # a report: it never fails on disagreement
    data: dict[str, object] = json.loads(out)
    assert list(data)[:3] == ["liansuo", "schema", "ok"]
    assert (data["liansuo"], data["schema"], data["ok"]) == (version(), SCHEMAS["zpw validate"], True)
    return data


def test_json_shape_and_summary(capsys: pytest.CaptureFixture[str]) -> None:
    data = json_report(capsys)
    assert list(data)[3:] == ["rows", "summary"]
    rows = data["rows"]
    assert isinstance(rows, list) and len(rows) == 28  # 2 tables x (4 sections x 3 quantities + 2 small tracks)
    for row in rows:
        assert list(row) == KEYS
        assert row["table"] in (1, 2) and row["fault"] == {1: "open", 2: "half"}[row["table"]]
        assert row["section"] in SECTIONS and row["quantity"] in QUANTITIES
        for key in KEYS[4:8]:
            assert row[key] is None or (isinstance(row[key], float) and row[key] >= 0.0)
        assert row["trend_ok"] is trend_ok(*(row[k] for k in KEYS[4:8]))
        assert row["model_rise_pct"] is not None and row["model_fall_pct"] is not None  # all four modelled
    agree = sum(1 for r in rows if r["trend_ok"])
    assert data["summary"] == {"rows": 28, "trend_ok": agree, "share": round(agree / 28, 3)}


def test_the_system_model_reaches_the_target(capsys: pytest.CaptureFixture[str]) -> None:
    """Issue 15: the trend agrees on at least 80 % of the rows. The rows that still differ are material rises of the
    minimum cab current on the 1400 m open line (docs/zpw2000a.md says why); every small-track and residual row
    agrees, and the station section without frequency selection has its cab-current rise. The passenger-dedicated
    line, with its own figures (2 ohm*km, 25 uF every 60 / 80 m), comes close to the article's magnitudes."""
    rows = json_report(capsys)["rows"]
    assert isinstance(rows, list)
    assert sum(r["trend_ok"] for r in rows) / len(rows) >= TARGET_SHARE
    differ = {(r["table"], r["section"], r["quantity"]) for r in rows if not r["trend_ok"]}
    assert differ == {(1, "passenger-line", "min_cab_current"), (1, "conventional-line", "min_cab_current"),
                      (2, "conventional-line", "min_cab_current")}
    by = {(r["table"], r["section"], r["quantity"]): r for r in rows}
    for t in (1, 2):
        small = by[t, "conventional-line", "small_track_voltage"]
        assert small["model_rise_pct"] > 5.0 and small["model_fall_pct"] > 5.0  # both ways, by tens of percent
        assert by[t, "station-no-selection", "min_cab_current"]["model_rise_pct"] > 5.0
        assert by[t, "passenger-line", "min_cab_current"]["model_rise_pct"] <= 6.0  # the rise it lacks
    # passenger-dedicated line, open capacitor: within a few points of the article (11.6, 28.9 / 21.5)
    assert by[1, "passenger-line", "adjustment_voltage"]["model_fall_pct"] == pytest.approx(11.6, abs=2.0)
    small = by[1, "passenger-line", "small_track_voltage"]
    assert (small["model_rise_pct"], small["model_fall_pct"]) == pytest.approx((28.9, 21.5), abs=2.0)


def test_the_articles_rows_are_transcribed(capsys: pytest.CaptureFixture[str]) -> None:
    """Figures read again in the article's tables 1 (open) and 2 (-50 %)."""
    paper = {(r.table, r.section, r.quantity): (r.rise_pct, r.fall_pct) for r in read_article().rows}
    assert len(paper) == 28
    assert paper[1, "passenger-line", "adjustment_voltage"] == (None, 11.6)
    assert paper[1, "conventional-line", "adjustment_voltage"] == (None, 23.8)
    assert paper[1, "passenger-line", "min_cab_current"] == (83.4, 19.3)
    assert paper[1, "station-no-selection", "min_cab_current"] == (31.1, 21.5)
    assert paper[1, "station-selection", "max_shunt_residual"] == (26.0, 33.9)
    assert paper[1, "conventional-line", "small_track_voltage"] == (45.7, 33.8)
    assert paper[2, "conventional-line", "min_cab_current"] == (112.0, 0.6)
    assert paper[2, "station-no-selection", "adjustment_voltage"] == (3.9, 8.0)
    assert paper[2, "station-selection", "max_shunt_residual"] == (17.6, 17.0)
    assert paper[2, "passenger-line", "small_track_voltage"] == (14.3, 11.9)
    assert not any(k[2] == "small_track_voltage" and k[1].startswith("station") for k in paper)  # "—" in the article
    article = read_article()
    assert [(s.id, s.length_m) for s in article.sections] == [(s, length) for s, length in zip(
        SECTIONS, (1400.0, 1400.0, 650.0, 650.0), strict=True)]
    assert article.carriers == ("1700", "2000", "2300", "2600")
    rows = json_report(capsys)["rows"]
    assert isinstance(rows, list)
    assert {(r["table"], r["section"], r["quantity"]): (r["paper_rise_pct"], r["paper_fall_pct"])
            for r in rows} == paper


@pytest.mark.parametrize(("paper", "model", "ok"), [
    ((None, 11.6), (0.0, 21.7), True),  # both only fall, materially
    ((None, 11.6), (6.0, 21.7), False),  # the model rises materially where the article only falls
    ((None, 11.6), (5.0, 21.7), True),  # 5 % is not material
    ((83.4, 19.3), (0.0, 41.2), False),  # a material rise the model does not have
    ((83.4, 19.3), (5.1, 41.2), True),
    ((31.1, 21.5), (9.0, 4.9), False),  # a material fall the model does not have
    ((0.6, 38.4), (0.0, 40.6), True),  # a small change in the article: any model figure agrees
    ((0.6, 38.4), (30.0, 40.6), True),
    ((28.9, 21.5), (None, None), False),  # not computed
])
def test_trend_rule(paper: tuple[float | None, float | None], model: tuple[float | None, float | None],
                    ok: bool) -> None:
    assert trend_ok(*paper, *model) is ok


def test_model_figures_match_single_evaluations(capsys: pytest.CaptureFixture[str]) -> None:
    """The 1400 m open-capacitor adjustment rows, recomputed one circuit and one capacitor at a time: the conventional
    line with the model's figures, the passenger-dedicated one with its own (2 ohm*km, 25 uF every 60 / 80 m)."""
    rows = json_report(capsys)["rows"]
    assert isinstance(rows, list)
    for section, layout in (("conventional-line", "conventional"), ("passenger-line", "passenger-line")):
        changes = []
        for carrier in ("1700", "2000", "2300", "2600"):
            params = layout_params(layout, carrier)
            caps = standard_positions(1400.0, params=params)
            assert len(caps) == {"conventional": 14, "passenger-line": 24 if carrier < "2300" else 18}[layout]
            circuit = ZpwCircuit(1400.0, carrier, caps, params)
            healthy = circuit.adjustment().voltage_mV
            for k in range(1, len(caps) + 1):
                changes.append(circuit.adjustment(ZpwFaults(capacitors={k: "open"})).voltage_mV / healthy * 100 - 100)
        row = next(r for r in rows if (r["table"], r["section"], r["quantity"]) == (1, section, "adjustment_voltage"))
        assert row["model_rise_pct"] == round(max(0.0, *changes), 1)
        assert row["model_fall_pct"] == round(max(0.0, *(-c for c in changes)), 1)


def test_text_report_fits_and_is_in_the_docs(capsys: pytest.CaptureFixture[str]) -> None:
    code, out, err = run(capsys)
    assert code == 0 and err == ""
    lines = out.splitlines()
    assert all(columns(line) <= 100 for line in lines)
    assert len([line for line in lines if re.match(r"[12] +\S+ \d+ m ", line)]) == 28
    assert re.fullmatch(r"trend agrees on \d+ of 28 rows \(\d+ %; target 80 %\)", lines[-1])
    assert "passenger-line 1400 m        open  min cab current   ↑83.4 ↓19.3" in out
    doc = (ROOT / "docs" / "zpw2000a.md").read_text(encoding="utf-8")
    assert f"```\n$ liansuo zpw validate\n{out}```" in doc, "docs/zpw2000a.md shows another table: paste it again"


def test_output_file_and_refusals(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    target = tmp_path / "v.json"
    code, out, _ = run(capsys, "--format", "json", "-o", str(target))
    assert code == 0 and out == f"wrote {target}\n"
    assert json.loads(target.read_text(encoding="utf-8"))["summary"]["rows"] == 28
    for argv, what in ((["--fault", "X:capacitor:1:open"], "--fault"), (["--format", "csv"], "--format csv"),
                       (["--plot", str(tmp_path / "p.png")], "--plot"), (["--section", "IG"], "--section")):
        code, out, err = run(capsys, *argv, "-o", str(tmp_path / "no.txt"))
        assert code == 2 and out == ""
        assert err == (f"liansuo zpw: {what} does not go with 'validate', which takes only --format text|json and "
                       "-o FILE\n")
    assert not (tmp_path / "no.txt").exists() and not (tmp_path / "p.png").exists()

"""The interlocking table as engineers sign it: groups, Chinese cell conventions, 120 columns, CSV, JSON, xlsx."""

from __future__ import annotations

import csv
import io
import json
import re
import unicodedata
from pathlib import Path

import jsonschema
import pytest
from openpyxl import load_workbook

from liansuo.cli.main import main
from liansuo.interlocking.table.build import build_table
from liansuo.interlocking.table.schema import TABLE_SCHEMA
from liansuo.interlocking.table.signed import SignedRow, signed_table
from liansuo.interlocking.table.text import as_csv, as_json, as_text
from liansuo.stations.loader import load, load_text


def width(line: str) -> int:
    return sum(2 if unicodedata.east_asian_width(c) in "WF" else 1 for c in line)


def rows(station: str) -> dict[str, tuple[str, SignedRow]]:
    """route id -> (group name, row)"""
    return {r.route: (g.name, r) for g in signed_table(build_table(load(station))).groups for r in g.rows}


@pytest.mark.parametrize("station", ["jiaopei", "gaotie", "depot"])
def test_text_fits_120_columns_and_groups_come_in_order(station: str, capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["table", station]) == 0
    out = capsys.readouterr().out
    assert all(width(line) <= 120 for line in out.splitlines())
    groups = re.findall(r"^== (\S+)", out, flags=re.MULTILINE)
    order = ["下行接车", "下行发车", "下行转线", "上行接车", "上行发车", "上行转线", "调车"]
    assert groups and [order.index(g) for g in groups] == sorted(order.index(g) for g in groups)


def test_jiaopei_groups_by_direction_and_throat() -> None:
    groups = [g.name for g in signed_table(build_table(load("jiaopei"))).groups]
    assert groups == ["下行接车 X咽喉", "下行发车 S咽喉", "上行接车 S咽喉", "上行发车 X咽喉",
                      "调车 X咽喉", "调车 S咽喉"]


def test_jiaopei_rows_read_as_an_engineer_writes_them() -> None:
    t = rows("jiaopei")
    group, x_xi = t["X-XI"]
    assert group == "下行接车 X咽喉"
    assert x_xi.cells["route"] == "至 IG" and x_xi.cells["mode"] == "基本"
    assert x_xi.cells["buttons"] == "XLA XILA" and x_xi.cells["aspects"] == "L/U"
    # the crossover pair once, with no separate driven or protection turnout for its partner
    assert x_xi.cells["turnouts"] == "7 1/3"
    assert t["X-X3"][1].cells["turnouts"] == "7 (1/3) 5"
    assert "接近锁闭 IAG 180s" in x_xi.cells["other"]
    # departures: to the neighbour of the link, over the 64D block
    group, xi_s = t["XI-S"]
    assert group == "下行发车 S咽喉" and xi_s.cells["route"] == "由 IG 至 乙站(虚拟)"
    assert xi_s.cells["other"].startswith("64D半自动闭塞")
    assert t["SI-X"][1].cells["route"] == "由 IG 至 甲站(虚拟)" and "64D半自动闭塞" in t["SI-X"][1].cells["other"]
    # the train and the shunting button of one signal are told apart
    assert t["XI-D4"][1].cells["buttons"] == "XIDA D4A"
    assert t["D1-D3"][1].cells["route"] == "由 D1 至 D3"


def test_enemies_are_signals_with_conditions_never_the_route_s_own() -> None:
    t = rows("jiaopei")
    d1_d3 = t["D1-D3"][1].cells["enemies"].split()
    assert "<(1),5>S" in d1_d3  # S-S3 is an enemy only with turnout 1 reverse and 5 normal
    assert "D1" not in d1_d3
    x_xi = t["X-XI"][1].cells["enemies"].split()
    assert "X" not in x_xi and "D2" in x_xi  # D2-D4 with 2 normal only; D2-XI always
    # only the train routes of SI are enemies of D3-D1
    assert "SI(列)" in t["D3-D1"][1].cells["enemies"].split()


def test_gaotie_variant_route_screen_doors_and_automatic_block() -> None:
    t = rows("gaotie")
    v = t["X-X3(BA1)"][1].cells
    assert v["mode"] == "变通" and v["buttons"] == "XLA BA1 X3LA" and v["route"] == "至 3G"
    assert "[5/7]" in v["turnouts"] and "3G站台门关闭" in v["other"] and "菱形交叉" in v["other"]
    assert t["X-X3"][1].cells["mode"] == "基本"
    dep = t["X3-XFCK"][1].cells
    assert dep["other"].startswith("自动闭塞 ") and "3G站台门关闭" in dep["other"]


def test_csv_and_json_carry_the_same_cells() -> None:
    table = build_table(load("jiaopei"))
    by_csv = {r["id"]: r for r in csv.DictReader(io.StringIO(as_csv(table)))}
    data = json.loads(as_json(table))
    jsonschema.validate(data, TABLE_SCHEMA)
    by_json = {r["id"]: r for g in data["groups"] for r in g["rows"]}
    assert set(by_csv) == set(by_json) == set(table.routes)
    for rid, row in by_json.items():
        assert {k: v for k, v in by_csv[rid].items() if k != "group"} == row
    assert data["routes"][0]["exit_link"] is None or isinstance(data["routes"][0]["exit_link"], str)
    assert "至 IG" in as_text(table)


def test_schema_command(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["table", "--schema"]) == 0
    assert json.loads(capsys.readouterr().out)["title"].startswith("liansuo interlocking table")


def test_xlsx_has_every_route_and_the_sign_off_block(tmp_path: Path, capsys: pytest.CaptureFixture[str]) -> None:
    out = tmp_path / "jiaopei.xlsx"
    assert main(["table", "jiaopei", "--format", "xlsx", "-o", str(out)]) == 0
    wb = load_workbook(out)
    table = build_table(load("jiaopei"))
    signed = signed_table(table)
    assert wb.sheetnames == [g.name for g in signed.groups]
    seen: set[str] = set()
    numbers = {r.cells["no"]: r.route for g in signed.groups for r in g.rows}
    for ws in wb.worksheets:
        values = [[str(c) if c is not None else "" for c in row] for row in ws.iter_rows(values_only=True)]
        assert values[1][:2] == ["序号", "进路"]
        seen |= {numbers[row[0]] for row in values[2:] if row and row[0] in numbers}
        text = "\n".join(" ".join(row) for row in values)
        for label in ("编制", "复核", "批准", "日期", "jiaopei.yaml", signed.sha256):
            assert label in text
        # printed as a signed 联锁表 is: A4 landscape, one page wide
        assert (int(ws.page_setup.paperSize), ws.page_setup.orientation) == (9, "landscape"), ws.title  # 9: A4
    assert seen == set(table.routes)


@pytest.mark.parametrize("station", ["jiaopei", "gaotie", "depot"])
def test_xlsx_opens_in_another_reader_with_every_route(tmp_path: Path, station: str) -> None:
    """Read back by calamine (a Rust reader of spreadsheet files, not the library that wrote it): every sheet opens
    and every route of the table stands on one, under its number."""
    from python_calamine import CalamineWorkbook

    out = tmp_path / f"{station}.xlsx"
    assert main(["table", station, "--format", "xlsx", "-o", str(out)]) == 0
    signed = signed_table(build_table(load(station)))
    wb = CalamineWorkbook.from_path(str(out))
    assert wb.sheet_names == [g.name for g in signed.groups]
    listed = {str(r.cells["no"]): r.route for g in signed.groups for r in g.rows}
    seen = set()
    for name in wb.sheet_names:
        rows = [[str(c) for c in row] for row in wb.get_sheet_by_name(name).to_python()]
        assert rows[1][:2] == ["序号", "进路"] and name in rows[0][0]
        seen |= {listed[row[0]] for row in rows[2:] if row and row[0] in listed}
    assert seen == set(build_table(load(station)).routes)


def test_xlsx_needs_an_output_file(capsys: pytest.CaptureFixture[str]) -> None:
    assert main(["table", "jiaopei", "--format", "xlsx"]) == 2
    assert "-o FILE" in capsys.readouterr().err


def test_a_table_that_cannot_be_written_says_so_and_leaves_no_file(tmp_path: Path,
                                                                   capsys: pytest.CaptureFixture[str]) -> None:
    for fmt, name in (("xlsx", "t.xlsx"), ("text", "t.txt")):
        target = tmp_path / "missing-folder" / name
        assert main(["table", "jiaopei", "--format", fmt, "-o", str(target)]) == 2  # a usage error
        err = capsys.readouterr().err
        assert f"cannot write {target}" in err and "Traceback" not in err
        assert not target.exists() and not target.parent.exists()
    good = tmp_path / "t.txt"
    assert main(["table", "jiaopei", "-o", str(good)]) == 0
    assert "至 IG" in good.read_text(encoding="utf-8") and not list(tmp_path.glob(".*.tmp"))


def test_a_route_signal_gives_a_transfer_group_between_receiving_and_departure() -> None:
    """A route signal (进路信号机) inside the station splits the movement: X receives up to it, and the route from it
    onto the track is a transfer (转线), grouped after the departures of its direction and named by its tracks."""
    minimal = Path(__file__).resolve().parent.parent / "src" / "liansuo" / "examples" / "stations" / "minimal.yaml"
    text = minimal.read_text("utf-8")
    text = text.replace("  - {id: XI, kind: starting", "  - {id: XL1, kind: route, at: J-1I, direction: down, "
                        "lamps: [U, L, H], buttons: [train]}\n  - {id: XI, kind: starting", 1)
    signed = signed_table(build_table(load_text(text, "m.yaml")))
    groups = [(g.name.split()[0], [r.route for r in g.rows]) for g in signed.groups]
    assert groups == [("下行接车", ["X-XL1"]), ("下行发车", ["XI-SBA"]), ("下行转线", ["XL1-XI"])]
    transfer = signed.groups[-1].rows[0]
    assert transfer.cells["route"] == "由 XL1 至 IG" and transfer.cells["signal"] == "XL1"
    assert "转线" in as_text(build_table(load_text(text, "m.yaml")))

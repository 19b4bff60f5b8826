"""The interlocking table as text (the signed layout, at most 120 columns), CSV and JSON.

Text and CSV print the cells of :mod:`.signed`, so they agree with each other and with the xlsx export
(:mod:`.xlsx`); JSON is the table's data (``InterlockingTable.as_dict``) with the signed groups added, after
the envelope every liansuo JSON report starts with (``liansuo``, ``schema``, ``ok``; see
:mod:`liansuo.kit.jsonreport`).

CSV and JSON are written row by row (:func:`write_csv`, :func:`write_json`): a hub's table lists hundreds of
thousands of conflicting pairs, and holding its whole JSON document (and then its text) at once took most of a
gigabyte. The JSON written is the same, byte for byte, as ``json.dumps(document, indent=2)``.
"""

from __future__ import annotations

import csv
import io
import json
from collections.abc import Iterator
from typing import TextIO

from liansuo.interlocking.table.build import InterlockingTable
from liansuo.interlocking.table.signed import COLUMNS, SignedTable, signed_table
from liansuo.kit.fit import columns as cell_width
from liansuo.kit.jsonreport import envelope
from liansuo.kit.printable import printable_block

WIDTH = 120
LEGEND = ("道岔 1 定位, (1) 反位, [1] 防护, {1} 带动, (1/3) 双动; 轨道区段 <5DG> 侵限; "
          "敌对信号 <1>D1 / <(1)>D1: 1 定位 / 反位时敌对; 按钮 XLA 列车, XDA 调车")


def wrap(text: str, width: int) -> list[str]:
    """``text`` in lines of at most ``width`` display columns, broken at spaces (a longer word is cut)."""
    lines: list[str] = []
    line = ""
    for word in text.split(" "):
        while cell_width(word) > width:  # cut a word that fits no line
            if line:
                lines.append(line)
                line = ""
            cut = 0
            while cell_width(word[:cut + 1]) <= width:
                cut += 1
            lines.append(word[:cut])
            word = word[cut:]
        candidate = f"{line} {word}" if line else word
        if cell_width(candidate) <= width:
            line = candidate
        else:
            lines.append(line)
            line = word
    if line or not lines:
        lines.append(line)
    return lines


def _pad(text: str, width: int) -> str:
    return text + " " * (width - cell_width(text))


def _line(cells: list[str]) -> str:
    return " ".join(_pad(c, col.width) for c, col in zip(cells, COLUMNS, strict=True)).rstrip()


def render_text(signed: SignedTable, table: InterlockingTable) -> str:
    lines = [f"联锁表 {signed.title}", f"station file {signed.file} sha256 {signed.sha256[:16]}",
             *wrap(LEGEND, WIDTH)]
    header = _line([c.heading for c in COLUMNS])
    for g in signed.groups:
        lines += ["", f"== {g.name} ==", header, "-" * WIDTH]
        for row in g.rows:
            wrapped = [wrap(row.cells[c.key], c.width) for c in COLUMNS]
            for i in range(max(len(w) for w in wrapped)):
                lines.append(_line([w[i] if i < len(w) else "" for w in wrapped]))
    lines.append("")
    throats = "; ".join(f"{k}: {' '.join(v)}" for k, v in table.throats.items())
    if throats:
        lines += wrap(f"咽喉 (引导总锁闭) {throats}", WIDTH)
    if table.unselectable:
        lines += wrap("无变通按钮, 不能排列的径路: " + "; ".join(table.unselectable), WIDTH)
    lines.append(f"{len(table.routes)} 条进路 routes")
    return printable_block("\n".join(lines))  # a note from the station file ('why:') may hold control characters


def as_text(table: InterlockingTable) -> str:
    return render_text(signed_table(table), table)


def as_csv(table: InterlockingTable) -> str:
    buf = io.StringIO()
    write_csv(table, buf)
    return buf.getvalue()


def write_csv(table: InterlockingTable, out: TextIO) -> None:
    w = csv.writer(out)
    w.writerow(["id", "group", *(c.key for c in COLUMNS)])
    for g in signed_table(table).groups:
        for row in g.rows:
            w.writerow([row.route, g.name, *(row.cells[c.key] for c in COLUMNS)])


def as_json(table: InterlockingTable) -> str:
    buf = io.StringIO()
    write_json(table, buf)
    return buf.getvalue()


def write_json(table: InterlockingTable, out: TextIO) -> None:
    """The table's document (no newline after it), one route and one group at a time; the signed groups are derived
    only once the routes are written (both at once would double the peak)."""
    out.write("{\n")
    for key, value in envelope("table", True).items():  # which liansuo wrote it, and the shape's version
        _member(out, key, value)
        out.write(",\n")
    _member(out, "station", table.station.id)
    out.write(',\n  "routes": ')
    _array(out, (r.as_dict() for r in table.routes.values()), bool(table.routes))
    out.write(",\n")
    _member(out, "throats", {k: list(v) for k, v in table.throats.items()})
    out.write(",\n")
    signed = signed_table(table)
    _member(out, "station_file", {"name": signed.file, "sha256": signed.sha256})
    out.write(',\n  "groups": ')
    _array(out, ({"name": g.name, "direction": g.direction, "category": g.category, "throat": g.throat,
                  "rows": [{"id": r.route, **r.cells} for r in g.rows]} for g in signed.groups), bool(signed.groups))
    out.write("\n}")


def _dumps(value: object, depth: int) -> str:
    """``value`` as json.dumps(indent=2) writes it ``depth`` levels down."""
    return json.dumps(value, ensure_ascii=False, indent=2).replace("\n", "\n" + "  " * depth)


def _member(out: TextIO, key: str, value: object) -> None:
    out.write(f"  {json.dumps(key, ensure_ascii=False)}: {_dumps(value, 1)}")


def _array(out: TextIO, items: Iterator[object], any_items: bool) -> None:
    if not any_items:
        out.write("[]")
        return
    out.write("[")
    for i, item in enumerate(items):
        out.write(("," if i else "") + "\n    " + _dumps(item, 2))
    out.write("\n  ]")

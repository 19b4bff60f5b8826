"""The interlocking table as text (the signed layout, at most 120 columns), CSV and JSON.

Text and CSV print the cells of :mod:`.signedtable`, so they agree with each other and with the xlsx export
(:mod:`.tablexlsx`); JSON is the table's data (``InterlockingTable.as_dict``) with the signed groups added.
"""

from __future__ import annotations

import csv
import io
import json

from .signedtable import COLUMNS, SignedTable, cell_width, signed_table
from .table import InterlockingTable

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
    return "\n".join(lines)


def as_text(table: InterlockingTable) -> str:
    return render_text(signed_table(table), table)


def as_csv(table: InterlockingTable) -> str:
    buf = io.StringIO()
    w = csv.writer(buf)
    w.writerow(["id", "group", *(c.key for c in COLUMNS)])
    for g in signed_table(table).groups:
        for row in g.rows:
            w.writerow([row.route, g.name, *(row.cells[c.key] for c in COLUMNS)])
    return buf.getvalue()


def as_json(table: InterlockingTable) -> str:
    data = table.as_dict()
    signed = signed_table(table)
    data["station_file"] = {"name": signed.file, "sha256": signed.sha256}
    data["groups"] = signed.as_dict()
    return json.dumps(data, ensure_ascii=False, indent=2)

"""The interlocking table as an xlsx workbook a design office prints and signs: one sheet per group of the signed
layout (:mod:`.signed`), each with the station, the table, and a sign-off block (编制 compiled, 复核 checked,
批准 approved, 日期 date) naming the station file and its SHA-256 and the liansuo version."""

from __future__ import annotations

from importlib import metadata
from pathlib import Path

from openpyxl import Workbook
from openpyxl.styles import Alignment, Border, Font, Side
from openpyxl.utils import get_column_letter

from liansuo.interlocking.table.signed import COLUMNS, SignedTable
from liansuo.kit.printable import printable

SIGN_OFF = ("编制 Compiled", "复核 Checked", "批准 Approved", "日期 Date")
_THIN = Side(style="thin")
_BOX = Border(left=_THIN, right=_THIN, top=_THIN, bottom=_THIN)
_BAD = str.maketrans({c: "_" for c in "[]:*?/\\"})


def _version() -> str:
    try:
        return metadata.version("liansuo")
    except metadata.PackageNotFoundError:  # pragma: no cover - a checkout that was never installed
        return "unknown"


def sheet_title(name: str, taken: set[str]) -> str:
    """A sheet title Excel accepts (31 characters, none of []:*?/\\), unique in the workbook."""
    base = name.translate(_BAD)[:28]
    title, n = base, 1
    while title in taken:
        n += 1
        title = f"{base}{n}"
    taken.add(title)
    return title


def write_xlsx(signed: SignedTable, path: Path) -> None:
    wb = Workbook()
    wb.remove(wb.active)  # type: ignore[arg-type]
    taken: set[str] = set()
    identity = f"站场文件 station file: {signed.file}  sha256: {signed.sha256}  liansuo {_version()}"
    for g in signed.groups:
        ws = wb.create_sheet(sheet_title(g.name, taken))
        ws.append([f"联锁表 {signed.title}  {g.name}"])
        ws["A1"].font = Font(bold=True, size=14)
        ws.append([c.heading for c in COLUMNS])
        for cell in ws[2]:
            cell.font, cell.border = Font(bold=True), _BOX
        for row in g.rows:
            ws.append([printable(row.cells[c.key]) for c in COLUMNS])  # a cell may quote the station file
            for cell in ws[ws.max_row]:
                cell.alignment, cell.border = Alignment(wrap_text=True, vertical="top"), _BOX
        for i, c in enumerate(COLUMNS, 1):
            ws.column_dimensions[get_column_letter(i)].width = c.width * 1.3 + 2
        ws.append([])
        ws.append([identity])
        for label in SIGN_OFF:
            ws.append([label, "", "", "签字 Signature"])
            ws.cell(ws.max_row, 2).border = Border(bottom=_THIN)
        ws.print_title_rows = "2:2"
        ws.page_setup.orientation = "landscape"
        ws.page_setup.paperSize = ws.PAPERSIZE_A4  # the signed 联锁表 is printed on A4, landscape
        ws.page_setup.fitToWidth = 1
        ws.page_setup.fitToHeight = 0
        ws.sheet_properties.pageSetUpPr.fitToPage = True
    wb.save(path)

"""``liansuo table STATION [--format text|csv|json|xlsx] [-o FILE] [--schema]``: the interlocking table (联锁表)
derived from the topology, in the signed layout (docs/interlocking-table.md)."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable
from pathlib import Path
from typing import TextIO

from liansuo.interlocking.table.route import InterlockingTable
from liansuo.kit.arguments import unwritable
from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.source import Diagnostic, StationError
from liansuo.stations.loader import load
from liansuo.stations.station import Station

Add = Callable[..., argparse.ArgumentParser]


def _table(station: Station) -> InterlockingTable | list[Diagnostic]:
    """The station's table under the default rules, or what its derivation refused (kept with the station, so that
    ``liansuo check`` derives it once for its errors and its warnings)."""
    from liansuo.interlocking.table.build import build_table

    try:
        return build_table(station)
    except StationError as exc:
        return exc.diagnostics


def check_errors(station: Station) -> list[Diagnostic]:
    """What ``liansuo table`` would refuse in a station that loaded (its ``overrides`` naming routes, turnouts,
    sections or enemies the topology does not give), each with the table's own message, for ``liansuo check``
    (handed to it by cli/main.py)."""
    table = station.derived(_table)
    return table if isinstance(table, list) else []


def check_warnings(station: Station) -> list[Diagnostic]:
    """The table's design warnings (paths it leaves out, and why), for ``liansuo check``."""
    table = station.derived(_table)
    return [] if isinstance(table, list) else list(table.warnings)


def cmd_table(args: argparse.Namespace) -> int:
    # the derivation (networkx) and the xlsx writer (openpyxl) load only when a table is asked for
    from liansuo.interlocking.table.build import build_table
    from liansuo.interlocking.table.schema import TABLE_SCHEMA
    from liansuo.interlocking.table.signed import signed_table
    from liansuo.interlocking.table.text import as_text, write_csv, write_json

    if args.schema:
        print(json.dumps(TABLE_SCHEMA, ensure_ascii=False, indent=2))
        return 0
    if args.station is None:
        return refuse("table", "a STATION is needed (or --schema)", Exit.USAGE)
    if args.format == "xlsx" and args.output is None:
        return refuse("table", "--format xlsx needs -o FILE", Exit.USAGE)
    if args.output is not None and (why := unwritable(Path(args.output))):
        return refuse("table", why, Exit.USAGE)
    try:
        table = build_table(load(args.station))
    except StationError as exc:
        return bad_input(exc)
    for w in table.warnings:  # paths the table leaves out, and why (as 'liansuo check' prints them)
        print(w, file=sys.stderr)
    if args.format == "xlsx":
        from liansuo.interlocking.table.xlsx import write_xlsx

        return _write(Path(args.output), lambda tmp: write_xlsx(signed_table(table), tmp))
    if args.format == "text":
        text = as_text(table) + "\n"
        if args.output is None:
            print(text, end="")
            return 0
        return _write(Path(args.output), lambda tmp: tmp.write_text(text, encoding="utf-8"))

    def write(out: TextIO) -> None:  # CSV and JSON go out row by row (a hub's would not fit in memory at once)
        if args.format == "csv":
            write_csv(table, out)
        else:
            write_json(table, out)
            out.write("\n")

    if args.output is None:
        write(sys.stdout)
        return 0
    return _write(Path(args.output), lambda tmp: _stream(tmp, write))


def _stream(path: Path, write: Callable[[TextIO], None]) -> None:
    with path.open("w", encoding="utf-8", newline="") as out:
        write(out)


def _write(path: Path, write: Callable[[Path], object]) -> int:
    """Write through a temporary file beside ``path``, so a failed write leaves no half-written table."""
    tmp = path.with_name(f".{path.name}.tmp")
    try:
        write(tmp)
        tmp.replace(path)
    except OSError as exc:
        tmp.unlink(missing_ok=True)
        return refuse("table", f"cannot write {path}: {exc.strerror or exc}; give -o a file in a folder you can "
                      "write to", Exit.USAGE)
    print(f"wrote {path}")
    return 0


def register(add: Add) -> None:
    sp = add("table", cmd_table, "print the interlocking table (联锁表) derived from the topology")
    sp.add_argument("station", nargs="?", help="bundled station name or path")
    sp.add_argument("--format", choices=("text", "csv", "json", "xlsx"), default="text",
                    help="text (default), csv, json or xlsx (xlsx needs -o)")
    sp.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of stdout (needed for xlsx)")
    sp.add_argument("--schema", action="store_true", help="print the JSON Schema of --format json and exit")

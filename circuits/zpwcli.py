"""``liansuo zpw STATION [--fault SECTION:capacitor:N:open|half|short ...] [--format text|json|csv] [-o FILE]``:
the command line of :mod:`.zpwfigures`."""

from __future__ import annotations

import argparse
import io
import json
import sys
from collections.abc import Callable
from pathlib import Path

from liansuo.stations.arguments import unwritable
from liansuo.stations.exitcodes import Exit, bad_input, refuse
from liansuo.stations.jsonreport import report
from liansuo.stations.loader import load
from liansuo.stations.source import StationError

from .zpwfigures import FAULT_FORM, FaultSpecError, as_text, collect_faults, section_rows, write_csv


def cmd_zpw(args: argparse.Namespace) -> int:
    if args.output and (why := unwritable(Path(args.output))):
        return refuse("zpw", why, Exit.USAGE)
    try:
        station = load(args.station)
    except StationError as exc:
        return bad_input(exc)
    try:
        faults = collect_faults(station, args.fault)
    except FaultSpecError as exc:
        return refuse("zpw", str(exc), Exit.USAGE)
    rows = section_rows(station, faults)
    if args.format == "csv":
        buf = io.StringIO()
        write_csv(buf, rows)
        text = buf.getvalue()
    elif args.format == "json":
        text = json.dumps(report("zpw", True, {"station": station.id, "sections": rows}), ensure_ascii=False,
                          indent=2) + "\n"
    else:
        text = as_text(station, rows) + "\n"
    if args.output is None:
        sys.stdout.write(text)
        return 0
    try:
        Path(args.output).write_text(text, encoding="utf-8", newline="")
    except OSError as exc:
        return refuse("zpw", f"cannot write {args.output}: {exc.strerror or exc}; give -o a file in a folder you can "
                      "write to", Exit.USAGE)
    print(f"wrote {args.output}")
    return 0


def register(add: Callable[[str, Callable[[argparse.Namespace], int], str], argparse.ArgumentParser]) -> None:
    """Add the ``zpw`` subcommand through the CLI's ``add(name, handler, help)``."""
    sp = add("zpw", cmd_zpw, "ZPW-2000A section figures: adjustment, shunt residual, cab current (with faults)")
    sp.add_argument("station", help="bundled station name or path")
    sp.add_argument("--fault", action="append", default=[], metavar=FAULT_FORM,
                    help="a compensation-capacitor fault (repeatable); capacitors are numbered from the lower end")
    sp.add_argument("--format", choices=("text", "json", "csv"), default="text", help="text (default), json or csv")
    sp.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of stdout")

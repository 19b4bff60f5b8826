"""``liansuo zpw STATION [--fault SECTION:capacitor:N:open|half|short ...] [--format text|json] [--csv FILE]``: the
command line of :mod:`.zpwfigures`."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable

from liansuo.stations.loader import load
from liansuo.stations.source import StationError

from .zpwfigures import FAULT_FORM, FaultSpecError, as_text, collect_faults, section_rows, write_csv


def cmd_zpw(args: argparse.Namespace) -> int:
    try:
        station = load(args.station)
    except StationError as exc:
        for d in exc.diagnostics:
            print(d, file=sys.stderr)
        return 1
    try:
        faults = collect_faults(station, args.fault)
    except FaultSpecError as exc:
        print(f"liansuo zpw: {exc}", file=sys.stderr)
        return 2
    rows = section_rows(station, faults)
    if args.csv:
        try:
            write_csv(args.csv, rows)
        except OSError as exc:
            print(f"liansuo zpw: cannot write {args.csv}: {exc.strerror}", file=sys.stderr)
            return 2
    if args.format == "json":
        print(json.dumps({"station": station.id, "sections": rows}, ensure_ascii=False, indent=2))
    else:
        print(as_text(station, rows))
    return 0


def register(add: Callable[[str, Callable[[argparse.Namespace], int], str], argparse.ArgumentParser]) -> None:
    """Add the ``zpw`` subcommand through the CLI's ``add(name, handler, help)``."""
    sp = add("zpw", cmd_zpw, "ZPW-2000A section figures: adjustment, shunt residual, cab current (with faults)")
    sp.add_argument("station", help="bundled station name or path")
    sp.add_argument("--fault", action="append", default=[], metavar=FAULT_FORM,
                    help="a compensation-capacitor fault (repeatable); capacitors are numbered from the lower end")
    sp.add_argument("--format", choices=("text", "json"), default="text")
    sp.add_argument("--csv", metavar="FILE", help="also write the table as CSV to FILE")

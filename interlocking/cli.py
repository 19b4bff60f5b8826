"""``liansuo table STATION [--format text|csv|json]``: the interlocking table (联锁表) derived from the topology."""

from __future__ import annotations

import argparse
from collections.abc import Callable

from liansuo.stations.cli import print_errors
from liansuo.stations.loader import load
from liansuo.stations.source import StationError

Add = Callable[..., argparse.ArgumentParser]


def cmd_table(args: argparse.Namespace) -> int:
    from .table import build_table  # the derivation (networkx) loads only when a table is asked for
    from .tableformat import as_csv, as_json, as_text

    try:
        table = build_table(load(args.station))
    except StationError as exc:
        return print_errors(exc)
    print({"text": as_text, "csv": as_csv, "json": as_json}[args.format](table), end="" if args.format == "csv"
          else "\n")
    return 0


def register(add: Add) -> None:
    sp = add("table", cmd_table, "print the interlocking table (联锁表) derived from the topology")
    sp.add_argument("station", help="bundled station name or path")
    sp.add_argument("--format", choices=("text", "csv", "json"), default="text")

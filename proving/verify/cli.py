"""``liansuo verify STATION [--format text|json] [--strict] [--route ID ...] [--no-pairs] [-v]``."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable

Add = Callable[..., argparse.ArgumentParser]


def cmd_verify(args: argparse.Namespace) -> int:
    from liansuo.stations.source import StationError

    from . import report_text, verify_station

    try:
        rep = verify_station(args.station, routes=args.route, pairs=not args.no_pairs, strict=args.strict)
    except StationError as exc:
        for d in exc.diagnostics:
            print(d, file=sys.stderr)
        print(f"{len(exc.diagnostics)} error(s); the station was not loaded", file=sys.stderr)
        return 1
    if args.format == "json":
        print(json.dumps(rep.as_dict(), ensure_ascii=False, indent=2))
    else:
        print(report_text(rep, verbose=args.verbose))
    return 0 if rep.ok else 1


def register(add: Add) -> None:
    sp = add("verify", cmd_verify, "run the interlocking test (联锁试验) of every route and pair of routes")
    sp.add_argument("station", help="bundled station name or path to a station YAML file")
    sp.add_argument("--format", choices=("text", "json"), default="text")
    sp.add_argument("--strict", action="store_true", help="design-rule warnings (dead zones ...) fail too")
    sp.add_argument("--route", action="append", metavar="ID", help="test only this route and its pairs (repeatable)")
    sp.add_argument("--no-pairs", action="store_true", help="skip the pairs of routes")
    sp.add_argument("-v", "--verbose", action="store_true", help="print the steps that reproduce each failure")
    sp.set_defaults(handler=cmd_verify)

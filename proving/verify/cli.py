"""``liansuo verify STATION [--format text|json] [--strict] [--route ID ...] [--no-pairs] [-v] [--workers N]
[--scheduler ADDRESS]``."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable

from ..spread import SpreadError, count

Add = Callable[..., argparse.ArgumentParser]


def cmd_verify(args: argparse.Namespace) -> int:
    from liansuo.stations.source import StationError

    from . import report_text, verify_station

    try:
        rep = verify_station(args.station, routes=args.route, pairs=not args.no_pairs, strict=args.strict,
                             workers=args.workers or (1 if args.scheduler else 0), scheduler=args.scheduler,
                             show_progress=None)
    except StationError as exc:
        for d in exc.diagnostics:
            print(d, file=sys.stderr)
        print(f"{len(exc.diagnostics)} error(s); the station was not loaded", file=sys.stderr)
        return 1
    except SpreadError as exc:
        print(f"liansuo verify: {exc}", file=sys.stderr)
        return 2
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
    sp.add_argument("--workers", type=count, default=0, metavar="N",
                    help="fan the test out on Dask over N local worker processes (default: run here, in one)")
    sp.add_argument("--scheduler", metavar="ADDRESS",
                    help="run on the Dask cluster whose scheduler is at ADDRESS (tcp://host:8786); docs/cluster.md")
    sp.set_defaults(handler=cmd_verify)

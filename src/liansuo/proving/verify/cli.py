"""``liansuo verify STATION [--format text|json] [--strict] [--route ID ...] [--no-pairs] [--simulate-all-pairs] [-v]
[--workers N] [--scheduler ADDRESS]``."""

from __future__ import annotations

import argparse
from collections.abc import Callable

from liansuo.kit.arguments import count
from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.jsonreport import print_report
from liansuo.proving.spread import SpreadError, add_wait_option

Add = Callable[..., argparse.ArgumentParser]


def cmd_verify(args: argparse.Namespace) -> int:
    from liansuo.kit.source import StationError
    from liansuo.proving.verify import report_text, verify_station

    try:
        rep = verify_station(args.station, routes=args.route, pairs=not args.no_pairs, strict=args.strict,
                             workers=args.workers or (1 if args.scheduler else 0), scheduler=args.scheduler,
                             show_progress=None, simulate_all=args.simulate_all_pairs,
                             cluster_wait_s=args.cluster_wait)
    except StationError as exc:
        return bad_input(exc)
    except SpreadError as exc:
        return refuse("verify", str(exc), Exit.USAGE)
    if args.route and not rep.results:
        return refuse("verify", f"no route {' or '.join(args.route)} in {rep.station}; 'liansuo table "
                      f"{args.station}' lists the routes", Exit.NOTHING_SELECTED)
    if args.format == "json":
        print_report("verify", rep.ok, rep.as_dict())
    else:
        print(report_text(rep, verbose=args.verbose))
    if not rep.ok:
        n = len(rep.failures)
        why = (f"{n} check{'s' if n != 1 else ''} failed" if n else
               f"{len(rep.warnings)} design-rule warning{'s' if len(rep.warnings) != 1 else ''} with --strict")
        return refuse("verify", f"{why} on {rep.station}", Exit.FAILED)
    return 0


def register(add: Add) -> None:
    sp = add("verify", cmd_verify, "run the interlocking test (联锁试验) of every route and pair of routes")
    sp.add_argument("station", help="bundled station name or path to a station YAML file")
    sp.add_argument("--format", choices=("text", "json"), default="text", help="text (default) or json")
    sp.add_argument("--strict", action="store_true", help="design-rule warnings (dead zones ...) fail too")
    sp.add_argument("--route", action="append", metavar="ID", help="test only this route and its pairs (repeatable)")
    sp.add_argument("--no-pairs", action="store_true", help="skip the pairs of routes")
    sp.add_argument("--simulate-all-pairs", action="store_true",
                    help="set and open together every compatible pair, also those apart (sharing no element), which "
                    "are otherwise proven without a simulation; slower on a large station ('liansuo docs verify')")
    sp.add_argument("-v", "--verbose", action="store_true", help="print the steps that reproduce each failure")
    sp.add_argument("--workers", type=count, default=0, metavar="N",
                    help="fan the test out on Dask over N local worker processes (default: run here, in one)")
    sp.add_argument("--scheduler", metavar="ADDRESS",
                    help="run on the Dask cluster whose scheduler is at ADDRESS (tcp://host:8786); "
                         "'liansuo docs cluster'")
    add_wait_option(sp)
    sp.set_defaults(handler=cmd_verify)

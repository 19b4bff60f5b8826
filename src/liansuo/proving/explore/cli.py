"""``liansuo explore STATION [--depth K] [--budget S] [--workers N | --scheduler ADDRESS] [--format text|json]
[--out DIR] [--routes N --faults N --occupied N --marks N --guide-locks N] [--no-reduction]``: every sequence of
commands, field events and time to a depth, judged by the safety oracle; a shortest reproducer per finding."""

from __future__ import annotations

import argparse
import sys
import uuid
from collections.abc import Callable, Iterator
from contextlib import ExitStack, contextmanager
from pathlib import Path

from liansuo.kit.arguments import count, positive_int
from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.fit import fit_all
from liansuo.kit.jsonreport import print_report
from liansuo.kit.source import StationError
from liansuo.proving.explore.actions import Bounds
from liansuo.proving.explore.report import as_dict, as_text
from liansuo.proving.explore.search import Expander, expand_here, expand_on, search
from liansuo.proving.spread import SpreadError, add_wait_option, client
from liansuo.rules import load_rules
from liansuo.stations.loader import load

Add = Callable[..., argparse.ArgumentParser]


def cmd_explore(args: argparse.Namespace) -> int:
    try:
        station = load(args.station)
    except StationError as exc:
        return bad_input(exc)
    rules = load_rules()
    bounds = Bounds(args.routes, args.faults, args.occupied, args.marks, args.guide_locks)
    reduce = not args.no_reduction
    workers = args.workers or (1 if args.scheduler else 0)
    expander = Expander(station, rules, bounds=bounds, reduce=reduce)  # here: the root, and the work when alone
    try:
        with ExitStack() as stack:
            if workers:
                c = stack.enter_context(client(workers, args.scheduler, args.cluster_wait))
                expand = expand_on(c, (uuid.uuid4().hex, station, rules, bounds, reduce))
            else:
                expand = expand_here(expander)
            tick = stack.enter_context(status(station.id))
            out = search(station, expand, expander.root_key, args.depth, budget_s=args.budget, progress=tick)
    except SpreadError as exc:
        return refuse("explore", str(exc), Exit.USAGE)
    rep = as_dict(out, args.station, args.depth, workers, bounds, reduce)
    if args.out:
        folder = Path(args.out)
        folder.mkdir(parents=True, exist_ok=True)
        for k, v in enumerate(rep["violations"]):
            (folder / f"explore-{station.id}-{k + 1}.yaml").write_text(v["reproducer"], encoding="utf-8")
    if args.format == "json":
        print_report("explore", not rep["violations"], rep)
    else:
        print(fit_all(as_text(rep)))
    if rep["violations"]:
        n = len(rep["violations"])
        return refuse("explore", f"{n} safety violation{'s' if n != 1 else ''} (a shortest reproducer for each is in "
                      "the report)", Exit.FAILED)
    return 0


Tick = Callable[[int, int, int, int, float], None]


@contextmanager
def status(name: str) -> Iterator[Tick]:
    """A live line on stderr when it is a terminal (nothing in a pipe, a file, CI): depth, frontier states expanded,
    states, transitions, rate."""
    if not sys.stderr.isatty():
        yield lambda *a: None
        return
    from rich.console import Console
    from rich.live import Live

    with Live(console=Console(stderr=True), transient=True, refresh_per_second=4) as panel:
        def tick(depth: int, done: int, states: int, transitions: int, seconds: float) -> None:
            rate = states / seconds if seconds else 0.0
            panel.update(f"explore {name}: depth {depth}, {done:,} of its frontier expanded; {states:,} states, "
                         f"{transitions:,} transitions, {rate:,.0f} states/s")
        yield tick


def register(add: Add) -> None:
    sp = add("explore", cmd_explore, "every sequence of commands, field events and time to a depth, under the safety "
             "oracle; a shortest reproducer per finding")
    sp.add_argument("station", help="bundled station name or path to a station YAML file")
    sp.add_argument("--depth", type=positive_int, default=4, metavar="K",
                    help="explore every sequence of up to K actions (default 4)")
    sp.add_argument("--budget", type=float, default=None, metavar="S",
                    help="stop after about S seconds (the report says how far it got)")
    sp.add_argument("--format", choices=("text", "json"), default="text", help="text (default) or json")
    sp.add_argument("--out", metavar="DIR", help="also write each reproducer to DIR/explore-STATION-N.yaml")
    sp.add_argument("--workers", type=count, default=0, metavar="N",
                    help="spread each level over Dask on N local worker processes (default: this process)")
    sp.add_argument("--scheduler", metavar="ADDRESS", help="spread it over the Dask cluster at ADDRESS instead")
    add_wait_option(sp)
    bounds = Bounds()
    sp.add_argument("--routes", type=count, default=bounds.routes, metavar="N",
                    help=f"routes set at once, guide aspects included (default {bounds.routes})")
    sp.add_argument("--faults", type=count, default=bounds.faults, metavar="N",
                    help=f"faults active at once (default {bounds.faults})")
    sp.add_argument("--occupied", type=count, default=bounds.occupied, metavar="N",
                    help=f"sections occupied at once by the explorer (default {bounds.occupied})")
    sp.add_argument("--marks", type=count, default=bounds.turnout_marks, metavar="N",
                    help=f"turnouts single-locked or single-blocked at once (default {bounds.turnout_marks})")
    sp.add_argument("--guide-locks", type=count, default=bounds.guide_locks, metavar="N",
                    help=f"throats under guide total lock at once (default {bounds.guide_locks})")
    sp.add_argument("--no-reduction", action="store_true",
                    help="explore every order of commuting actions too (the partial-order reduction off)")

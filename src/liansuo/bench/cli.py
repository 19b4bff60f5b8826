"""``liansuo bench [--quick] [--scale | --explore] [--format json|text] [--history FILE]``."""

from __future__ import annotations

import argparse
from collections.abc import Callable
from pathlib import Path

from liansuo.kit.exitcodes import Exit, refuse

Add = Callable[..., argparse.ArgumentParser]


def cmd_bench(args: argparse.Namespace) -> int:
    from liansuo.bench.history import unfit
    from liansuo.bench.report import main  # the benchmark loads the whole simulation: only when it runs

    if args.history is not None and (why := unfit(args.history)):
        return refuse("bench", why, Exit.BAD_INPUT if why.startswith(str(args.history)) else Exit.USAGE)
    return main(quick=args.quick, fmt=args.format, scale=args.scale, explore=args.explore, history=args.history)


def register(add: Add) -> None:
    sp = add("bench", cmd_bench, "benchmark table building and the interlocking cycle (hub and jiaopei), and the "
             "classroom server under attack")
    sp.add_argument("--quick", action="store_true", help="fewer cycles (under a minute)")
    sp.add_argument("--format", choices=("json", "text"), default="json", help="json (default) or text")
    sp.add_argument("--explore", action="store_true", help="instead, the figures of 'liansuo explore': saturation, "
                    "the depth reached on jiaopei in ten minutes, the mutation score of explore alone (the better part "
                    "of an hour; with --quick minutes): 'liansuo docs benchmark'")
    sp.add_argument("--history", type=Path, metavar="FILE", help="also append the report to FILE as one line of JSON "
                    "with the time and the commit (the project keeps docs/benchmark-history.jsonl)")
    sp.add_argument("--scale", action="store_true", help="also verify, soak and write the table of large hubs "
                    "(about a quarter of an hour in full on 2 cores; with --quick minutes): 'liansuo docs benchmark'")

"""``liansuo test FILE... [-k TEXT] [-v] [--junit-xml FILE]``: run YAML route-test scripts."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable
from pathlib import Path

from liansuo.stations.source import StationError

from .junit import write_junit
from .scripts import Outcome, parse_script, run_script

Add = Callable[..., argparse.ArgumentParser]


def cmd_test(args: argparse.Namespace) -> int:
    outcomes: list[Outcome] = []
    broken = 0
    for f in args.files:
        try:
            script = parse_script(Path(f))
            outcomes += run_script(script, args.k)
        except StationError as exc:
            for d in exc.diagnostics:
                print(d, file=sys.stderr)
            broken += 1
    for o in outcomes:
        if o.passed:
            print(f"PASS {o.script}: {o.name}")
            for h in o.hazards:
                print(f"    HAZARD {h}")
        else:
            print(f"FAIL {o.script}:{o.line}: {o.name}\n    {o.failure}")
            if args.verbose:
                for entry in o.log:
                    print(f"      {entry}")
    if args.junit_xml:
        write_junit(args.junit_xml, outcomes)
    passed = sum(o.passed for o in outcomes)
    failed = len(outcomes) - passed + broken
    print(f"{passed} passed, {failed} failed")
    return 0 if failed == 0 and outcomes else 1


def register(add: Add) -> None:
    sp = add("test", cmd_test, "run YAML route-test scripts")
    sp.add_argument("files", nargs="+", help="test script files")
    sp.add_argument("-k", metavar="TEXT", help="run only tests whose name contains TEXT")
    sp.add_argument("-v", "--verbose", action="store_true", help="print every step of failing tests")
    sp.add_argument("--junit-xml", metavar="FILE", help="also write a JUnit XML report")

"""``liansuo test FILE... [-k TEXT] [-v] [--junit-xml FILE]``: run YAML route-test scripts;
``liansuo run SCENARIO [--until DURATION] [--engine kinematic|sumo]``: run a scenario headless."""

from __future__ import annotations

import argparse
import sys
import time
from collections.abc import Callable
from datetime import datetime
from pathlib import Path

from liansuo.simulation.timeparse import parse_duration
from liansuo.simulation.trains.sumo import SumoEngineError
from liansuo.simulation.trains.sumo_export import SumoExportError, SumoUnavailable
from liansuo.stations.cli import print_errors
from liansuo.stations.source import StationError

from .junit import write_junit
from .scenario import parse_scenario, run_scenario
from .scripts import Outcome, Unrunnable, parse_script, run_script

Add = Callable[..., argparse.ArgumentParser]


def cmd_test(args: argparse.Namespace) -> int:
    started, start = datetime.now(), time.perf_counter()
    outcomes: list[Outcome] = []
    unrunnable: list[Unrunnable] = []
    for f in args.files:
        try:
            script = parse_script(Path(f))
            outcomes += run_script(script, args.k)
        except StationError as exc:
            for d in exc.diagnostics:
                print(d, file=sys.stderr)
            unrunnable.append(Unrunnable(f, [str(d) for d in exc.diagnostics]))
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
        write_junit(args.junit_xml, outcomes, unrunnable, started=started, time_s=time.perf_counter() - start)
    passed = sum(o.passed for o in outcomes)
    failed = len(outcomes) - passed + len(unrunnable)
    print(f"{passed} passed, {failed} failed")
    return 0 if failed == 0 and outcomes else 1


def cmd_run(args: argparse.Namespace) -> int:
    try:
        sc = parse_scenario(Path(args.scenario))
    except StationError as exc:
        return print_errors(exc)
    until = None
    if args.until:
        try:
            until = parse_duration(args.until)
        except ValueError as exc:
            print(f"--until: {exc}", file=sys.stderr)
            return 2
    try:
        status, sim = run_scenario(sc, until, engine=args.engine)
    except StationError as exc:
        return print_errors(exc)
    except (SumoUnavailable, SumoExportError, SumoEngineError) as exc:  # the SUMO engine could not start
        print(f"liansuo run --engine {args.engine}: {exc}", file=sys.stderr)
        return 2
    sim.close()
    return status


def register_run(add: Add) -> None:
    sp = add("run", cmd_run, "run a scenario headless and print the event log")
    sp.add_argument("scenario", help="scenario YAML file")
    sp.add_argument("--until", metavar="DURATION", help="keep running to this simulated time (e.g. 10min)")
    sp.add_argument("--engine", choices=("kinematic", "sumo"), default="kinematic",
                    help="what moves the trains: the built-in kinematic model (default) or Eclipse SUMO "
                         "(pip install 'liansuo[sumo]'; see docs/sumo.md)")


def register(add: Add) -> None:
    sp = add("test", cmd_test, "run YAML route-test scripts")
    sp.add_argument("files", nargs="+", help="test script files")
    sp.add_argument("-k", metavar="TEXT", help="run only tests whose name contains TEXT")
    sp.add_argument("-v", "--verbose", action="store_true", help="print every step of failing tests")
    sp.add_argument("--junit-xml", metavar="FILE", help="also write a JUnit XML report")

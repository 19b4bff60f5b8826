"""``liansuo test FILE... [-k EXPRESSION] [-v] [--format text|json] [--junit-xml FILE]``: run YAML route-test scripts;
``liansuo run SCENARIO [--until DURATION] [--engine kinematic|sumo] [--format text|json] [--plot FILE]
[--plot-csv FILE]``: run a scenario headless (and plot its trains, :mod:`.trainplot`).

Every file is read and every station loaded before anything runs, so a bad input stops the command with exit
status 3 and nothing run or written (docs/commands.md, "Exit status").
"""

from __future__ import annotations

import argparse
import time
from collections.abc import Callable
from datetime import datetime
from pathlib import Path

from liansuo.kit.arguments import unwritable
from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.fit import fit_all
from liansuo.kit.jsonreport import print_report
from liansuo.kit.plotfiles import add_plot_options, plot_problem, write_rows
from liansuo.kit.source import Diagnostic, StationError
from liansuo.proving.junit import write_junit
from liansuo.proving.keywords import expression
from liansuo.proving.scenario import ScenarioLog, parse_scenario, run_scenario, station_of
from liansuo.proving.scripts import Outcome, Script, Unrunnable, parse_script, run_script, script_station, selected
from liansuo.proving.trainplot import COLUMNS as TRACE_COLUMNS
from liansuo.proving.trainplot import TrainTrace, draw
from liansuo.simulation.timeparse import parse_duration
from liansuo.simulation.trains.sumo import SumoEngineError
from liansuo.simulation.trains.sumo_export import SumoExportError, SumoUnavailable
from liansuo.stations import limits
from liansuo.stations.station import Station

Add = Callable[..., argparse.ArgumentParser]
FORMATS = ("text", "json")


def _load_scripts(files: list[str]) -> tuple[list[tuple[Script, Station]], list[Unrunnable], int]:
    """Every script with its station; those that did not load (all reported at once on stderr, or as one JSON error
    object) and the exit status."""
    scripts: list[tuple[Script, Station]] = []
    unrunnable: list[Unrunnable] = []
    found: list[Diagnostic] = []
    what = "test script"
    for f in files:
        kind = "test script"
        try:
            script = parse_script(Path(f))
            kind = f"station of {f}"
            scripts.append((script, script_station(script)))
        except StationError as exc:
            found += exc.diagnostics
            what = f"input of {len(unrunnable) + 1} scripts" if unrunnable else kind
            unrunnable.append(Unrunnable(f, [str(d) for d in exc.diagnostics]))
    return scripts, unrunnable, bad_input(StationError(found), what) if found else 0


def cmd_test(args: argparse.Namespace) -> int:
    if args.junit_xml and (why := unwritable(Path(args.junit_xml), "--junit-xml")):
        return refuse("test", why, Exit.USAGE)
    started, start = datetime.now(), time.perf_counter()
    loaded, unrunnable, status = _load_scripts(args.files)
    if unrunnable:  # nothing runs; a CI server still gets the report, each such script an error (as pytest does)
        if args.junit_xml:
            write_junit(args.junit_xml, [], unrunnable, started=started, time_s=time.perf_counter() - start)
        return status
    if not any(selected(script, args.k) for script, _ in loaded):
        total = sum(len(script.tests) for script, _ in loaded)
        return refuse("test", f"no test matches -k {args.k!r} (of {total} test{'s' if total != 1 else ''} in "
                      f"{len(loaded)} script{'s' if len(loaded) != 1 else ''}); nothing ran", Exit.NOTHING_SELECTED)
    outcomes: list[Outcome] = []
    for script, station in loaded:
        outcomes += run_script(script, args.k, station)
    passed = sum(o.passed for o in outcomes)
    failed = len(outcomes) - passed
    if args.format == "json":
        print_report("test", failed == 0, {"scripts": list(args.files), "k": args.k, "passed": passed,
                                           "failed": failed, "tests": [o.as_dict() for o in outcomes]})
    else:
        _print_outcomes(outcomes, args.verbose)
        print(f"{passed} passed, {failed} failed")
    if args.junit_xml:
        write_junit(args.junit_xml, outcomes, started=started, time_s=time.perf_counter() - start)
    if failed:
        return refuse("test", f"{failed} of {len(outcomes)} test{'s' if len(outcomes) != 1 else ''} failed",
                      Exit.FAILED)
    return 0


def _print_outcomes(outcomes: list[Outcome], verbose: bool) -> None:
    lines: list[str] = []
    for o in outcomes:
        if o.passed:
            lines.append(f"PASS {o.script}: {o.name}")
            lines += [f"    HAZARD {h}" for h in o.hazards]
        else:
            lines += [f"FAIL {o.script}:{o.line}: {o.name}", f"    {o.failure}"]
            if verbose:
                lines += [f"      {entry}" for entry in o.log]
    if lines:
        print(fit_all(lines))


def cmd_run(args: argparse.Namespace) -> int:
    until = None
    if args.until:
        try:
            until = parse_duration(args.until)
        except ValueError as exc:
            return refuse("run", f"--until {args.until}: {exc}", Exit.USAGE)
        if why := limits.SCENARIO.problem("--until", until, args.until):
            return refuse("run", why, Exit.USAGE)
    if why := plot_problem(args):
        return refuse("run", why, Exit.USAGE)
    try:
        sc = parse_scenario(Path(args.scenario))
    except StationError as exc:
        return bad_input(exc, "scenario")
    try:
        station = station_of(sc)
    except StationError as exc:
        return bad_input(exc, f"station of {args.scenario}")
    log = ScenarioLog()
    text: list[str] | None = [] if args.format == "json" else None  # the text log is not printed with JSON
    trace = TrainTrace() if args.plot or args.plot_csv else None
    try:
        status, sim = run_scenario(sc, until, text, engine=args.engine, log=log, station=station,
                                   watch=trace.attach if trace else None)
    except (SumoUnavailable, SumoExportError, SumoEngineError) as exc:  # the SUMO engine could not start
        return refuse(f"run --engine {args.engine}", str(exc), Exit.USAGE)
    sim.close()
    if trace is not None:
        if args.plot_csv and (why := write_rows(args.plot_csv, TRACE_COLUMNS, trace.rows)):
            return refuse("run", why, Exit.USAGE)
        if args.plot and (why := draw(trace, f"{Path(sc.file).name}: the trains of {sc.station}", args.plot)):
            return refuse("run", why, Exit.USAGE)
        if args.format == "text":
            for f in (args.plot, args.plot_csv):
                if f:
                    print(f"wrote {f}")
    if args.format == "json":
        print_report("run", status == 0, {"scenario": sc.file, "station": sc.station, "engine": args.engine,
                                          "events": log.events, "problems": log.problems,
                                          "end_s": log.end_s, "trains": log.trains})
    if status:
        first = log.problems[0] if log.problems else None
        where = f"{sc.file}:{first['line']}: '{first['command']}'" if first else sc.file
        verdict = "was refused; the run stopped" if first and first["refused"] else "did not hold"
        return refuse("run", f"{where} {verdict}", Exit.FAILED)
    return 0


def register_run(add: Add) -> None:
    sp = add("run", cmd_run, "run a scenario headless and print the event log")
    sp.add_argument("scenario", help="scenario YAML file")
    sp.add_argument("--until", metavar="DURATION", help="keep running to this simulated time (e.g. 10min)")
    sp.add_argument("--engine", choices=("kinematic", "sumo"), default="kinematic",
                    help="what moves the trains: the built-in kinematic model (default) or Eclipse SUMO "
                         "(pip install 'liansuo[sumo]'; 'liansuo docs sumo')")
    sp.add_argument("--format", choices=FORMATS, default="text", help="text (default: the event log) or json")
    add_plot_options(sp, "time-distance and speed-distance plots of the trains")


def register(add: Add) -> None:
    sp = add("test", cmd_test, "run YAML route-test scripts")
    sp.add_argument("files", nargs="+", metavar="FILE", help="test script files")
    sp.add_argument("-k", metavar="EXPRESSION", type=expression,
                    help="run only the tests the expression selects, as pytest's -k: words of their names (any case; "
                    "a word matches a part of the test's name or its file's), and, or, not, parentheses; exit status "
                    "5 if none does")
    sp.add_argument("-v", "--verbose", action="store_true", help="print every step of failing tests")
    sp.add_argument("--format", choices=FORMATS, default="text", help="text (default) or json")
    sp.add_argument("--junit-xml", metavar="FILE", help="also write a JUnit XML report")

"""``liansuo zpw STATION [--fault SECTION:capacitor:N:open|half|short ...] [--format text|json|csv] [-o FILE]
[--plot FILE] [--plot-csv FILE] [--section ID]``: the command line of :mod:`.figures` (the table) and
:mod:`.plot` (the profiles along one section). ``liansuo zpw validate [--format text|json] [-o FILE]`` (the
reserved word ``validate`` in place of STATION; a station file of that name is ``./validate``) puts the model beside
the capacitor-fault article (:mod:`.validate`); ``liansuo zpw sweep`` (another reserved word) runs a parameter study
of one section (:mod:`.study`)."""

from __future__ import annotations

import argparse
import io
import json
from collections.abc import Callable
from pathlib import Path

from liansuo.circuits.zpw.figures import FAULT_FORM, FaultSpecError, as_text, collect_faults, section_rows, write_csv
from liansuo.kit.arguments import unwritable
from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.jsonreport import report
from liansuo.kit.output import deliver
from liansuo.kit.plotfiles import add_plot_options, plot_problem, write_rows
from liansuo.kit.source import Diagnostic, StationError
from liansuo.stations.loader import load
from liansuo.stations.station import Station

VALIDATE = "validate"
SWEEP = "sweep"
# the options only 'liansuo zpw sweep' takes, with their defaults (to tell them given)
SWEEP_OPTIONS: dict[str, object] = {"length": None, "layout": None, "carrier": [], "ballast": [], "capacitance": None,
                                    "faults": None, "samples": None, "ballast_tolerance": None,
                                    "capacitor_tolerance": None, "seed": None}


def cmd_zpw(args: argparse.Namespace) -> int:
    if args.station == SWEEP:
        return cmd_sweep(args)
    given = [f"--{k.replace('_', '-')}" for k, default in SWEEP_OPTIONS.items() if getattr(args, k) != default]
    if given:
        return refuse("zpw", f"{given[0]} goes with 'liansuo zpw sweep'", Exit.USAGE)
    if args.station == VALIDATE:
        return cmd_validate(args)
    if args.strict or args.sensitivity:
        word = "--strict" if args.strict else "--sensitivity"
        return refuse("zpw", f"{word} goes with 'liansuo zpw validate'", Exit.USAGE)
    if args.output and (why := unwritable(Path(args.output))):
        return refuse("zpw", why, Exit.USAGE)
    if why := plot_problem(args):
        return refuse("zpw", why, Exit.USAGE)
    if args.section and not (args.plot or args.plot_csv):
        return refuse("zpw", "--section chooses the section to plot: give --plot FILE or --plot-csv FILE with it",
                      Exit.USAGE)
    try:
        station = load(args.station)
    except StationError as exc:
        return bad_input(exc)
    try:
        faults = collect_faults(station, args.fault)
        plot = _plot_cases(station, args)
    except FaultSpecError as exc:
        return refuse("zpw", str(exc), Exit.USAGE)
    rows = section_rows(station, faults)
    if args.format == "csv":
        buf = io.StringIO()
        write_csv(buf, rows)
        text = buf.getvalue()
    elif args.format == "json":
        text = json.dumps(report("zpw", True, {"station": station.id, "sections": rows}), ensure_ascii=False,
                          indent=2) + "\n"
    else:
        text = as_text(station, rows) + "\n"
    if plot is not None and (why := _write_plot(station, args, *plot)):
        return refuse("zpw", why, Exit.USAGE)
    also = [f for f in (args.plot, args.plot_csv) if f] if args.format == "text" else []
    return deliver("zpw", text, args.output, also)


def cmd_validate(args: argparse.Namespace) -> int:
    """``liansuo zpw validate``: the article's rows beside the model's; exit status 0 (a report), or with
    ``--strict`` 1 when fewer rows than the target agree in magnitude."""
    given = [opt for opt, value in (("--fault", args.fault), ("--plot", args.plot), ("--plot-csv", args.plot_csv),
                                    ("--section", args.section)) if value]
    if given or args.format == "csv":
        what = given[0] if given else "--format csv"
        return refuse("zpw", f"{what} does not go with 'validate', which takes only --format text|json, -o FILE, "
                      "--strict and --sensitivity", Exit.USAGE)
    if args.output and (why := unwritable(Path(args.output))):
        return refuse("zpw", why, Exit.USAGE)
    from liansuo.circuits.zpw.validate import as_text, conclusions, sensitivity, sensitivity_text, summary, validate

    rows = validate()
    total = summary(rows)
    ok = total["target_met"] or not args.strict
    found = sensitivity() if args.sensitivity else None
    if args.format == "json":
        body = {"rows": list(rows), "summary": total, "conclusions": conclusions()}
        text = json.dumps(report("zpw validate", ok, body | ({"sensitivity": found} if found else {})),
                          ensure_ascii=False, indent=2) + "\n"
    else:
        text = as_text(rows) + "\n" + (sensitivity_text(found) + "\n" if found else "")
    status = deliver("zpw", text, args.output, [])
    if status == 0 and not ok:
        return refuse("zpw", f"--strict: the size agrees on {total['magnitude_ok']} of {total['rows']} rows, under "
                      f"the target of {total['target_share'] * 100:.0f} %", Exit.FAILED)
    return status


def _plot_cases(station: Station, args: argparse.Namespace) -> tuple[str, list[dict[int, str]]] | None:
    """The section to plot and its fault cases, or None when no plot is asked for."""
    if not (args.plot or args.plot_csv):
        return None
    from liansuo.circuits.zpw.plot import fault_cases, plotted_section

    section = plotted_section(station, args.section, args.fault)
    return section, fault_cases(station, section, args.fault)


def _write_plot(station: Station, args: argparse.Namespace, section: str, cases: list[dict[int, str]]) -> str:
    """The figure and its CSV; '' or why one could not be written."""
    from liansuo.circuits.zpw.plot import COLUMNS, draw, profiles, rows

    profs = profiles(station, section, cases)
    if args.plot_csv and (why := write_rows(args.plot_csv, COLUMNS, rows(section, profs))):
        return why
    return draw(station, section, profs, args.plot) if args.plot else ""


def check_warnings(station: Station) -> list[Diagnostic]:
    """``liansuo check``'s warnings for ZPW-2000A sections the adjustment table cannot adjust (:mod:`.adjust`);
    numpy loads only for a station with ZPW-2000A sections."""
    if not any(s.type.value == "zpw2000a" and s.carrier is not None for s in station.model.sections):
        return []
    from liansuo.circuits.zpw.adjust import station_warnings

    return station_warnings(station)


def cmd_sweep(args: argparse.Namespace) -> int:
    """``liansuo zpw sweep``: a study of one section (:mod:`.study`), its summary as text, or every row as CSV or
    JSON."""
    from liansuo.circuits.zpw import study as studies
    from liansuo.circuits.zpw.params import carrier_frequency_Hz
    from liansuo.circuits.zpw.study import COLUMNS, Study, csv_rows, run_study, summary_text

    given = [opt for opt, value in (("--fault", args.fault), ("--section", args.section), ("--strict", args.strict),
                                    ("--sensitivity", args.sensitivity)) if value]
    if given:
        return refuse("zpw", f"{given[0]} does not go with 'sweep' (its options: 'liansuo docs zpw2000a', 'Sweeps')",
                      Exit.USAGE)
    if args.output and (why := unwritable(Path(args.output))):
        return refuse("zpw", why, Exit.USAGE)
    if why := plot_problem(args):
        return refuse("zpw", why, Exit.USAGE)
    for carrier in args.carrier:
        try:
            carrier_frequency_Hz(carrier)
        except (KeyError, ValueError):
            return refuse("zpw", f"--carrier {carrier}: give a ZPW-2000A carrier (1700, 2000-1, 2600-2 ...)",
                          Exit.USAGE)
    study = Study(length_m=1400.0 if args.length is None else args.length, layout=args.layout or "conventional",
                  carriers=tuple(args.carrier) or Study.carriers, ballasts=tuple(args.ballast) or None,
                  capacitance_uF=args.capacitance, faults=args.faults or "none", samples=args.samples or 0,
                  ballast_tolerance=0.2 if args.ballast_tolerance is None else args.ballast_tolerance,
                  capacitor_tolerance=0.1 if args.capacitor_tolerance is None else args.capacitor_tolerance,
                  seed=1 if args.seed is None else args.seed)
    if why := study.problem():
        return refuse("zpw", why, Exit.USAGE)
    if study.length_m < 1.0 or study.length_m > 5000.0:
        return refuse("zpw", f"--length {study.length_m:g}: give 1 to 5000 metres", Exit.USAGE)
    if study.samples > 1_000_000:
        return refuse("zpw", f"--samples {study.samples}: at most 1000000", Exit.USAGE)
    try:
        rows, summary = run_study(study)
    except ValueError as exc:
        return refuse("zpw", str(exc), Exit.USAGE)
    if args.format == "csv":
        buf = io.StringIO()
        import csv

        w = csv.writer(buf, lineterminator="\n")
        w.writerow(COLUMNS)
        w.writerows(csv_rows(rows))
        text = buf.getvalue()
    elif args.format == "json":
        text = json.dumps(report("zpw sweep", True, {"summary": summary, "rows": rows}), ensure_ascii=False,
                          indent=2) + "\n"
    else:
        text = summary_text(summary) + "\n"
    if args.plot or args.plot_csv:
        carrier, ballast, profs = studies.profiles(study)
        if args.plot_csv and (why := write_rows(args.plot_csv, studies.PROFILE_COLUMNS,
                                                studies.profile_rows(carrier, ballast, profs))):
            return refuse("zpw", why, Exit.USAGE)
        if args.plot and (why := studies.draw(study, carrier, ballast, profs, args.plot)):
            return refuse("zpw", why, Exit.USAGE)
    also = [f for f in (args.plot, args.plot_csv) if f] if args.format == "text" else []
    return deliver("zpw", text, args.output, also)


def register(add: Callable[[str, Callable[[argparse.Namespace], int], str], argparse.ArgumentParser]) -> None:
    """Add the ``zpw`` subcommand through the CLI's ``add(name, handler, help)``."""
    sp = add("zpw", cmd_zpw, "ZPW-2000A section figures: adjustment, shunt residual, cab current (with faults)")
    sp.add_argument("station", help="bundled station name or path; 'validate': the model against the capacitor-fault "
                    "article (--format text|json, -o FILE, --strict); 'sweep': a parameter study of one section")
    sp.add_argument("--fault", action="append", default=[], metavar=FAULT_FORM,
                    help="a compensation-capacitor fault (repeatable); capacitors are numbered from the lower end")
    sp.add_argument("--format", choices=("text", "json", "csv"), default="text", help="text (default), json or csv")
    sp.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of stdout")
    add_plot_options(sp, "the shunt residual and the cab-signal current along one section, healthy and faulted")
    sp.add_argument("--strict", action="store_true", help="with 'validate': exit status 1 when fewer rows than the "
                    "target (80 %%) agree with the article in magnitude")
    sp.add_argument("--sensitivity", action="store_true", help="with 'validate': also how the score moves with each "
                    "parameter the article does not publish")
    study = sp.add_argument_group("sweep", "liansuo zpw sweep: one section over carriers, ballasts, capacitor faults "
                                           "or a Monte Carlo of tolerances ('liansuo docs zpw2000a', 'Sweeps')")
    study.add_argument("--length", type=float, metavar="M", help="the section's length (default 1400 m)")
    study.add_argument("--layout", choices=("conventional", "passenger-line", "passenger-station"),
                       help="whose standard capacitors and design ballast (default conventional)")
    study.add_argument("--carrier", action="append", default=[], metavar="HZ",
                       help="a carrier, repeatable (default 1700-1, 2000-1, 2300-1, 2600-1)")
    study.add_argument("--ballast", action="append", default=[], type=float, metavar="OHM_KM",
                       help="a ballast resistance, repeatable (default the layout's design minimum)")
    study.add_argument("--capacitance", type=float, metavar="UF", help="every capacitor's value (default the layout's)")
    study.add_argument("--faults", choices=("none", "single-open", "single-half", "single"),
                       help="the capacitor fault cases: none (default), every single one open, at -50 %%, or both")
    study.add_argument("--samples", type=int, metavar="N", help="a Monte Carlo of about N healthy sections a carrier")
    study.add_argument("--ballast-tolerance", type=float, metavar="F", help="Monte Carlo: ballast within +-F (0.2)")
    study.add_argument("--capacitor-tolerance", type=float, metavar="F",
                       help="Monte Carlo: each capacitor within +-F of its value (0.1)")
    study.add_argument("--seed", type=int, metavar="N", help="Monte Carlo: the random seed (1)")
    sp.add_argument("--section", metavar="ID", help="the section to plot (default: the one the faults name, else the "
                    "first ZPW-2000A section)")

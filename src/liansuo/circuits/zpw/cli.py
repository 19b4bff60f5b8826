"""``liansuo zpw STATION [--fault SECTION:capacitor:N:open|half|short ...] [--format text|json|csv] [-o FILE]
[--plot FILE] [--plot-csv FILE] [--section ID]``: the command line of :mod:`.figures` (the table) and
:mod:`.plot` (the profiles along one section). ``liansuo zpw validate [--format text|json] [-o FILE]`` (the
reserved word ``validate`` in place of STATION; a station file of that name is ``./validate``) puts the model beside
the capacitor-fault article (:mod:`.validate`)."""

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


def cmd_zpw(args: argparse.Namespace) -> int:
    if args.station == VALIDATE:
        return cmd_validate(args)
    if args.strict:
        return refuse("zpw", "--strict goes with 'liansuo zpw validate'", Exit.USAGE)
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
        return refuse("zpw", f"{what} does not go with 'validate', which takes only --format text|json, -o FILE "
                      "and --strict", Exit.USAGE)
    if args.output and (why := unwritable(Path(args.output))):
        return refuse("zpw", why, Exit.USAGE)
    from liansuo.circuits.zpw.validate import as_text, conclusions, summary, validate

    rows = validate()
    total = summary(rows)
    ok = total["target_met"] or not args.strict
    if args.format == "json":
        text = json.dumps(report("zpw validate", ok, {"rows": list(rows), "summary": total,
                                                      "conclusions": conclusions()}),
                          ensure_ascii=False, indent=2) + "\n"
    else:
        text = as_text(rows) + "\n"
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


def register(add: Callable[[str, Callable[[argparse.Namespace], int], str], argparse.ArgumentParser]) -> None:
    """Add the ``zpw`` subcommand through the CLI's ``add(name, handler, help)``."""
    sp = add("zpw", cmd_zpw, "ZPW-2000A section figures: adjustment, shunt residual, cab current (with faults)")
    sp.add_argument("station", help="bundled station name or path; 'validate': the model against the capacitor-fault "
                    "article (--format text|json, -o FILE)")
    sp.add_argument("--fault", action="append", default=[], metavar=FAULT_FORM,
                    help="a compensation-capacitor fault (repeatable); capacitors are numbered from the lower end")
    sp.add_argument("--format", choices=("text", "json", "csv"), default="text", help="text (default), json or csv")
    sp.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of stdout")
    add_plot_options(sp, "the shunt residual and the cab-signal current along one section, healthy and faulted")
    sp.add_argument("--strict", action="store_true", help="with 'validate': exit status 1 when fewer rows than the "
                    "target (80 %%) agree with the article in magnitude")
    sp.add_argument("--section", metavar="ID", help="the section to plot (default: the one the faults name, else the "
                    "first ZPW-2000A section)")

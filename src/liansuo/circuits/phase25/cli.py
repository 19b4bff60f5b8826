"""``liansuo 25hz STATION --section ID [--format text|json] [-o FILE] [--plot FILE] [--plot-csv FILE]``: a 25 Hz
section against ballast resistance, the command line of :mod:`.sweep`."""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from pathlib import Path

from liansuo.circuits.phase25 import sweep as sweeps
from liansuo.circuits.phase25.sweep import SectionChoiceError
from liansuo.kit.arguments import unwritable
from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.jsonreport import report
from liansuo.kit.output import deliver
from liansuo.kit.plotfiles import add_plot_options, plot_problem, write_rows
from liansuo.kit.source import StationError
from liansuo.stations.loader import load


def cmd_25hz(args: argparse.Namespace) -> int:
    if args.output and (why := unwritable(Path(args.output))):
        return refuse("25hz", why, Exit.USAGE)
    if why := plot_problem(args):
        return refuse("25hz", why, Exit.USAGE)
    try:
        station = load(args.station)
    except StationError as exc:
        return bad_input(exc)
    try:
        sweeps.check_section(station, args.section)
    except SectionChoiceError as exc:
        return refuse("25hz", str(exc), Exit.USAGE)
    model = sweeps.section_model(station, args.section)
    points = sweeps.sweep(model, sweeps.ballast_points())
    if args.plot_csv and (why := write_rows(args.plot_csv, sweeps.COLUMNS, sweeps.rows(args.section, points))):
        return refuse("25hz", why, Exit.USAGE)
    if args.plot and (why := sweeps.draw(station, args.section, model, points, args.plot)):
        return refuse("25hz", why, Exit.USAGE)
    shown = [q for q in points if q.ballast_ohm_km in sweeps.TEXT_POINTS]
    if args.format == "json":
        text = json.dumps(report("25hz", True, {
            "station": station.id, "section": args.section, "length_m": round(model.length_m, 2),
            "feed_tap_V": model.params.feed_tap_V, "design_ballast_ohm_km": model.params.ballast_ohm_km,
            "points": [{k: v for k, v in r.items() if k != "section"} for r in sweeps.rows(args.section, shown)]},
            ), ensure_ascii=False, indent=2) + "\n"
    else:
        text = sweeps.as_text(station, args.section, model, shown) + "\n"
    also = [f for f in (args.plot, args.plot_csv) if f] if args.format == "text" else []
    return deliver("25hz", text, args.output, also)


def register(add: Callable[[str, Callable[[argparse.Namespace], int], str], argparse.ArgumentParser]) -> None:
    """Add the ``25hz`` subcommand through the CLI's ``add(name, handler, help)``."""
    sp = add("25hz", cmd_25hz, "a 25 Hz phase-sensitive section against ballast resistance: track voltage, phase, "
             "worst shunt residual")
    sp.add_argument("station", help="bundled station name or path")
    sp.add_argument("--section", metavar="ID", required=True, help="the 25 Hz section")
    sp.add_argument("--format", choices=("text", "json"), default="text", help="text (default) or json")
    sp.add_argument("-o", "--output", metavar="FILE", help="write to FILE instead of stdout")
    add_plot_options(sp, "the track voltage and phase against ballast")

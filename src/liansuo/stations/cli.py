"""``liansuo stations [--format text|json]``, ``liansuo check STATION [--format text|json]`` and ``liansuo generate
hub --turnouts N --tracks M [-o FILE]``: the station files (``liansuo schema`` is in ``cli/schemas.py``, with the
other kinds)."""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable

from liansuo.kit.arguments import positive_int, unwritable
from liansuo.kit.exitcodes import Exit, bad_input, refuse
from liansuo.kit.fit import fit
from liansuo.kit.jsonreport import print_report
from liansuo.kit.source import Diagnostic, StationError
from liansuo.stations.library import bundled, describe
from liansuo.stations.loader import load
from liansuo.stations.station import Station
from liansuo.stations.summary import summarise, summary_text

Add = Callable[..., argparse.ArgumentParser]
FORMATS = ("text", "json")
Warnings = Callable[[Station], list[Diagnostic]]
# a station's field I/O point map checked against it (fieldio/cli.py): every problem, and what the map wires
PointsCheck = Callable[[Station, str], tuple[list[Diagnostic], str]]


def cmd_stations(args: argparse.Namespace) -> int:
    if args.format == "json":
        print_report("stations", True, {"stations": [{"name": name, "file": str(path), "description": describe(path)}
                                                     for name, path in bundled().items()]})
        return 0
    for name, path in bundled().items():
        print(fit(f"{name:10} {describe(path)}", indent=" " * 11))
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    try:
        station = load(args.station)
        for errors in args.more_errors:  # what the layers above refuse (the table's overrides), from cli/main.py
            found = errors(station)
            if found:
                raise StationError(found)
    except StationError as exc:
        return bad_input(exc, station=args.station)
    for more in args.more_warnings:  # checks of the layers above, handed in by the command line (cli/main.py)
        station.warnings = [*station.warnings, *more(station)]
    wired = ""
    if getattr(args, "points", None):
        found, wired = args.points_check(station, args.points)
        errors = [d for d in found if d.severity == "error"]
        if errors:
            return bad_input(StationError(errors), "point map", station=args.station)
        station.warnings = [*station.warnings, *found]
    if args.format == "json":
        print_report("check", True, {**summarise(station), **({"points": wired} if wired else {})})
    else:
        print(summary_text(station) + (f"\npoint map {args.points}: {wired}" if wired else ""))
    return 0


def cmd_generate(args: argparse.Namespace) -> int:
    """A generated hub station file (the benchmark's), on stdout or in ``-o FILE``."""
    from pathlib import Path

    from liansuo.stations.hubgen import generate_hub
    from liansuo.stations.loader import load_text

    if args.output and (why := unwritable(Path(args.output))):
        return refuse("generate hub", why, Exit.USAGE)
    try:
        text = generate_hub(args.turnouts, args.tracks)
    except ValueError as exc:
        return refuse("generate hub", str(exc), Exit.USAGE)
    name = args.output or f"<hub{args.turnouts}>"
    load_text(text, name)  # what is written always loads: the generator's own check
    if args.output:
        try:
            Path(args.output).write_text(text, encoding="utf-8")
        except OSError as exc:
            return refuse("generate hub", f"cannot write {args.output}: {exc.strerror or exc}; give -o a file in a "
                          "folder you can write to", Exit.USAGE)
        print(f"wrote {args.output}: a hub with {args.turnouts} turnouts and {args.tracks} station tracks "
              f"(liansuo check {args.output})", file=sys.stderr)
    else:
        sys.stdout.write(text)
    return 0


def register(add: Add, more_warnings: tuple[Warnings, ...] = (), more_errors: tuple[Warnings, ...] = (),
             points_check: PointsCheck | None = None) -> None:
    """Add ``stations``, ``check`` and ``generate``; ``more_warnings``: design checks of higher layers that
    ``check`` adds to the station's own (the track-circuit physics: ``circuits/zpw/cli.py``); ``more_errors``: what
    higher layers refuse in a station that loaded (the interlocking table: ``interlocking/table/cli.py``), so that
    ``check`` accepts only what every command accepts; ``points_check``: ``check --points FILE``, a field I/O point
    map checked against the station (``fieldio/cli.py``)."""
    sp = add("stations", cmd_stations, "list the bundled stations")
    sp.add_argument("--format", choices=FORMATS, default="text", help="text (default) or json")
    sp = add("check", cmd_check, "validate a station file and summarise it")
    sp.set_defaults(more_warnings=more_warnings, more_errors=more_errors)
    sp.add_argument("station", help="bundled station name or path to a station YAML file")
    sp.add_argument("--format", choices=FORMATS, default="text", help="text (default) or json")
    if points_check is not None:
        sp.set_defaults(points_check=points_check)
        sp.add_argument("--points", metavar="FILE", help="also check this field I/O point map against the station "
                                                         "('liansuo docs field-mode')")
    sp = add("generate", cmd_generate, "write a generated station file (a hub of any size, for stress tests)")
    sp.add_argument("kind", choices=("hub",), help="what to generate: 'hub', a double-ended yard of parallel tracks")
    sp.add_argument("--turnouts", type=positive_int, required=True, metavar="N", help="turnouts in the hub")
    sp.add_argument("--tracks", type=positive_int, required=True, metavar="M", help="station tracks in the hub")
    sp.add_argument("-o", "--output", metavar="FILE", help="write the station file here (default: stdout)")


"""``liansuo stations``, ``liansuo check STATION [--format text|json]`` and ``liansuo generate hub --turnouts N
--tracks M [-o FILE]``: the station files (``liansuo schema`` is in ``cli/schemas.py``, with the other kinds)."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable

from .library import bundled, describe
from .loader import load
from .source import StationError
from .summary import summarise, summary_text

Add = Callable[..., argparse.ArgumentParser]


def print_errors(exc: StationError) -> int:
    """Every diagnostic of a station that did not load, on stderr; the exit status 1."""
    for d in exc.diagnostics:
        print(d, file=sys.stderr)
    n = len(exc.diagnostics)
    print(f"{n} error{'s' if n != 1 else ''}; the station was not loaded", file=sys.stderr)
    return 1


def cmd_stations(args: argparse.Namespace) -> int:
    for name, path in bundled().items():
        print(f"{name:10} {describe(path)}")
    return 0


def cmd_check(args: argparse.Namespace) -> int:
    try:
        station = load(args.station)
    except StationError as exc:
        if args.format == "json":
            print(json.dumps({"station": args.station, "ok": False,
                              "errors": [d.as_dict() for d in exc.diagnostics]}, ensure_ascii=False, indent=2))
            return 1
        return print_errors(exc)
    if args.format == "json":
        print(json.dumps({"ok": True, **summarise(station)}, ensure_ascii=False, indent=2))
    else:
        print(summary_text(station))
    return 0


def cmd_generate(args: argparse.Namespace) -> int:
    """A generated hub station file (the benchmark's), on stdout or in ``-o FILE``."""
    from pathlib import Path

    from .hubgen import generate_hub
    from .loader import load_text

    try:
        text = generate_hub(args.turnouts, args.tracks)
    except ValueError as exc:
        print(f"liansuo generate hub: {exc}", file=sys.stderr)
        return 2
    name = args.output or f"<hub{args.turnouts}>"
    load_text(text, name)  # what is written always loads: the generator's own check
    if args.output:
        Path(args.output).write_text(text, encoding="utf-8")
        print(f"wrote {args.output}: a hub with {args.turnouts} turnouts and {args.tracks} station tracks "
              f"(liansuo check {args.output})", file=sys.stderr)
    else:
        sys.stdout.write(text)
    return 0


def register(add: Add) -> None:
    add("stations", cmd_stations, "list the bundled stations")
    sp = add("check", cmd_check, "validate a station file and summarise it")
    sp.add_argument("station", help="bundled station name or path to a station YAML file")
    sp.add_argument("--format", choices=("text", "json"), default="text")
    sp = add("generate", cmd_generate, "write a generated station file (a hub of any size, for stress tests)")
    sp.add_argument("kind", choices=("hub",), help="what to generate: 'hub', a double-ended yard of parallel tracks")
    sp.add_argument("--turnouts", type=_positive, required=True, metavar="N", help="turnouts in the hub")
    sp.add_argument("--tracks", type=_positive, required=True, metavar="M", help="station tracks in the hub")
    sp.add_argument("-o", "--output", metavar="FILE", help="write the station file here (default: stdout)")


def _positive(text: str) -> int:
    try:
        value = int(text)
    except ValueError:
        raise argparse.ArgumentTypeError(f"{text!r} is not a whole number") from None
    if value < 1:
        raise argparse.ArgumentTypeError(f"{value} is not a positive number")
    return value

"""``liansuo stations``, ``liansuo check STATION [--format text|json]`` and ``liansuo schema``: the station files."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable

from .library import bundled, describe
from .loader import load
from .schema import StationFile
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


def cmd_schema(args: argparse.Namespace) -> int:
    schema = StationFile.model_json_schema(by_alias=True)
    schema["$schema"] = "https://json-schema.org/draft/2020-12/schema"
    schema["title"] = "liansuo station file"
    print(json.dumps(schema, ensure_ascii=False, indent=2))
    return 0


def register(add: Add) -> None:
    add("stations", cmd_stations, "list the bundled stations")
    sp = add("check", cmd_check, "validate a station file and summarise it")
    sp.add_argument("station", help="bundled station name or path to a station YAML file")
    sp.add_argument("--format", choices=("text", "json"), default="text")
    add("schema", cmd_schema, "print the JSON Schema of the station format")

"""The ``liansuo`` command line."""

from __future__ import annotations

import argparse
import json
import sys
from collections.abc import Callable, Sequence

from liansuo.stations.library import bundled, describe
from liansuo.stations.loader import load
from liansuo.stations.schema import StationFile
from liansuo.stations.source import StationError
from liansuo.stations.summary import summarise, summary_text

Handler = Callable[[argparse.Namespace], int]


def _print_errors(exc: StationError) -> int:
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
        return _print_errors(exc)
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


def cmd_table(args: argparse.Namespace) -> int:
    from liansuo.interlocking.table import build_table
    from liansuo.interlocking.tableformat import as_csv, as_json, as_text

    try:
        table = build_table(load(args.station))
    except StationError as exc:
        return _print_errors(exc)
    print({"text": as_text, "csv": as_csv, "json": as_json}[args.format](table), end="" if args.format == "csv"
          else "\n")
    return 0


def build_parser() -> argparse.ArgumentParser:
    p = argparse.ArgumentParser(prog="liansuo", description="Station signalling and interlocking simulator (联锁)")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")

    def add(name: str, handler: Handler, help_: str) -> argparse.ArgumentParser:
        sp = sub.add_parser(name, help=help_, description=help_)
        sp.set_defaults(handler=handler)
        return sp

    add("stations", cmd_stations, "list the bundled stations")
    sp = add("check", cmd_check, "validate a station file and summarise it")
    sp.add_argument("station", help="bundled station name or path to a station YAML file")
    sp.add_argument("--format", choices=("text", "json"), default="text")
    add("schema", cmd_schema, "print the JSON Schema of the station format")
    sp = add("table", cmd_table, "print the interlocking table (联锁表) derived from the topology")
    sp.add_argument("station", help="bundled station name or path")
    sp.add_argument("--format", choices=("text", "csv", "json"), default="text")
    from liansuo.bench.cli import register as register_bench
    from liansuo.circuits.zpwcli import register as register_zpw
    from liansuo.proving.cli import register_run

    register_zpw(add)
    register_bench(add)
    register_run(add)
    _register_plugins(add)
    return p


def _register_plugins(add: Callable[..., argparse.ArgumentParser]) -> None:
    """Subcommands of the layers above (proving: ``liansuo test``, ``verify``, ``soak``; the console: ``liansuo
    tui``, ``replay``), found through the ``liansuo.commands`` entry-point group so this module never imports
    them."""
    from importlib.metadata import entry_points

    for ep in entry_points(group="liansuo.commands"):
        try:
            register = ep.load()
        except ImportError as exc:  # a broken plugin must not take the rest of the command line down
            print(f"liansuo: subcommand '{ep.name}' unavailable: {exc}", file=sys.stderr)
            continue
        register(add)


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    args = parser.parse_args(argv)
    handler: Handler | None = getattr(args, "handler", None)
    if handler is None:
        parser.print_help()
        return 2
    try:
        return handler(args)
    except BrokenPipeError:  # e.g. piped into head
        return 0
    except KeyboardInterrupt:
        return 130


if __name__ == "__main__":
    sys.exit(main())

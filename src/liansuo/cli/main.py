"""The ``liansuo`` command: every subcommand, registered from the rooms' own ``register(add)`` functions.

The list is explicit: the package is one, so there is no plugin group to search. A room's register function
imports only what its arguments need; what a subcommand runs is loaded when it runs, so ``liansuo check`` never
loads the console (Textual) and the console never slows the other subcommands.
"""

from __future__ import annotations

import argparse
import sys
from collections.abc import Callable, Sequence
from functools import partial
from itertools import pairwise
from typing import NoReturn

from liansuo.bench import cli as bench
from liansuo.circuits.phase25 import cli as phase25cli
from liansuo.circuits.zpw import cli as zpwcli
from liansuo.classroom import cli as exercise
from liansuo.cli import completion, docs, schemas
from liansuo.fieldio import cli as fieldcli
from liansuo.interlocking.table import cli as interlocking
from liansuo.kit.exitcodes import Exit, refuse
from liansuo.kit.extras import needed
from liansuo.kit.jsonreport import errors_as_json, print_error, version
from liansuo.proving import cli as proving
from liansuo.proving.explore import cli as explore
from liansuo.proving.fuzz import cli as fuzz
from liansuo.proving.mutation import cli as mutation
from liansuo.proving.soak import cli as soakcli
from liansuo.proving.verify import cli as verify
from liansuo.remote import cli as remote
from liansuo.server import cli as server
from liansuo.stations import cli as stations
from liansuo.tui import cli as tui

Handler = Callable[[argparse.Namespace], int]
Add = Callable[[str, Handler, str], argparse.ArgumentParser]

# in the order of the help: the station, its table and track circuits, proving it, timing it, the console
REGISTER: tuple[Callable[[Add], None], ...] = (
    # stations, check, generate
    partial(stations.register, more_warnings=(zpwcli.check_warnings, interlocking.check_warnings),
            more_errors=(interlocking.check_errors,), points_check=fieldcli.check_points),
    schemas.register,  # schema
    interlocking.register,  # table
    zpwcli.register,  # zpw
    phase25cli.register,  # 25hz
    proving.register_run,  # run
    proving.register,  # test
    verify.register,  # verify
    soakcli.register,  # soak
    explore.register,  # explore
    mutation.register,  # mutate
    fuzz.register,  # fuzz
    bench.register,  # bench
    partial(tui.register, connect=remote.cmd_connect),  # tui (--connect: the classroom's client)
    tui.register_replay,  # replay
    exercise.register,  # exercise
    server.register,  # serve
    fieldcli.register,  # field-sim, field-map
    docs.register,  # docs
)


# the commands that need an extra (kit/extras.py), and the options that make a command need the cluster extra
NEEDS = {"tui": "console", "replay": "console", "serve": "serve"}
CLUSTER_OPTIONS = ("workers", "scheduler")


def extra_of(args: argparse.Namespace) -> str | None:
    """The extra the parsed command line needs beyond the core install, if any."""
    if any(getattr(args, o, None) for o in CLUSTER_OPTIONS):
        return "cluster"
    if getattr(args, "verify", False) is True:  # replay --verify: no console
        return None
    return NEEDS.get(getattr(args, "command", None) or "")


class Parser(argparse.ArgumentParser):
    """argparse's parser, whose refusal of a command line with ``--format json`` is also a JSON error object on
    stdout (exit status 2, as argparse's own)."""

    def error(self, message: str) -> NoReturn:
        print_error(Exit.USAGE, f"{message}; '{self.prog} --help' lists the arguments")
        super().error(message)


def json_asked(argv: Sequence[str]) -> str | None:
    """The command of a command line that asks for ``--format json`` (its errors then go out as JSON too)."""
    words = list(argv)
    asked = "--format=json" in words or any(a == "--format" and b == "json" for a, b in pairwise(words))
    return next((w for w in words if not w.startswith("-")), None) if asked else None


def build_parser() -> argparse.ArgumentParser:
    p = Parser(prog="liansuo", description="Station signalling and interlocking simulator (联锁)")
    p.add_argument("--version", action="version", version=f"liansuo {version()}")
    sub = p.add_subparsers(dest="command", metavar="COMMAND")

    def add(name: str, handler: Handler, help_: str) -> argparse.ArgumentParser:
        sp = sub.add_parser(name, help=help_, description=help_)
        sp.set_defaults(handler=handler)
        return sp

    for register in REGISTER:
        register(add)
    completion.register(add, p)  # last: its script is made from the whole parser
    return p


def main(argv: Sequence[str] | None = None) -> int:
    parser = build_parser()
    words = sys.argv[1:] if argv is None else list(argv)
    with errors_as_json(json_asked(words)):
        args = parser.parse_args(words)
    handler: Handler | None = getattr(args, "handler", None)
    if handler is None:
        parser.print_help()
        print("liansuo: a COMMAND is needed (the list above)", file=sys.stderr)
        return 2
    json_errors = args.command if getattr(args, "format", None) == "json" else None
    try:
        with errors_as_json(json_errors):  # its refusals as a JSON error object too (kit/jsonreport.py)
            extra = extra_of(args)
            why = needed(extra) if extra else None
            if why:
                return refuse(args.command, why, Exit.USAGE)
            return handler(args)
    except BrokenPipeError:  # e.g. piped into head
        return 0
    except KeyboardInterrupt:
        return 130

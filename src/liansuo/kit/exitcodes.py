"""The exit status of every ``liansuo`` command, by pytest's convention (docs/commands.md, "Exit status").

Each non-zero status comes with a one-line message on stderr that says what went wrong and what to do; with
``--format json``, an error object on stdout too (:func:`~liansuo.kit.jsonreport.print_error`) unless the command's
report was printed already.
"""

from __future__ import annotations

import sys
from enum import IntEnum

from liansuo.kit.jsonreport import print_error
from liansuo.kit.printable import printable
from liansuo.kit.source import StationError


class Exit(IntEnum):
    """What a ``liansuo`` command's exit status means."""

    OK = 0  # done; every check or test passed
    FAILED = 1  # checks or tests ran and some failed (a verify failure, a failed test, a soak violation ...)
    USAGE = 2  # the command line is wrong: an unknown option, a bad value (argparse's own status)
    BAD_INPUT = 3  # an input file is missing, unreadable, malformed or of the wrong kind (FILE:LINE where known)
    NOTHING_SELECTED = 5  # the selection (-k, --route ...) matched nothing, so nothing ran


def refuse(command: str, message: str, status: Exit) -> int:
    """Print ``liansuo COMMAND: MESSAGE`` on stderr, one line (control characters a message may quote from a file
    written out), and with ``--format json`` the error object on stdout; give ``status`` back for the command to
    return."""
    print(f"liansuo {command}: {printable(message)}", file=sys.stderr)
    print_error(status, message)
    return int(status)


def bad_input(exc: StationError, what: str = "station", **keys: object) -> int:
    """Every diagnostic of a file that did not load on stderr (``FILE:LINE:COLUMN: error: ...``), then, unless that
    was one line already, ``N errors; the WHAT was not loaded``; with ``--format json`` the error object on stdout,
    every diagnostic in its ``errors`` and ``keys`` beside them; :attr:`Exit.BAD_INPUT`."""
    for d in exc.diagnostics:
        print(d, file=sys.stderr)
    n = len(exc.diagnostics)
    if n != 1 or exc.diagnostics[0].hint:
        print(f"{n} error{'s' if n != 1 else ''}; the {what} was not loaded", file=sys.stderr)
    first = exc.diagnostics[0].message if exc.diagnostics else "it could not be read"
    more = f" (and {n - 1} more error{'s' if n != 2 else ''})" if n > 1 else ""
    print_error(Exit.BAD_INPUT, f"{first}{more}; the {what} was not loaded",
                [d.as_dict() for d in exc.diagnostics], **keys)
    return int(Exit.BAD_INPUT)

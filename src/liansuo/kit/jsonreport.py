"""The envelope of every JSON report ``liansuo`` writes: which liansuo wrote it and which shape it has.

Every ``--format json`` output is one object whose first keys are ``"liansuo"`` (the package version that wrote it)
and ``"schema"`` (the version of that command's JSON shape, an integer raised whenever a key is renamed, removed or
changes meaning; adding a key does not raise it), then ``"ok"`` (true exactly when the command exits 0), then the
command's own keys. Each shape is described in docs/commands.md ("JSON reports").

A command run with ``--format json`` that stops before its report (a missing or malformed file, a bad value, a
cluster that failed) prints instead one error object in the same envelope, ``ok: false``, with ``error`` (``status``,
``message``, ``file``, ``line``, ``column``, ``hint``) and ``errors`` (every diagnostic of the file): the command line
(``cli/main.py``) turns this on with :func:`errors_as_json`, and ``kit/exitcodes.py``'s ``refuse`` and ``bad_input``
print it through :func:`print_error`.
"""

from __future__ import annotations

import json
import sys
from collections.abc import Iterator
from contextlib import contextmanager
from functools import cache
from importlib import metadata
from typing import Any, TextIO

# the version of each command's JSON shape (docs/commands.md lists the keys of each)
SCHEMAS: dict[str, int] = {
    "stations": 1, "check": 1, "table": 1, "zpw": 1, "test": 1, "run": 1, "verify": 1, "soak": 1, "explore": 1,
    "mutate": 1, "bench": 1, "replay": 1, "25hz": 1, "zpw validate": 1, "fuzz": 1, "exercise": 1,
    "zpw sweep": 1,
}


@cache
def version() -> str:
    """The installed liansuo's version (the package metadata; ``unknown`` in a checkout never installed)."""
    try:
        return metadata.version("liansuo")
    except metadata.PackageNotFoundError:  # pragma: no cover - a checkout that was never installed
        return "unknown"


class _JsonErrors:
    """The command whose errors go out as JSON objects (None: as text alone), and whether its report was made (what
    goes wrong after it, such as checks that failed, is said on stderr alone: stdout holds one object)."""

    command: str | None = None
    reported = False


def envelope(command: str, ok: bool) -> dict[str, Any]:
    """The keys every JSON report of ``command`` starts with."""
    _JsonErrors.reported = True
    return {"liansuo": version(), "schema": SCHEMAS.get(command, 1), "ok": ok}


def report(command: str, ok: bool, body: dict[str, Any]) -> dict[str, Any]:
    """``body`` in the envelope; the envelope's keys come first and win over the body's."""
    return {**envelope(command, ok), **{k: v for k, v in body.items() if k not in ("liansuo", "schema", "ok")}}


def print_report(command: str, ok: bool, body: dict[str, Any], out: TextIO | None = None) -> None:
    """Write the report as indented JSON (UTF-8 text as is) and a newline."""
    print(json.dumps(report(command, ok, body), ensure_ascii=False, indent=2), file=out or sys.stdout)


@contextmanager
def errors_as_json(command: str | None) -> Iterator[None]:
    """While ``command`` runs with ``--format json``: :func:`print_error` prints (``command`` None: it does not)."""
    _JsonErrors.command, _JsonErrors.reported = command, False
    try:
        yield
    finally:
        _JsonErrors.command, _JsonErrors.reported = None, False


def print_error(status: int, message: str, errors: list[dict[str, Any]] | None = None, **keys: Any) -> bool:
    """The error object on stdout, when the command runs with ``--format json`` and made no report yet: ``status``
    (the exit status), ``message`` (what went wrong and what to do), the place of the first of ``errors`` (the
    diagnostics of a file, :meth:`~liansuo.kit.source.Diagnostic.as_dict`) and its hint; ``keys`` follow the
    envelope (``check``: ``station``). Whether it printed."""
    command = _JsonErrors.command
    if command is None or _JsonErrors.reported:
        return False
    first = (errors or [{}])[0]
    error = {"status": int(status), "message": message, "file": first.get("file"), "line": first.get("line"),
             "column": first.get("column"), "hint": first.get("hint", "")}
    print_report(command, False, {**keys, "error": error, "errors": errors or []})
    return True

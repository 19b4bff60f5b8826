"""The envelope of every JSON report ``liansuo`` writes: which liansuo wrote it and which shape it has.

Every ``--format json`` output is one object whose first keys are ``"liansuo"`` (the package version that wrote it)
and ``"schema"`` (the version of that command's JSON shape, an integer raised whenever a key is renamed, removed or
changes meaning; adding a key does not raise it), then ``"ok"`` (true exactly when the command exits 0), then the
command's own keys. Each shape is described in docs/commands.md ("JSON reports").
"""

from __future__ import annotations

import json
import sys
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


def envelope(command: str, ok: bool) -> dict[str, Any]:
    """The keys every JSON report of ``command`` starts with."""
    return {"liansuo": version(), "schema": SCHEMAS[command], "ok": ok}


def report(command: str, ok: bool, body: dict[str, Any]) -> dict[str, Any]:
    """``body`` in the envelope; the envelope's keys come first and win over the body's."""
    return {**envelope(command, ok), **{k: v for k, v in body.items() if k not in ("liansuo", "schema", "ok")}}


def print_report(command: str, ok: bool, body: dict[str, Any], out: TextIO | None = None) -> None:
    """Write the report as indented JSON (UTF-8 text as is) and a newline."""
    print(json.dumps(report(command, ok, body), ensure_ascii=False, indent=2), file=out or sys.stdout)

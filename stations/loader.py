"""Load a station by bundled name or path: YAML -> strict schema -> double slips expanded into plain turnouts,
tracks and diamonds (:mod:`.doubleslip`) -> cross-checks -> :class:`Station`.

Nothing is half-loaded: either a complete, consistent :class:`Station` comes back or :class:`StationError` is raised
with every problem found, each as ``FILE:LINE:COLUMN: message`` with a hint.
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any

from pydantic import ValidationError

from liansuo.rules import RuleSet

from .checks import cross_check
from .doubleslip import double_slip_errors, expand_double_slips
from .filekind import check_kind, read_source
from .library import resolve
from .rules import design_warnings
from .schema import StationFile
from .source import Diagnostic, Source, StationError, read_yaml
from .station import Station

_HINTS = {
    "extra_forbidden": "remove it, or check its spelling against 'liansuo schema' and docs/station-format.md",
    "missing": "add this key; docs/station-format.md lists what each item needs",
    "enum": "use one of the values listed",
    "literal_error": "use one of the values listed",
    "string_type": "write a text value",
    "float_type": "write a number of metres",
    "int_type": "write a whole number",
    "bool_type": "write true or false",
    "list_type": "write a list ('- item' lines)",
    "model_type": "write a mapping ('key: value' lines)",
    "too_short": "add items: the message says how many the list needs",
    "too_long": "remove items: the message says how many the list takes",
    "string_too_short": "write a non-empty text",
    "int_from_float": "write a whole number",
    "greater_than": "write a larger number",
    "greater_than_equal": "write a larger number",
    "less_than": "write a smaller number",
    "less_than_equal": "write a smaller number",
    "finite_number": "write an ordinary number (not .nan or .inf)",
}
_DEFAULT_HINT = "docs/station-format.md explains what this key takes"


def _describe(err: Any) -> str:
    kind = err["type"]
    loc = err["loc"]
    where = ".".join(str(p) for p in loc if p != "__root__")
    if kind == "extra_forbidden":
        return f"unknown key '{loc[-1]}'"
    if kind == "missing":
        return f"missing key '{loc[-1]}'"
    msg = str(err["msg"])
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    value = err.get("input")
    shown = repr(value) if not isinstance(value, dict | list) else type(value).__name__
    if len(shown) > 40:
        shown = shown[:37] + "..."
    return f"{where}: {msg} (got {shown})"


def _schema_diagnostics(src: Source, exc: ValidationError) -> list[Diagnostic]:
    out = []
    for err in exc.errors():
        loc = tuple(p for p in err["loc"] if not (isinstance(p, str) and p.startswith("function-")))
        # pydantic reports the alias for 'from'/'to' tracks; marks are stored under the YAML key, which matches.
        hint = _HINTS.get(err["type"], _DEFAULT_HINT)
        at_key = err["type"] == "extra_forbidden"
        if err["type"] == "missing":
            loc = loc[:-1]
        out.append(src.diagnostic(loc, _describe(err), hint, at_key=at_key))
    return out


def parse_source(src: Source, rules: RuleSet | None = None) -> Station:
    check_kind(src, "station")
    if not isinstance(src.data, dict):
        raise StationError([src.diagnostic((), "a station file is a mapping of keys such as 'id:' and 'tracks:'",
                                           "see docs/station-format.md for a small complete example")])
    try:
        # JSON mode keeps strictness (no "1" -> 1) while accepting enum values written as text
        model = StationFile.model_validate_json(json.dumps(src.data, default=str), by_alias=True)
    except ValidationError as exc:
        raise StationError(_schema_diagnostics(src, exc)) from None
    errors = double_slip_errors(model, src)
    if errors:
        raise StationError(errors)
    model, src = expand_double_slips(model, src)  # into turnouts, tracks and a diamond: nothing later knows of them
    errors = cross_check(model, src)
    if errors:
        raise StationError(errors)
    station = Station(model, src)
    station.warnings = design_warnings(station, rules.design if rules else None)
    return station


def load_text(text: str, file: str = "<station>", *, rules: RuleSet | None = None) -> Station:
    return parse_source(read_yaml(text, file), rules)


def load(name_or_path: str | Path, *, rules: RuleSet | None = None) -> Station:
    """Load a bundled station by name (``jiaopei``) or any station file by path; its design warnings follow the
    design rules of ``rules`` (by default the default rule set)."""
    path = resolve(name_or_path)
    return parse_source(read_source(path, "station", "give a bundled station name (see 'liansuo stations') or a "
                                    "path"), rules)

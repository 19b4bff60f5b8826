"""A pydantic model's validation errors as ``FILE:LINE:COLUMN`` diagnostics with a hint, for every kind of file
read from YAML: station files (:mod:`.loader`), and test scripts, scenarios and exercises, whose models live with
their loaders. The model is also what ``liansuo schema KIND`` writes as the kind's JSON Schema, so an editor and the
loader accept the same files."""

from __future__ import annotations

from collections.abc import Mapping
from typing import Any, TypeVar

from pydantic import BaseModel, ValidationError

from liansuo.kit.source import Diagnostic, Source
from liansuo.stations import limits

M = TypeVar("M", bound=BaseModel)

_HINTS = {
    "extra_forbidden": "remove it, or check its spelling against 'liansuo schema' and 'liansuo docs station-format'",
    "missing": "add this key; 'liansuo docs station-format' lists what each item needs",
    "enum": "use one of the values listed",
    "literal_error": "use one of the values listed",
    "string_type": "write a text value",
    "float_type": "write a number of metres",
    "int_type": "write a whole number",
    "bool_type": "write true or false",
    "list_type": "write a list ('- item' lines)",
    "model_type": "write a mapping ('key: value' lines)",
    "too_short": "add items: the message says how many the list needs",
    "too_long": "remove items: the message says how many the list takes; a whole station past its size limits "
                "('liansuo docs robustness', 'Station size') is split into stations joined by links",
    "string_too_short": "write a non-empty text",
    "int_from_float": "write a whole number",
    "greater_than": "write a larger number",
    "greater_than_equal": "write a larger number",
    "less_than": "write a smaller number",
    "less_than_equal": "write a smaller number",
    "finite_number": "write an ordinary number (not .nan or .inf)",
}
_DEFAULT_HINT = "'liansuo docs station-format' explains what this key takes"


def _describe(err: Any) -> str:
    kind = err["type"]
    loc = err["loc"]
    where = ".".join(str(p) for p in loc if p != "__root__")
    if kind == "extra_forbidden":
        return f"unknown key '{loc[-1]}'"
    if kind == "missing":
        return f"missing key '{loc[-1]}'"
    msg = str(err["msg"])
    if kind == "too_long" and len(loc) == 1 and str(loc[0]) in limits.STATION_ITEMS:  # a station's own list
        most, have = err["ctx"]["max_length"], err["ctx"].get("actual_length")
        return (f"{where}: a station has at most {most:,} {str(loc[0]).replace('_', ' ')}"
                f"{f', not {have:,}' if have is not None else ''}: larger than any real station")
    if msg.startswith("Value error, "):
        msg = msg[len("Value error, "):]
    value = err.get("input")
    if kind in ("finite_number", "float_type") and type(value) is int:  # a whole number past 1e308 has no float
        msg = "a number this large is out of every range (beyond 1e308)"
    shown = repr(value) if not isinstance(value, dict | list) else type(value).__name__
    if len(shown) > 40:
        shown = shown[:37] + "..."
    return f"{where}: {msg} (got {shown})"


def schema_diagnostics(src: Source, exc: ValidationError, hints: Mapping[str, str] | None = None,
                       default_hint: str = _DEFAULT_HINT) -> list[Diagnostic]:
    """One diagnostic per validation error, at the line of the value (of the key, for an unknown key); ``hints``
    replace the station file's hints by error type, ``default_hint`` serves every other type."""
    table = {**_HINTS, **(hints or {})}
    out = []
    for err in exc.errors():
        loc = tuple(p for p in err["loc"] if not (isinstance(p, str) and p.startswith("function-")))
        # pydantic reports the alias for 'from'/'to' tracks; marks are stored under the YAML key, which matches.
        hint = table.get(err["type"], default_hint)
        at_key = err["type"] == "extra_forbidden"
        if err["type"] == "missing":
            loc = loc[:-1]
        out.append(src.diagnostic(loc, _describe(err), hint, at_key=at_key))
    return out


def validate(src: Source, model: type[M], errors: list[Diagnostic], kind: str, doc: str) -> M | None:
    """``src``'s data as ``model``, or None with a diagnostic in ``errors`` for each problem, ``errors`` then in the
    order of the file. A problem at a place ``errors`` already reports (a step the command language refused, say)
    is not reported twice. ``kind`` names the file kind (``liansuo schema KIND``), ``doc`` the document that
    describes it, for the hints."""
    try:
        return model.model_validate(src.data)
    except ValidationError as exc:
        hints = {"extra_forbidden": f"remove it, or check its spelling against 'liansuo schema {kind}' and {doc}",
                 "missing": f"add this key; {doc} lists what each item needs",
                 "float_type": "write a number"}
        seen = {(d.line, d.column) for d in errors}
        errors += [d for d in schema_diagnostics(src, exc, hints, f"{doc} explains what this key takes")
                   if (d.line, d.column) not in seen]
        errors.sort(key=lambda d: (d.line, d.column))
        return None

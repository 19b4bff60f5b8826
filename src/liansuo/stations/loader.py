"""Load a station by bundled name or path: YAML -> strict schema -> double slips expanded into plain turnouts,
tracks and diamonds (:mod:`.doubleslip`) -> cross-checks -> :class:`Station`.

Nothing is half-loaded: either a complete, consistent :class:`Station` comes back or :class:`StationError` is raised
with every problem found, each as ``FILE:LINE:COLUMN: message`` with a hint.
"""

from __future__ import annotations

import json
from pathlib import Path

from pydantic import ValidationError

from liansuo.kit.filekind import HOLDS, check_kind, kind_of_data, read_source
from liansuo.kit.printable import printable
from liansuo.kit.source import Diagnostic, Source, StationError, read_yaml
from liansuo.rules import RuleSet
from liansuo.stations.checks import cross_check
from liansuo.stations.doubleslip import double_slip_errors, expand_double_slips
from liansuo.stations.library import bundled, resolve, resolve_from
from liansuo.stations.rules import design_warnings
from liansuo.stations.schema import StationFile
from liansuo.stations.station import Station
from liansuo.stations.validation import schema_diagnostics


def parse_source(src: Source, rules: RuleSet | None = None) -> Station:
    check_kind(src, "station")
    if not isinstance(src.data, dict):
        raise StationError([src.diagnostic((), "a station file is a mapping of keys such as 'id:' and 'tracks:'",
                                           "'liansuo docs station-format' for a small complete example")])
    try:
        # JSON mode keeps strictness (no "1" -> 1) while accepting enum values written as text
        model = StationFile.model_validate_json(json.dumps(src.data, default=str), by_alias=True)
    except ValidationError as exc:
        raise StationError(schema_diagnostics(src, exc)) from None
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


def load_named(name: str, named_in: str | Path, *, rules: RuleSet | None = None) -> Station:
    """The station a script, a scenario or an exercise names with ``station:`` (a bundled name, or a path relative to
    the file naming it). A file there that is no station file at all (none of a station's keys) is refused in one
    line at the naming file, none of its content quoted: a file handed over may name any file on the machine as its
    station, and the diagnostics of a station file would show its keys."""
    if name in bundled():
        return load(name, rules=rules)
    path = resolve_from(name, named_in)
    src = read_source(path, "station", "give a bundled station name (see 'liansuo stations') or a path relative to "
                      f"{printable(str(named_in))}")
    if kind_of_data(src.data) != "station":
        raise StationError([Diagnostic(str(named_in), 1, 1, f"its station {printable(name)} is not a station file, so "
                                       "nothing of it is shown", f"a station file has {HOLDS['station']}; name a "
                                       "bundled station or a station file")])
    return parse_source(src, rules)

"""What kind of liansuo file a file is, told from its content: a station, a test script, a scenario, an exercise or
a recording. A command given a file of another kind names both kinds in one line instead of listing the keys it did
not expect (``liansuo test station.yaml``: "this is a station file, not a test script").
"""

from __future__ import annotations

import json
from pathlib import Path
from typing import Any, Literal

from liansuo.kit.source import Diagnostic, Source, StationError, read_text, read_yaml

Kind = Literal["station", "script", "scenario", "exercise", "recording"]

RECORDING_FORMAT = "liansuo-recording"  # the "format" of a recording's header line (simulation/recording/recorder.py)

NAMES: dict[Kind, str] = {"station": "station file", "script": "test script", "scenario": "scenario",
                          "exercise": "exercise", "recording": "recording"}
# how a file of each kind is used, for the message naming a wrong kind
USE: dict[Kind, str] = {
    "station": "check it with 'liansuo check FILE'",
    "script": "run it with 'liansuo test FILE'",
    "scenario": "run it with 'liansuo run FILE'",
    "exercise": "load it with 'liansuo tui STATION --exercise FILE'",
    "recording": "play it with 'liansuo replay FILE'",
}
# what a file of each kind holds, for the same message and for an empty file
HOLDS: dict[Kind, str] = {
    "station": "'id:', 'name:', 'ends:', 'tracks:' and 'sections:'",
    "script": "'station:' and 'tests:'",
    "scenario": "'station:' and 'steps:'",
    "exercise": "'title:', 'station:', 'setup:' and 'goal:' or 'goals:'",
    "recording": "a header line and one JSON record a line",
}
# top-level keys only a file of that kind has
_SIGNS: dict[Kind, frozenset[str]] = {
    "station": frozenset({"ends", "tracks", "sections", "signals", "turnouts", "joints", "platforms"}),
    "script": frozenset({"tests"}),
    "scenario": frozenset({"steps"}),
    "exercise": frozenset({"title", "setup", "goal", "goals", "briefing"}),
}


def kind_of_text(text: str) -> Kind | None:
    """``recording`` when the first line is a recording's header; ``None`` otherwise (the YAML kinds need parsing)."""
    first = next((line for line in text.splitlines() if line.strip()), "")
    if not first.lstrip().startswith("{"):
        return None
    try:
        head = json.loads(first)
    except (ValueError, RecursionError):  # not JSON, or nested deeper than the parser goes: not a recording header
        return None
    return "recording" if isinstance(head, dict) and head.get("format") == RECORDING_FORMAT else None


def kind_of_data(data: Any) -> Kind | None:
    """The kind a parsed YAML document is, by the top-level keys only that kind has; ``None`` when no kind's keys
    are there or those of more than one are (the reader then reports what is wrong key by key)."""
    if not isinstance(data, dict):
        return None
    found = [kind for kind, signs in _SIGNS.items() if signs & data.keys()]
    return found[0] if len(found) == 1 else None


def wrong_kind(file: str, found: Kind, wanted: Kind) -> StationError:
    """The one-line error for a file of kind ``found`` given where a ``wanted`` one belongs."""
    return StationError([Diagnostic(
        file, 1, 1, f"this is {_a(NAMES[found])}, not {_a(NAMES[wanted])} ({USE[found].replace('FILE', file)}; "
                    f"{_a(NAMES[wanted])} has {HOLDS[wanted]})")])


def check_kind(src: Source, wanted: Kind) -> None:
    """Raise :func:`wrong_kind` when the document is plainly of another kind."""
    found = kind_of_data(src.data)
    if found is not None and found != wanted:
        raise wrong_kind(src.file, found, wanted)


def read_source(path: Path, wanted: Kind, missing_hint: str) -> Source:
    """Read a YAML file of kind ``wanted``: :class:`StationError` at ``FILE:LINE:COLUMN`` when it is missing,
    unreadable, empty, not YAML, or a file of another kind."""
    text = read_text(path, missing_hint)
    if kind_of_text(text) == "recording":
        raise wrong_kind(str(path), "recording", wanted)
    if not text.strip():
        raise StationError([Diagnostic(str(path), 1, 1, "the file is empty", f"{_a(NAMES[wanted])} has "
                                       f"{HOLDS[wanted]}")])
    src = read_yaml(text, str(path))
    check_kind(src, wanted)
    return src


def kind_of_file(path: Path) -> Kind | None:
    """The kind of the file at ``path``, or ``None`` when it is unreadable or of no kind liansuo knows."""
    try:
        text = read_text(path)
        return kind_of_text(text) or kind_of_data(read_yaml(text, str(path)).data)
    except StationError:
        return None


def _a(noun: str) -> str:
    return f"{'an' if noun[0] in 'aeiou' else 'a'} {noun}"

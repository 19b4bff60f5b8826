"""Reading a session recording (docs/console.md, "The recording file") and finding the station it was made on.

:func:`load_recording` reads the whole file within the limits of :mod:`.schema` (a regular file, its size,
UTF-8, each line one record the schema accepts), then checks what no single record can say: the header first, the
``init`` record second, the ``end`` record last, cycles in order and the time of each at its cycle, the commands
numbered without a gap and as many as the end record counts. Anything wrong is a :class:`RecordingError`: a
``FILE:LINE:COLUMN`` diagnostic for each problem (up to :data:`.schema.MAX_ERRORS`), never a traceback.

:func:`recording_station` loads the station the recording names, a bundled name or a path relative to the recording
file, and refuses a station other than the one the recording was made on (its id, then the SHA-256 of its file).
"""

from __future__ import annotations

import hashlib
import os
import re
import stat
from dataclasses import dataclass
from pathlib import Path
from typing import Any

from pydantic import TypeAdapter, ValidationError

from liansuo.kit.filekind import kind_of_data, kind_of_text, wrong_kind
from liansuo.kit.printable import printable
from liansuo.kit.source import Diagnostic, StationError, read_yaml
from liansuo.simulation.recording.schema import (
    FORMAT,
    KINDS,
    MAX_BYTES,
    MAX_ERRORS,
    MAX_LINE_CHARS,
    RECORD,
    VERSION,
    ChgRecord,
    CmdRecord,
    CycRecord,
    EndRecord,
    HeaderRecord,
    InitRecord,
)
from liansuo.stations.library import LIBRARY, bundled
from liansuo.stations.loader import load
from liansuo.stations.station import Station

_JSON: TypeAdapter[Any] = TypeAdapter(Any)  # any JSON value, parsed by pydantic (bounded nesting, no RecursionError)
_JSON_AT = re.compile(r" at line \d+ column (\d+)$")
DOC = "'liansuo docs console', 'The recording file'"
RECORD_AGAIN = "record the session again with 'liansuo tui --record FILE'"


class RecordingError(StationError):
    """A recording that cannot be replayed: its diagnostics say where and why."""


@dataclass(frozen=True)
class Recording:
    """A recording that passed every check of :func:`load_recording`; each record with its line in the file."""

    path: str
    header: HeaderRecord
    init: InitRecord
    end: EndRecord
    end_line: int
    commands: list[tuple[int, CmdRecord]]  # (line, record), in the order sent
    cycles_changed: dict[int, tuple[int, CycRecord]]  # cycle -> (line, record)
    changes: dict[int, tuple[int, ChgRecord]]  # command number -> (line, the record of what it changed)
    cycle_lines: list[tuple[int, int]]  # (cycle, line) of every record after the header, for a cycle's line

    @property
    def station(self) -> str:
        return self.header.station

    @property
    def station_id(self) -> str:
        return self.header.station_id

    @property
    def cycle_s(self) -> float:
        return self.header.cycle_s

    @property
    def cycles(self) -> int:
        return self.end.n

    @property
    def duration(self) -> float:
        return self.cycles * self.cycle_s

    def line_of_cycle(self, n: int) -> int:
        """The line where a record of cycle ``n`` stands or would stand."""
        return next((line for cycle, line in self.cycle_lines if cycle >= n), self.end_line)


def load_recording(path: str | Path) -> Recording:
    """Read and check a recording; :class:`RecordingError` names the line of anything wrong, and the kind of a file
    that is another kind of liansuo file (a station, a script ...)."""
    p = Path(path)
    text = _read(p)
    file = str(p)
    if kind_of_text(text) != "recording":
        raise _not_a_recording(file, text)
    version = _header(text).get("version")
    if version != VERSION:
        shown = printable(repr(version))[:40]
        raise _error(file, 1, f"recording format version {shown}; this liansuo reads version {VERSION}",
                     RECORD_AGAIN)
    errors: list[Diagnostic] = []
    entries: list[tuple[int, Any]] = []
    for i, line in enumerate(text.split("\n"), 1):
        if not line.strip():
            continue
        if len(errors) >= MAX_ERRORS:
            errors = [*errors[:MAX_ERRORS], Diagnostic(file, i, 1, f"the lines from here not checked after "
                                                                   f"{MAX_ERRORS} errors")]
            break
        if len(line) > MAX_LINE_CHARS:
            errors.append(Diagnostic(file, i, 1, f"a line of {len(line):,} characters; a record is at most "
                                                 f"{MAX_LINE_CHARS:,}", RECORD_AGAIN))
            continue
        try:
            entries.append((i, RECORD.validate_json(line)))
        except ValidationError as exc:
            errors += _record_errors(file, i, exc)
    if not errors:
        return _assemble(file, entries)
    raise RecordingError(errors)


def _read(p: Path) -> str:
    file = str(p)
    try:
        st = p.stat()
    except (FileNotFoundError, NotADirectoryError):
        raise _error(file, 1, "no such file", "give a recording written by 'liansuo tui --record FILE'") from None
    except OSError as exc:
        raise _error(file, 1, f"cannot read the file: {exc.strerror}", "") from None
    if stat.S_ISDIR(st.st_mode):
        raise _error(file, 1, "this is a folder, not a recording", "give a file written by 'liansuo tui --record'")
    if not stat.S_ISREG(st.st_mode):
        raise _error(file, 1, "not a regular file (a device, a pipe or a socket)", "give a recording file")
    if st.st_size > MAX_BYTES:
        raise _error(file, 1, f"{st.st_size:,} bytes: a recording is at most {MAX_BYTES:,}", "")
    try:
        with p.open("rb") as fh:
            data = fh.read(MAX_BYTES + 1)
    except OSError as exc:
        raise _error(file, 1, f"cannot read the file: {exc.strerror}", "") from None
    if len(data) > MAX_BYTES:
        raise _error(file, 1, f"more than {MAX_BYTES:,} bytes: a recording is at most that", "")
    try:
        return data.decode("utf-8")
    except UnicodeDecodeError as exc:
        line = data.count(b"\n", 0, exc.start) + 1
        column = exc.start - data.rfind(b"\n", 0, exc.start)
        raise RecordingError([Diagnostic(file, line, column, f"not UTF-8 text (byte 0x{data[exc.start]:02x})",
                                         "a recording is UTF-8 JSON lines; the file is damaged")]) from None


def _not_a_recording(file: str, text: str) -> RecordingError:
    """The error for a file whose first line is no recording header: another kind of liansuo file (YAML), or
    something else."""
    if not text.strip():
        return _error(file, 1, "the file is empty", "a recording has a header line and one JSON record a line")
    first = next(line for line in text.split("\n") if line.strip())
    found = None
    if not first.lstrip().startswith(("{", "[")):  # JSON is no other kind of liansuo file
        try:
            found = kind_of_data(read_yaml(text, file).data)
        except StationError:
            found = None
    if found is not None:
        return RecordingError(wrong_kind(file, found, "recording").diagnostics)
    if first.lstrip().startswith("{"):
        try:
            _JSON.validate_json(first)
        except ValidationError as exc:  # not even JSON: say why
            return RecordingError(_record_errors(file, 1, exc)[:1])
    return _error(file, 1, "not a liansuo recording (no header line)",
                  f"a recording's first line is its header, {{\"k\": \"header\", \"format\": \"{FORMAT}\", ...}}")


def _header(text: str) -> dict[str, Any]:
    """The first line as a JSON object, or {} (pydantic's parser: no nesting too deep for it to fail on)."""
    first = next((line for line in text.split("\n") if line.strip()), "")
    try:
        head = _JSON.validate_json(first)
    except ValidationError:
        return {}
    return head if isinstance(head, dict) else {}


def _record_errors(file: str, line: int, exc: ValidationError) -> list[Diagnostic]:
    """One diagnostic per problem of one line."""
    out = []
    for err in exc.errors(include_url=False):
        kind, loc = err["type"], [str(p) for p in err["loc"]]
        column = 1
        if kind == "json_invalid":
            why = err["msg"].removeprefix("Invalid JSON: ")
            at = _JSON_AT.search(why)
            if at:  # the position in the line: the diagnostic's column
                why, column = why[:at.start()], int(at.group(1))
            msg, hint = f"not a JSON record: {why}", "each line is one JSON object; the file is damaged"
        elif kind in ("union_tag_not_found", "model_type", "model_attributes_type") or not loc:
            msg, hint = "a record is a JSON object with a 'k' key", f"'k' is one of {', '.join(KINDS)}"
        elif kind == "union_tag_invalid":
            tag = printable(str(err.get("ctx", {}).get("tag", "")))[:40]
            msg, hint = f"unknown record kind 'k': '{tag}'", f"'k' is one of {', '.join(KINDS)}"
        else:
            where = ".".join("in" if p == "in_" else p for p in loc[1:])
            if kind == "missing":
                msg = f"{loc[0]} record: missing key '{where}'"
            elif kind == "extra_forbidden":
                msg = f"{loc[0]} record: unknown key '{printable(where)[:60]}'"
            else:
                value = err.get("input")
                shown = printable(repr(value) if not isinstance(value, dict | list) else type(value).__name__)
                msg = f"{loc[0]} record: {printable(where)[:60]}: {err['msg']} (got {shown[:40]})"
            hint = f"{DOC} lists what each record holds"
        out.append(Diagnostic(file, line, column, msg, hint))
    return out


def _assemble(file: str, entries: list[tuple[int, Any]]) -> Recording:
    """The records in their places, or the first problem with their order, numbering or times."""
    if not entries or not isinstance(entries[0][1], HeaderRecord):
        raise _error(file, entries[0][0] if entries else 1, "the first record is the header",
                     f"a recording starts with {{\"k\": \"header\", \"format\": \"{FORMAT}\", ...}}")
    header: HeaderRecord = entries[0][1]
    if len(entries) < 2 or not isinstance(entries[1][1], InitRecord):
        line = entries[1][0] if len(entries) > 1 else entries[0][0]
        what = "has only its header" if len(entries) < 2 else f"has a '{entries[1][1].k}' record second"
        raise _error(file, line, f"the recording {what}: its 'init' record (the state when recording started) is "
                                 "missing, so there is nothing to replay", RECORD_AGAIN)
    init: InitRecord = entries[1][1]
    last_line, last = entries[-1]
    if not isinstance(last, EndRecord):
        raise _error(file, last_line, "the recording has no 'end' record after this line: it was cut short (the "
                                      "console was killed or did not close the file), so its length is unknown",
                     RECORD_AGAIN)
    commands: list[tuple[int, CmdRecord]] = []
    cycles_changed: dict[int, tuple[int, CycRecord]] = {}
    changes: dict[int, tuple[int, ChgRecord]] = {}
    cycle_lines: list[tuple[int, int]] = []
    n_before, line_before = 0, entries[1][0]
    for line, rec in entries[2:]:
        if isinstance(rec, HeaderRecord | InitRecord):
            raise _error(file, line, f"a second '{rec.k}' record", "a recording has one header and one init record")
        if isinstance(rec, EndRecord) and line != last_line:
            raise _error(file, line, "an 'end' record before the last line", "nothing follows the end record")
        if rec.n < n_before:
            raise _error(file, line, f"cycle {rec.n} after cycle {n_before} (line {line_before}): records are in "
                                     "the order of time", "the file is damaged")
        want_t = header.t0 + rec.n * header.cycle_s
        if abs(rec.t - want_t) > header.cycle_s / 2:
            raise _error(file, line, f"t = {rec.t:g} s does not fit cycle {rec.n} (t = {want_t:g} s at "
                                     f"{header.cycle_s:g} s a cycle from t0 = {header.t0:g} s)", "the file is damaged")
        n_before, line_before = rec.n, line
        cycle_lines.append((rec.n, line))
        if isinstance(rec, CmdRecord):
            if rec.i != len(commands) + 1:
                raise _error(file, line, f"command number {rec.i} where {len(commands) + 1} was next: a command "
                                         "record is missing or repeated", "the file is damaged")
            commands.append((line, rec))
        elif isinstance(rec, CycRecord):
            if rec.n in cycles_changed:
                raise _error(file, line, f"a second record of cycle {rec.n} (the first at line "
                                         f"{cycles_changed[rec.n][0]})", "the file is damaged")
            cycles_changed[rec.n] = (line, rec)
        elif isinstance(rec, ChgRecord):
            owner = len(commands)
            if not owner or owner in changes:
                raise _error(file, line, "a 'chg' record that follows no command (it holds what the command before "
                                         "it changed)", "the file is damaged")
            changes[owner] = (line, rec)
    end: EndRecord = last
    if end.cmds != len(commands):
        raise _error(file, last_line, f"the end record counts {end.cmds} commands, the file holds {len(commands)}: "
                                      "a command record is missing or one too many", "the file is damaged")
    return Recording(file, header, init, end, last_line, commands, cycles_changed, changes, cycle_lines)


def _error(file: str, line: int, message: str, hint: str) -> RecordingError:
    return RecordingError([Diagnostic(file, line, 1, message, hint)])


# ---- the station ----------------------------------------------------------------------------------------------------
def station_digest(path: Path) -> str:
    """SHA-256 of a station file, hex; '' when it cannot be read."""
    try:
        return hashlib.sha256(path.read_bytes()).hexdigest()
    except OSError:
        return ""


def station_reference(station: Station, recording: Path | None) -> tuple[str, str]:
    """How a recording names ``station`` and the digest of its file: a bundled name, or the file's path relative to
    the recording's folder (absolute without a recording file); the station's id for a station read from no file."""
    file = Path(station.source.file) if station.source is not None else None
    if file is None or not file.is_file():
        return station.id, ""
    file = file.resolve()
    if file.parent == LIBRARY.resolve() and bundled().get(file.stem) is not None:
        return file.stem, station_digest(file)
    if recording is None:
        return str(file), station_digest(file)
    try:
        ref = os.path.relpath(file, recording.resolve().parent)
    except ValueError:  # another drive (Windows)
        ref = str(file)
    return ref, station_digest(file)


def station_file(rec: Recording, given: str | None = None) -> Path:
    """The file of the recording's station: ``given`` (a bundled name or a path, from the command line) or the one
    the header names, a bundled name or a path relative to the recording."""
    name = given if given is not None else rec.station
    found = bundled().get(name)
    if found is not None:
        return found
    path = Path(name)
    if given is not None:
        return path
    folder = Path(rec.path).parent
    target = folder / path
    # a recording is a file one is given: its header may name only a station beside it, never /etc/shadow or ../..,
    # whose lines a refusal would echo. The station is not read here: nothing of the file named is shown.
    if path.is_absolute() or not target.resolve().is_relative_to(folder.resolve()):
        raise _error(rec.path, 1, f"the recording names its station as {printable(name)}, outside the recording's "
                                  "folder: a recording's station is a bundled name or a file in its folder",
                     f"if it is the station it was made on, give it: 'liansuo replay FILE --station "
                     f"{printable(str(target))}'")
    return target


def recording_station(rec: Recording, given: str | None = None) -> Station:
    """The station to replay ``rec`` on: its own (or ``given``), loaded and checked to be the one the recording was
    made on. :class:`RecordingError` says which station the recording was made on and which was found;
    :class:`~stations.source.StationError` (not this subclass) when the station file itself does not load."""
    path = station_file(rec, given)
    if given is not None:
        found = f"--station {printable(given)}"
    elif rec.station in bundled():
        found = f"the bundled station {printable(rec.station)} it names"
    else:
        shown = printable(rec.station) + ("" if str(path) == rec.station else f" ({printable(str(path))})")
        found = f"the station file it names, {shown},"
    fix = "give the station it was made on with 'liansuo replay FILE --station STATION'"
    made_on = f"the recording was made on station {printable(rec.station_id)}"
    if not path.is_file():
        what = "does not exist" if not path.exists() else "is not a regular file"
        raise _error(rec.path, 1, f"{made_on}, and {found} {what}", fix)
    station = load(path)
    if station.id != rec.station_id:
        raise _error(rec.path, 1, f"{made_on}, but {found} is station {printable(station.id)}: a replay there cannot "
                                  "reproduce it", fix)
    digest = station_digest(path)
    if digest != rec.header.station_sha256:
        raise _error(rec.path, 1, f"{made_on}, and the file of {found} has changed since (its SHA-256 differs): a "
                                  "replay on it could not reproduce the recording",
                     "give the station file as it was with 'liansuo replay FILE --station FILE', or record again")
    return station

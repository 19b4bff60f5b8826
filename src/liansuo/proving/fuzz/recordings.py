"""Fuzzing of recordings (issue 17, docs/robustness.md "Recordings"): damaged copies of real recordings through the
path of ``liansuo replay --verify``.

The seeds are real recordings, made with the recorder (:mod:`~liansuo.simulation.recording.recorder`) from the bundled
example scenarios (each ``run`` step shortened, so a replay stays quick) and from a console session with faults and
refused commands. A sample is a seed with one to four damages of the kinds a disk, an editor or a hand makes: lines
dropped, repeated, swapped or cut; a key removed; a value replaced by an extreme (NaN, infinity, -1, 0, 2**31, 1e308,
text, null, nesting deeper than any parser goes, control characters); another station, a device, a folder or a
file outside the recording's folder as the station, an empty or wrong digest; bytes that are not UTF-8.
:func:`attempt` gives it to the product as ``replay --verify`` does: load, find and check the station, re-simulate.
A clear refusal (a :class:`~stations.source.StationError`, or mismatches found) is "refused"; anything escaping is a
defect.

``liansuo fuzz recordings --budget N`` runs the same generator longer; ``tests/test_fuzz_recordings.py`` runs it
derandomized with a small budget.
"""

from __future__ import annotations

import json
import tempfile
from collections.abc import Callable
from functools import cache
from importlib.resources import files
from pathlib import Path
from typing import Any

import yaml
from hypothesis import strategies as st

from liansuo.kit.source import StationError
from liansuo.rules import load_rules
from liansuo.simulation.recording.file import load_recording, recording_station
from liansuo.simulation.recording.recorder import Recorder
from liansuo.simulation.recording.replayer import Replayer
from liansuo.simulation.sim import Simulation
from liansuo.simulation.timeparse import parse_duration

NAME = "recordings"
Sample = bytes

SCENARIOS = ("jiaopei-receive-depart", "depot-auto-shunting", "gaotie-dead-zone-train")
SEED_RUN_S = 20.0  # each 'run' step of a scenario seed at most this long: a seed replays in a fraction of a second
# a console session on jiaopei: a route, occupancy, a release, faults (one of them a lamp), refused commands
SESSION = ("jiaopei", ("route X XI", "run 2s", "occupy IAG", "run 5s", "release X", "fault no-indication 5",
                       "route S SI", "fault filament XI lamp=H", "run 2s", "repair filament XI", "vacate IAG",
                       "throw 5 reverse", "run 3s", "cancel S", "route X X3", "run 10s"))

DrawFn = Callable[[st.SearchStrategy[Any]], Any]
EXTREMES: tuple[Any, ...] = (float("nan"), float("inf"), float("-inf"), -1, 0, 1, 0.0, 1e308, -1e308, 2**31, 2**63,
                             10**30, 1e9, 345_601, "", "x" * 5000, "\x1b[2J\x1b]0;owned\x07", "\u2028", "\x00", None,
                             True, [], {}, [[[]]], {"k": "cmd"})
STATIONS = ("gaotie", "depot", "jiaopei", "/dev/zero", "/tmp", "../nowhere.yaml", "", "x" * 5000, "\x1b[2J", ".",
            "/etc/passwd", "../../../../etc/passwd", "sub/../../x.yaml")  # outside the recording's folder
DIGESTS = ("", "0" * 64, "A" * 64, "x")  # empty: the station unchecked (issue 45)
COMMAND_LINES = ("run 100h", "run 50min", "run 1s", "", "expect alarm nothing", "route X XI", "cancel X", "bogus",
                 "run 0s")


# ---- seeds ----------------------------------------------------------------------------------------------------------
def _record(station: str, steps: tuple[str, ...]) -> bytes:
    """A session of ``steps`` on ``station`` as the recorder writes it."""
    sim = Simulation(station)
    lines: list[str] = []
    rec = Recorder(sim, lambda r: lines.append(json.dumps(r, ensure_ascii=False, separators=(",", ":")))).attach()
    for step in steps:
        sim.command(step)
    rec.detach()
    rec.end()
    return ("\n".join(lines) + "\n").encode("utf-8")


def _scenario_steps(name: str) -> tuple[str, tuple[str, ...]]:
    """A bundled example scenario's station and steps, each run cut to :data:`SEED_RUN_S`."""
    data = yaml.safe_load((files("liansuo") / "examples" / "scenarios" / f"{name}.yaml").read_text(encoding="utf-8"))
    steps = []
    for step in data["steps"]:
        words = str(step).split("#", 1)[0].split()
        if words[:1] == ["run"] and len(words) == 2:
            step = f"run {min(parse_duration(words[1]), SEED_RUN_S):g}s"
        steps.append(str(step))
    return str(data["station"]), tuple(steps)


@cache
def seeds() -> tuple[bytes, ...]:
    """The real recordings every sample starts from."""
    return (_record(*SESSION), *(_record(*_scenario_steps(name)) for name in SCENARIOS))


# ---- damages --------------------------------------------------------------------------------------------------------
def _index(draw: DrawFn, items: list[Any]) -> int:
    """An index past the header (its own damages are :func:`_header`), evenly spread over the lines (hypothesis's
    integers favour the smallest; its Random, derandomized with the rest, does not)."""
    return int(draw(st.randoms(use_true_random=False)).randrange(1, len(items))) if len(items) > 1 else 0


def _drop(draw: DrawFn, lines: list[bytes]) -> list[bytes]:
    i = _index(draw, lines)
    return lines[:i] + lines[i + 1:]


def _repeat(draw: DrawFn, lines: list[bytes]) -> list[bytes]:
    i = _index(draw, lines)
    return lines[:i + 1] + lines[i:]


def _swap(draw: DrawFn, lines: list[bytes]) -> list[bytes]:
    i, j = _index(draw, lines), _index(draw, lines)
    out = list(lines)
    out[i], out[j] = out[j], out[i]
    return out


def _cut(draw: DrawFn, lines: list[bytes]) -> list[bytes]:
    """The file cut short inside a line (a disk full, a killed console)."""
    i = _index(draw, lines)
    at = int(draw(st.integers(0, max(0, len(lines[i]) - 1))))
    return [*lines[:i], lines[i][:at]]


def _bytes(draw: DrawFn, lines: list[bytes]) -> list[bytes]:
    """Bytes no editor means: not UTF-8, NUL, a byte-order mark, CR line ends."""
    i = _index(draw, lines)
    junk = draw(st.sampled_from((b"\xff", b"\xc3", b"\x00", b"\xef\xbb\xbf", b"\r", b"\xed\xa0\x80")))
    at = int(draw(st.integers(0, len(lines[i]))))
    out = list(lines)
    out[i] = lines[i][:at] + junk + lines[i][at:]
    return out


def _nest(draw: DrawFn, lines: list[bytes]) -> list[bytes]:
    """A value nested deeper than any parser goes."""
    i = _index(draw, lines)
    depth = int(draw(st.sampled_from((50, 1_000, 100_000))))
    out = list(lines)
    out[i] = lines[i].rstrip(b"}") + b',"x":' + b"[" * depth + b"]" * depth + b"}"
    return out


def _paths(value: Any, at: tuple[Any, ...] = ()) -> list[tuple[Any, ...]]:
    """Every place in a JSON value: keys of objects and items of arrays."""
    out = [at] if at else []
    if isinstance(value, dict):
        for k, v in value.items():
            out += _paths(v, (*at, k))
    elif isinstance(value, list):
        for n, v in enumerate(value):
            out += _paths(v, (*at, n))
    return out


def _header(draw: DrawFn, lines: list[bytes]) -> list[bytes]:
    """The header's values: the station, the cycle, the version ..."""
    return _edit(draw, lines, 0)


def _edit(draw: DrawFn, lines: list[bytes], line: int | None = None) -> list[bytes]:
    """One value of one record removed, or replaced by an extreme, another station or another command."""
    i = _index(draw, lines) if line is None else line
    try:
        record = json.loads(lines[i])
    except (ValueError, RecursionError):  # a line damaged already: nothing to edit in it
        return lines
    places = _paths(record)
    if not places:
        return lines
    place = draw(st.sampled_from(places))
    *parents, last = place
    holder = _at(record, tuple(parents))
    if draw(st.booleans()) and isinstance(holder, dict):
        del holder[last]
    elif last == "station":
        holder[last] = draw(st.sampled_from(STATIONS))
    elif last == "station_sha256":
        holder[last] = draw(st.sampled_from(DIGESTS))
    elif last == "line":
        holder[last] = draw(st.sampled_from(COMMAND_LINES))
    else:
        holder[last] = draw(st.sampled_from(EXTREMES))
    out = list(lines)
    out[i] = json.dumps(record, ensure_ascii=False, separators=(",", ":")).encode("utf-8", "surrogatepass")
    return out


def _plausible(draw: DrawFn, lines: list[bytes]) -> list[bytes]:
    """A value changed to another of its kind, so the file still reads and only the replay can tell: a relay
    state flipped, an aspect or a section state swapped, an answer changed, a record moved a cycle (its time
    with it)."""
    i = _index(draw, lines)
    try:
        record = json.loads(lines[i])
    except (ValueError, RecursionError):
        return lines
    if not isinstance(record, dict):
        return lines
    n, t = record.get("n"), record.get("t")
    if isinstance(n, int) and isinstance(t, float) and record.get("k") != "init" and draw(st.booleans()):
        step = t / n if n > 0 else 0.25
        record["n"] = max(0, record["n"] + draw(st.sampled_from((-1, 1, 4))))
        record["t"] = round(record["n"] * step, 9)
    else:
        leaves = [p for p in _paths(record) if not isinstance(_at(record, p), dict | list) and p[0] != "k"]
        if not leaves:
            return lines
        *parents, last = draw(st.sampled_from(leaves))
        holder = _at(record, tuple(parents))
        value = holder[last]
        if isinstance(value, bool):
            holder[last] = not value
        elif isinstance(value, str) or value is None:
            holder[last] = draw(st.sampled_from((*load_rules().aspects.lamps, "locked", "free", "occupied",
                                                 "normal", "reverse", None, "route X XI", "cancel X")))
        elif isinstance(value, int | float):
            holder[last] = value + draw(st.sampled_from((-1, 1)))
    out = list(lines)
    out[i] = json.dumps(record, ensure_ascii=False, separators=(",", ":")).encode("utf-8")
    return out


def _at(value: Any, place: tuple[Any, ...]) -> Any:
    for p in place:
        value = value[p]
    return value


DAMAGES = (_drop, _repeat, _swap, _cut, _bytes, _nest, _header, _edit, _edit, _edit, _plausible, _plausible,
           _plausible, _plausible)


@st.composite
def _sample(draw: DrawFn) -> Sample:
    lines = draw(st.sampled_from(seeds())).split(b"\n")
    for _ in range(draw(st.sampled_from((1, 1, 1, 2, 3)))):
        if lines:
            lines = draw(st.sampled_from(DAMAGES))(draw, lines)
    return b"\n".join(lines)


def strategy() -> st.SearchStrategy[Sample]:
    """Damaged copies of real recordings."""
    return _sample()


def attempt(sample: Sample) -> str:
    """``replay --verify`` on ``sample``: "accepted" when it loads and replays to the recorded outputs, "refused"
    when it is refused with a diagnostic or its replay finds mismatches."""
    with tempfile.TemporaryDirectory(prefix="liansuo-fuzz-") as folder:
        path = Path(folder) / "session.jsonl"
        path.write_bytes(sample)
        try:
            rec = load_recording(path)
            station = recording_station(rec)
        except StationError as exc:  # the loader's documented refusal: a FILE:LINE diagnostic for each problem
            if not exc.diagnostics or not all(str(d) for d in exc.diagnostics):
                raise AssertionError("refused without a message") from exc
            return "refused"
        return "refused" if Replayer(rec, station).verify() else "accepted"

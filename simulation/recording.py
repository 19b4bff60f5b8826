"""Recording and replay of a session, like a CBI maintenance terminal's data recorder (维护台数据回放).

A :class:`Recorder` attached to a :class:`~simulation.sim.Simulation` writes a compact JSON-lines file:

- a header: ``{"k": "header", "format": "liansuo-recording", "version": 1, "station": ..., "cycle_s": ...}``;
- ``{"k": "init", ...}``: the full state when recording started;
- ``{"k": "cmd", "n": N, "t": T, "line": ..., "ok": ..., "msg": ..., "by": ...}``: every command with the number of
  cycles run before it, its simulated time, its answer and who sent it (trainee, instructor, exercise);
- ``{"k": "cyc", "n": N, "t": T, "in": {...}, "out": {...}}``: after each cycle, only what changed: relay inputs
  (``gj`` track relays, ``ind`` turnout indication, ``dj`` proven lamps, ``pd`` door relays PDKJ/PDQCJ) and outputs
  (``sig`` aspects, ``drv`` turnout drives, ``sec`` section states). Cycles that change nothing are not written.

Time is injected, so a session is reproduced by re-simulating the recorded commands on the recorded station:
:class:`Replayer` does that, cycle by cycle, and checks every cycle's changes against the file.
"""

from __future__ import annotations

import json
from collections.abc import Callable, Iterator
from dataclasses import dataclass, field
from pathlib import Path
from typing import IO, Any

from liansuo.interlocking.io import Result
from liansuo.stations.filekind import RECORDING_FORMAT, kind_of_data, kind_of_text, wrong_kind
from liansuo.stations.source import StationError, read_text, read_yaml

from .sim import Simulation

FORMAT = RECORDING_FORMAT
VERSION = 1

Record = dict[str, Any]
State = dict[str, dict[str, dict[str, Any]]]


def snapshot(sim: Simulation) -> State:
    """Relay inputs and outputs of the interlocking now, as plain JSON values."""
    board, out = sim.view.inputs, sim.view.outputs
    st = sim.station
    return {
        "in": {
            "gj": {s: board.clear(s) for s in st.sections},
            "ind": {t: board.indication(t) for t in st.turnouts},
            "dj": {s: sorted(lamp for lamp, ok in board.lamps.get(s, {}).items() if ok) for s in st.signals},
            "pd": {k: [board.pdkj.get(k, False), board.pdqcj.get(k, False)] for k in out.doors},
        },
        "out": {
            "sig": dict(sorted(out.signals.items())),
            "drv": {t: out.turnouts.get(t) for t in st.turnouts},
            "sec": {s: sim.section_state(s) for s in st.sections},
        },
    }


def diff(before: State, after: State) -> State:
    """What changed from ``before`` to ``after``: only the groups and keys that differ."""
    out: State = {}
    for side, groups in after.items():
        for group, values in groups.items():
            old = before.get(side, {}).get(group, {})
            changed = {k: v for k, v in values.items() if old.get(k) != v}
            if changed:
                out.setdefault(side, {})[group] = changed
    return out


class Recorder:
    """Records a simulation's commands and cycles through ``write`` (one dict per record).

    ``attach()`` wraps the simulation's ``step`` and ``command`` on that instance (``detach()`` restores them), so
    cycles run inside a ``run`` command are recorded too. ``source`` names who sends the next commands.
    """

    def __init__(self, sim: Simulation, write: Callable[[Record], None], *, station: str = "") -> None:
        self.sim = sim
        self.write = write
        self.station = station or sim.station.id
        self.source = "console"
        self.cycles = 0
        self._state = snapshot(sim)
        self._depth = 0
        self._held: list[Record] = []
        self._step: Callable[[], None] | None = None
        self._command: Callable[[str], Result] | None = None

    def header(self) -> None:
        self.write({"k": "header", "format": FORMAT, "version": VERSION, "station": self.station,
                    "station_id": self.sim.station.id, "cycle_s": self.sim.cycle_s, "t0": self.sim.t})
        self.write({"k": "init", "n": 0, "t": self.sim.t, **self._state})

    def attach(self) -> Recorder:
        self.header()
        self._step, self._command = self.sim.step, self.sim.command
        object.__setattr__(self.sim, "step", self._recorded_step)
        object.__setattr__(self.sim, "command", self._recorded_command)
        return self

    def detach(self) -> None:
        for name in ("step", "command"):
            self.sim.__dict__.pop(name, None)

    def _recorded_step(self) -> None:
        assert self._step is not None
        self._step()
        self.cycles += 1
        now = snapshot(self.sim)
        changes = diff(self._state, now)
        self._state = now
        if changes:
            self._emit({"k": "cyc", "n": self.cycles, "t": self.sim.t, **changes})

    def _recorded_command(self, line: str) -> Result:
        assert self._command is not None
        n, t = self.cycles, self.sim.t
        self._depth += 1
        try:
            result = self._command(line)
        finally:
            self._depth -= 1
        if self._depth == 0:
            held, self._held = self._held, []
            if not line.strip().startswith("expect"):
                self.write({"k": "cmd", "n": n, "t": t, "line": line, "ok": result.ok, "msg": result.message,
                            "by": self.source})
            for r in held:
                self.write(r)
            now = snapshot(self.sim)
            changes = diff(self._state, now)
            self._state = now
            if changes:
                self.write({"k": "chg", "n": self.cycles, "t": self.sim.t, **changes})
        return result

    def _emit(self, record: Record) -> None:
        if self._depth:
            self._held.append(record)  # cycles inside a command are written after the command itself
        else:
            self.write(record)


class FileRecorder(Recorder):
    """A recorder writing JSON lines to a file."""

    def __init__(self, sim: Simulation, path: str | Path, *, station: str = "") -> None:
        self.path = Path(path)
        self._fh: IO[str] = self.path.open("w", encoding="utf-8")
        super().__init__(sim, self._write_line, station=station)

    def _write_line(self, record: Record) -> None:
        self._fh.write(json.dumps(record, ensure_ascii=False, separators=(",", ":")) + "\n")
        if record["k"] != "cyc":
            self._fh.flush()

    def close(self) -> None:
        """Write the end mark (so a quiet tail of the session keeps its length) and close the file."""
        if self._fh.closed:
            return
        self.detach()
        self._write_line({"k": "end", "n": self.cycles, "t": self.sim.t})
        self._fh.close()


# ---- loading and replay ---------------------------------------------------------------------------------------------
@dataclass
class Recording:
    path: str
    station: str
    station_id: str
    cycle_s: float
    records: list[Record] = field(default_factory=list)

    @property
    def commands(self) -> list[Record]:
        return [r for r in self.records if r["k"] == "cmd"]

    @property
    def cycles(self) -> int:
        return max((int(r["n"]) for r in self.records if r["k"] in ("cyc", "cmd", "chg", "end")), default=0)

    @property
    def duration(self) -> float:
        return self.cycles * self.cycle_s


class RecordingError(ValueError):
    pass


def load_recording(path: str | Path) -> Recording:
    """Read a recording; :class:`RecordingError` names the line of anything malformed, and the kind of a file that
    is another kind of liansuo file (a station, a script ...)."""
    p = Path(path)
    try:  # within the input limits: a device, a pipe or a file too large is refused, never read
        whole = read_text(p, "give a recording written by 'liansuo tui --record FILE'")
    except StationError as exc:
        d = exc.diagnostics[0]
        raise RecordingError(f"{d.file}:{d.line}: {d.message}") from None
    if kind_of_text(whole) != "recording":
        try:
            found = kind_of_data(read_yaml(whole, str(p)).data)
        except StationError:
            found = None
        if found is not None:
            raise RecordingError(str(wrong_kind(str(p), found, "recording").diagnostics[0]))
    lines = whole.splitlines()
    records: list[Record] = []
    for i, text in enumerate(lines, 1):
        if not text.strip():
            continue
        try:
            rec = json.loads(text)
        except json.JSONDecodeError as exc:
            raise RecordingError(f"{p}:{i}: not a JSON record: {exc.msg}") from exc
        if not isinstance(rec, dict) or "k" not in rec:
            raise RecordingError(f"{p}:{i}: a record is an object with a 'k' key")
        records.append(rec)
    if not records or records[0].get("k") != "header" or records[0].get("format") != FORMAT:
        raise RecordingError(f"{p}:1: not a liansuo recording (no header line)")
    head = records[0]
    if head.get("version") != VERSION:
        raise RecordingError(f"{p}:1: recording format version {head.get('version')} (this liansuo reads {VERSION})")
    return Recording(str(p), str(head["station"]), str(head.get("station_id", "")), float(head["cycle_s"]),
                     records[1:])


class Replayer:
    """Re-simulates a recording on a fresh simulation and checks each cycle against the recorded changes."""

    def __init__(self, rec: Recording, make_sim: Callable[[str, float], Simulation] | None = None) -> None:
        self.rec = rec
        self._make = make_sim or _default_sim
        self.expected: dict[int, Record] = {int(r["n"]): r for r in rec.records if r["k"] == "cyc"}
        self.commands = rec.commands
        self.changes = [r for r in rec.records if r["k"] == "chg"]
        self.mismatches: list[str] = []
        self.reset()

    def reset(self) -> None:
        self.sim = self._make(self.rec.station, self.rec.cycle_s)
        self.recorder = Recorder(self.sim, self._check, station=self.rec.station).attach()
        self.next_cmd = 0
        self.next_chg = 0
        self.mismatches = []
        self.played: list[Record] = []  # commands replayed so far, with their answers now

    @property
    def cycle(self) -> int:
        return self.recorder.cycles

    def _check(self, record: Record) -> None:
        if record["k"] == "chg":
            want = self.changes[self.next_chg] if self.next_chg < len(self.changes) else {}
            self.next_chg += 1
        elif record["k"] == "cyc":
            want = self.expected.get(int(record["n"]), {})
        else:
            return
        n = int(record["n"])
        got = {k: record[k] for k in ("in", "out") if k in record}
        exp = {k: want[k] for k in ("in", "out") if k in want}
        if got != exp and len(self.mismatches) < 50:
            self.mismatches.append(f"cycle {n} (t = {record['t']:g} s): recorded {json.dumps(exp)}, "
                                   f"replayed {json.dumps(got)}")

    def advance(self, cycle: int) -> None:
        """Run forward to ``cycle`` cycles, sending each recorded command at its place."""
        cycle = min(cycle, self.rec.cycles)
        while True:
            cmd = self.commands[self.next_cmd] if self.next_cmd < len(self.commands) else None
            if cmd is not None and int(cmd["n"]) <= self.cycle and int(cmd["n"]) <= cycle:
                self.next_cmd += 1
                self.recorder.source = str(cmd.get("by", ""))
                result = self.sim.command(str(cmd["line"]))
                self.played.append({**cmd, "ok_now": result.ok, "msg_now": result.message})
                if result.ok != cmd.get("ok") or result.message != cmd.get("msg"):
                    self.mismatches.append(f"command '{cmd['line']}' at t = {cmd['t']:g} s answered "
                                           f"'{result.message}', recorded '{cmd.get('msg')}'")
                continue
            if self.cycle >= cycle:
                return
            self.sim.step()

    def seek(self, t: float) -> None:
        target = max(0, round(t / self.rec.cycle_s))
        if target < self.cycle:
            self.reset()
        self.advance(target)

    def verify(self) -> list[str]:
        """Replay the whole recording from the start; the mismatches (none when the replay reproduces it)."""
        self.reset()
        self.advance(self.rec.cycles)
        return self.mismatches


def _default_sim(station: str, cycle_s: float) -> Simulation:
    return Simulation(station, cycle_s=cycle_s)


def iter_lines(rec: Recording) -> Iterator[str]:
    """A readable listing of the recorded commands."""
    for r in rec.commands:
        mark = "ok" if r.get("ok") else "refused"
        yield f"{float(r['t']):9.2f} {r.get('by', '')!s:10} {r['line']}  -> {mark}: {r.get('msg', '')}"

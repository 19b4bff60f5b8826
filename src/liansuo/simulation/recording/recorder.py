"""Recording of a session, like a CBI maintenance terminal's data recorder (维护台数据回放).

A :class:`Recorder` attached to a :class:`~simulation.sim.Simulation` writes a compact JSON-lines file (the format in
docs/console.md, "The recording file"; every record's model in :mod:`.schema`):

- a header: ``{"k": "header", "format": "liansuo-recording", "version": 2, "station": ..., "station_id": ...,
  "station_sha256": ..., "cycle_s": ..., "t0": ...}``: the station by bundled name or by its path relative to the
  recording, with its id and the digest of its file;
- ``{"k": "init", "n": 0, "t": T, "in": {...}, "out": {...}}``: the full state when recording started;
- ``{"k": "cmd", "i": I, "n": N, "t": T, "line": ..., "ok": ..., "msg": ..., "by": ...}``: every command, numbered
  from 1, with the number of cycles run before it, its simulated time, its answer and who sent it (trainee,
  instructor, exercise);
- ``{"k": "cyc", "n": N, "t": T, "in": {...}, "out": {...}}``: after each cycle, only what changed: relay inputs
  (``gj`` track relays, ``ind`` turnout indication, ``dj`` proven lamps, ``pd`` door relays PDKJ/PDQCJ) and outputs
  (``sig`` aspects, ``drv`` turnout drives, ``sec`` section states). Cycles that change nothing are not written;
- ``{"k": "chg", ...}``: what a command changed without a cycle, right after it (and the cycles it ran);
- ``{"k": "end", "n": N, "t": T, "cmds": C}``: the session's length and its number of commands.

Commands the trains' automation sends during a cycle are not recorded: the replay's own automation sends them again.
Time is injected, so a session is reproduced by re-simulating the recorded commands on the recorded station
(:mod:`.replayer`). Reading a recording: :mod:`.file`.
"""

from __future__ import annotations

import json
from collections.abc import Callable
from pathlib import Path
from typing import IO, Any

from liansuo.interlocking.io import Result
from liansuo.simulation.recording.file import Recording, RecordingError, load_recording, station_reference
from liansuo.simulation.recording.schema import FORMAT, MAX_COMMAND_CHARS, VERSION
from liansuo.simulation.sim import Simulation

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
    cycles run inside a ``run`` command are recorded too. ``source`` names who sends the next commands. ``path``
    is the file written, if any: the header names a station file relative to it.
    """

    def __init__(self, sim: Simulation, write: Callable[[Record], None], *, path: Path | None = None) -> None:
        self.sim = sim
        self.write = write
        self.path = path
        self.source = "console"
        self.cycles = 0
        self.commands = 0
        self._state = snapshot(sim)
        self._depth = 0
        self._held: list[Record] = []
        self._step: Callable[[], None] | None = None
        self._command: Callable[[str], Result] | None = None

    def header(self) -> None:
        station, digest = station_reference(self.sim.station, self.path)
        if not digest:  # the replay checks the station by this digest: a recording without one is refused
            raise ValueError(f"station {self.sim.station.id} was not read from a file: a recording names its station's "
                             "file and its SHA-256; load the station from a file to record it")
        self.write({"k": "header", "format": FORMAT, "version": VERSION, "station": station,
                    "station_id": self.sim.station.id, "station_sha256": digest,
                    "cycle_s": self.sim.cycle_s, "t0": self.sim.t})
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

    def end(self) -> None:
        """The end record: the session's length and how many commands it sent."""
        self.write({"k": "end", "n": self.cycles, "t": self.sim.t, "cmds": self.commands})

    def _recorded_step(self) -> None:
        assert self._step is not None
        self._depth += 1  # what the trains' automation commands during the cycle is part of the cycle
        try:
            self._step()
        finally:
            self._depth -= 1
        self.cycles += 1
        self._cycle_done(self._changes())

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
                self.commands += 1
                self._command_done(n, t, line, result)
            for r in held:
                self.write(r)
            self._command_changes(self._changes())
        return result

    def _changes(self) -> State:
        now = snapshot(self.sim)
        changes = diff(self._state, now)
        self._state = now
        return changes

    # what is written; the replay's checker (:mod:`.replayer`) compares instead
    def _cycle_done(self, changes: State) -> None:
        if changes:
            record = {"k": "cyc", "n": self.cycles, "t": self.sim.t, **changes}
            if self._depth:
                self._held.append(record)  # cycles inside a command are written after the command itself
            else:
                self.write(record)

    def _command_done(self, n: int, t: float, line: str, result: Result) -> None:
        self.write({"k": "cmd", "i": self.commands, "n": n, "t": t, "line": line[:MAX_COMMAND_CHARS], "ok": result.ok,
                    "msg": result.message, "by": self.source})

    def _command_changes(self, changes: State) -> None:
        if changes:
            self.write({"k": "chg", "n": self.cycles, "t": self.sim.t, **changes})


class FileRecorder(Recorder):
    """A recorder writing JSON lines to a file."""

    def __init__(self, sim: Simulation, path: str | Path) -> None:
        file = Path(path)
        self._fh: IO[str] = file.open("w", encoding="utf-8")  # closed by close(), when the session ends
        super().__init__(sim, self._write_line, path=file)

    def _write_line(self, record: Record) -> None:
        self._fh.write(json.dumps(record, ensure_ascii=False, separators=(",", ":")) + "\n")
        if record["k"] != "cyc":
            self._fh.flush()

    def close(self) -> None:
        """Write the end mark (so a quiet tail of the session keeps its length) and close the file."""
        if self._fh.closed:
            return
        self.detach()
        self.end()
        self._fh.close()


__all__ = ["FileRecorder", "Recorder", "Recording", "RecordingError", "diff", "load_recording", "snapshot"]

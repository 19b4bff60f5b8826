"""Playing a recorded session back (``liansuo replay FILE``), like a maintenance terminal's data replay.

The console re-simulates the recording on its station from the recorded commands (time is injected, so this is
deterministic) and checks every cycle against the recorded relay inputs and outputs; a mismatch is shown in the
status line. The clock keys work as in the live console (space, ``.``, ``>``, ``<``), plus seeking: ``[`` / ``]``
10 s back / forward, ``{`` / ``}`` 60 s, Home / End, and ``seek DURATION`` in the command bar. The diagram cannot be
operated: a replay only shows what happened.
"""

from __future__ import annotations

from typing import ClassVar

from rich.text import Text
from textual.binding import Binding, BindingType

from liansuo.kit.printable import printable
from liansuo.simulation import Result
from liansuo.simulation.recording.file import Recording
from liansuo.simulation.recording.replayer import Replayer
from liansuo.simulation.timeparse import parse_duration
from liansuo.stations.station import Station
from liansuo.tui.app import ConsoleApp
from liansuo.tui.grid import Ref
from liansuo.tui.panels import clock_text


class ReplayApp(ConsoleApp):
    TITLE = "liansuo 联锁 replay"
    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("left_square_bracket", "seek(-10)", "-10s", key_display="["),
        Binding("right_square_bracket", "seek(10)", "+10s", key_display="]"),
        Binding("left_curly_bracket", "seek(-60)", "-60s", show=False),
        Binding("right_curly_bracket", "seek(60)", "+60s", show=False),
        Binding("home", "seek_to(0)", "start", show=False, priority=True),  # over the diagram's scrolling
        Binding("end", "seek_to(-1)", "end", show=False, priority=True),
    ]

    def __init__(self, rec: Recording, station: Station | None = None, *, speed: float = 1.0,
                 paused: bool = False) -> None:
        self.replayer = Replayer(rec, station)
        self.rec = rec
        super().__init__(rec.station, paused=paused, speed=speed, sim=self.replayer.sim)
        self.warm_up = False  # the recording has its own first cycle

    def started(self) -> None:
        log = self.log_panel
        log.add(f"replay of {printable(self.rec.path)}: {self.rec.duration:g} s, {len(self.rec.commands)} commands",
                "bold")
        self.say("replay: space play/pause, [ ] seek 10 s, { } 60 s, Home/End, > < speed, ': seek 2min'")

    def advance(self, cycles: int) -> None:
        target = self.replayer.cycle + cycles
        before = len(self.replayer.played)
        self.replayer.advance(target)
        self._log_played(before)
        if self.replayer.done:
            self.paused = True

    def _log_played(self, before: int) -> None:
        log = self.log_panel
        for played in self.replayer.played[before:]:
            cmd = played.cmd
            who = f"{printable(cmd.by)}>"
            log.add(f"{cmd.t:9.2f} {who:8} {printable(cmd.line)}", "#9fd3ff")
            if not cmd.ok:
                log.add(f"{cmd.t:9.2f} {'refused':8} {printable(cmd.msg)}", "#ff8080")

    def seek(self, t: float) -> None:
        try:
            self._seek(t)
        except Exception as exc:  # no traceback on the screen: in the alarms, and on stderr when the console closes
            self.paused = True
            incident = self.report_unexpected(exc, "seeking")
            self.say(f"replay stopped: {incident.summary}", False)

    def _seek(self, t: float) -> None:
        t = max(0.0, min(t, self.rec.duration))
        old = self.sim
        before = len(self.replayer.played)
        self.replayer.seek(t)
        if self.replayer.sim is not old:  # seeking back re-simulates from the start
            self.sim = self.replayer.sim
            self.operator.sim = self.sim
            self.events.reset()
            self.log_panel.show([])
            before = 0
        self._log_played(before)
        self.diagram.update_view()
        self.refresh_views()

    def action_seek(self, seconds: float) -> None:
        self.seek(self.sim.t + seconds)

    def action_seek_to(self, t: float) -> None:
        self.seek(self.rec.duration if t < 0 else t)

    def send(self, line: str, source: str = "trainee") -> Result:
        words = line.split()
        if words and words[0] == "seek" and len(words) == 2:
            try:
                self.seek(parse_duration(words[1]))
            except ValueError as exc:
                self.say(str(exc), False)
                return Result.refuse(str(exc))
            return Result.accept(f"t = {self.sim.t:g} s")
        why = "replay: the recorded session is only shown; commands here are 'seek DURATION'"
        self.say(why, False)
        return Result.refuse(why)

    def press(self, ref: Ref) -> None:
        self.say("replay: the diagram only shows the recorded session", None)

    def action_arm(self, mode: str) -> None:
        self.say("replay: the diagram only shows the recorded session", None)

    def status_text(self, alarms: int) -> Text:
        out = Text(no_wrap=True, overflow="ellipsis")
        out.append(" REPLAY ", style="bold black on #ffd700")
        out.append(printable(f" {self.sim.station.model.name.zh} ") +
                   f"│ t {clock_text(self.sim.t)} / {clock_text(self.rec.duration)} ")
        out.append("⏸ " if self.paused else "▶ ", style="bold #ffd700" if self.paused else "#80ff80")
        out.append(f"{self.speed:g}x ")
        if alarms:
            out.append(f"│ ⚠ {alarms} ", style="bold #ff4040")
        bad = self.replayer.mismatches
        out.append(f"│ ✗ {len(bad)} mismatches " if bad else "│ ✓ outputs match ",
                   style="bold #ff4040" if bad else "#40e070")
        return out

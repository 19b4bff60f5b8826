"""The operator console (操作表示机): a Textual app over one :class:`~simulation.sim.Simulation`.

The console is a thin view: everything it changes goes through the command language (``sim.command``), and it
reads the simulation only to draw it. It paces ``sim.step()`` against the wall clock (1x real time by default);
the layers below never read the wall clock. A recorder may be attached to write the session to a file, and the same
app plays a recording back (:mod:`tui.replay`).

No input ends it unasked: a long ``run`` goes in slices (:mod:`tui.longrun`), an error nobody expected is shown in the
alarm panel and the console carries on (:mod:`tui.guard`, :mod:`tui.incidents`), and every way out asks first.
"""

from __future__ import annotations

import os
import time
from pathlib import Path
from typing import ClassVar

from rich.text import Text
from textual.actions import SkipAction
from textual.app import ComposeResult
from textual.binding import BindingType
from textual.containers import Horizontal
from textual.widgets import Footer, Input

from liansuo.classroom.exercise import Exercise, GoalCheck
from liansuo.classroom.passwords import ENV, hash_password
from liansuo.classroom.roles import INSTRUCTOR, TRAINEE, command_word, refusal
from liansuo.kit.printable import printable
from liansuo.simulation import Result
from liansuo.simulation.fieldlink import FieldLink
from liansuo.simulation.recording.recorder import FileRecorder
from liansuo.simulation.sim import Simulation
from liansuo.tui.commands import ConsoleCommands, PaletteCommand, console_commands
from liansuo.tui.completion import example_route
from liansuo.tui.consolesim import ConsoleSim
from liansuo.tui.describe import describe
from liansuo.tui.diagram import Diagram, DiagramColumn
from liansuo.tui.dialogs import ConfirmScreen, HelpScreen, MenuScreen
from liansuo.tui.fieldmode import FieldModeControls
from liansuo.tui.grid import Ref
from liansuo.tui.incidents import KEY_PREFIX, Incident
from liansuo.tui.instructor import InstructorPanel
from liansuo.tui.keys import CONSOLE_BINDINGS
from liansuo.tui.lesson import LessonControls
from liansuo.tui.longrun import LongRun, requested_run
from liansuo.tui.operate import ConsoleOperator, PressOutcome
from liansuo.tui.panels import (
    AlarmBell,
    AlarmLine,
    AlarmPanel,
    CommandBar,
    EventLog,
    EventReader,
    FunctionBar,
    MessageLine,
    StatusBar,
    clock_text,
    read_alarms,
    sender,
    waiting_text,
)
from liansuo.tui.safeapp import SafeApp

SPEEDS = (0.25, 0.5, 1.0, 2.0, 4.0, 8.0, 16.0, 32.0, 64.0)
TICK_S = 0.125  # redraw at 8 Hz: often enough for the USU flash (35 per minute)
MAX_STEPS_PER_TICK = 400
QUIT_WORDS = ("quit", "exit")  # typed in the command bar, they close the console (after asking), as ctrl+q does
MUTE_WORDS = {"mute": True, "unmute": False}  # typed in the command bar, they mute or unmute the alarm bell, as m does


class ConsoleApp(SafeApp, LessonControls, FieldModeControls):
    TITLE = "liansuo 联锁"
    # The console runs its simulation's clock (pause, speed, a typed 'run' in slices); a classroom's client does not:
    # the server runs it (remote/app.py)
    LOCAL_CLOCK = True
    # The console refuses a trainee's instructor commands itself; a classroom's client leaves that to the server,
    # which answers and counts them
    LOCAL_ROLES = True
    # No text selection with the mouse, as on a CBI display: a press is always an operation. (Textual's selection also
    # kept the widget under a press and failed when a burst of input removed it before the release.)
    ALLOW_SELECT = False
    # Text too long for its widget ends in an ellipsis instead of folding: Textual cannot fold a word into a width of
    # 0, so a window squeezed through 1x1 with a dialog or the palette open would fail to lay out.
    CSS = """
    * { text-overflow: ellipsis; }
    ConsoleScreen { layout: vertical; background: #0c0f12; }  /* only the console's own: dialogs let it show */
    #main { height: 1fr; }
    #left { width: 1fr; }
    Diagram { height: 3fr; }  /* until the column shares its lines (tui/diagram.py, DiagramColumn) */
    #panels { height: 1fr; min-height: 4; }
    AlarmPanel { width: 2fr; }
    EventLog { width: 3fr; }
    """

    BINDINGS: ClassVar[list[BindingType]] = CONSOLE_BINDINGS
    COMMANDS = SafeApp.COMMANDS | {ConsoleCommands}  # the console's own actions in the palette (tui/commands.py)

    def __init__(self, station: str = "jiaopei", *, paused: bool = False, speed: float = 1.0,
                 instructor_password: str | None = None, instructor_hash: str | None = None,
                 record: str | Path | None = None, exercise: str | Path | None = None, cycle_s: float = 0.25,
                 sim: ConsoleSim | None = None, mute: bool = False, field: FieldLink | None = None,
                 changeover_hash: str | None = None) -> None:
        """``field``: a link to field equipment behind the change-over (docs/field-mode.md); ``changeover_hash``:
        the change-over password (QHA), hashed, asked before each change-over."""
        super().__init__()
        self.station_ref = station
        self.sim: ConsoleSim = sim if sim is not None else Simulation(station, cycle_s=cycle_s)
        if field is not None and isinstance(self.sim, Simulation):
            self.sim.attach_field(field)
        self.changeover_hash = changeover_hash
        self.operator = ConsoleOperator(self.sim)
        self.paused = paused
        self.speed = speed
        # the instructor's password, hashed: from a password file, the argument or the environment; None: none asked
        plain = instructor_password if instructor_password is not None else os.environ.get(ENV)
        self.password = instructor_hash or (hash_password(plain) if plain else None)
        self.instructor = False
        self.acknowledged: set[str] = set()
        self.alarm_bell = AlarmBell(mute)
        self.events = EventReader()
        self.exercise: Exercise | None = None
        self.goal: GoalCheck | None = None
        self.goal_reached_at: float | None = None
        self.goals_met: set[int] = set()  # goals of the exercise met so far (a goal once met stays met)
        self._exercise_arg = exercise
        self._debt = 0.0
        self._wall = time.monotonic()
        self._ticks = 0
        self.warm_up = True
        self._status = Text()
        self._waiting = ""  # why a signal stays red over its route, as last said (panels.waiting_text)
        self.instructor_panel: InstructorPanel | None = None  # mounted the first time instructor mode opens
        self.long_run: LongRun | None = None
        self.recorder: FileRecorder | None = None
        if record is not None and isinstance(self.sim, Simulation):
            self.recorder = FileRecorder(self.sim, record)
            self.recorder.attach()

    # ---- layout ----
    def compose(self) -> ComposeResult:
        yield StatusBar(id="status")
        with Horizontal(id="main"), DiagramColumn(id="left"):
            yield Diagram(lambda: self.sim, self.operator.pressed, id="diagram", operable=self.operator.operable)
            with Horizontal(id="panels"):
                yield AlarmPanel(id="alarms")
                yield EventLog(id="events")
        yield FunctionBar(id="functions")
        yield MessageLine(id="message")
        yield CommandBar(lambda: self.sim, id="command")
        yield Footer()

    def on_mount(self) -> None:
        # the main screen's widgets, kept so the clock and the answers reach them while a dialog is open
        self.diagram = self.query_one(Diagram)
        self.log_panel = self.query_one(EventLog)
        self.alarm_panel = self.query_one(AlarmPanel)
        self.function_bar = self.query_one(FunctionBar)
        self.status_bar = self.query_one(StatusBar)
        self.message_line = self.query_one(MessageLine)
        self.command_bar = self.query_one(CommandBar)
        self.diagram.focus()
        if self.warm_up and self.sim.t == 0:
            self.advance(1)  # one cycle, so the field has lit the lamps the interlocking commanded at start
        self.say(f"{self.sim.station.display_name()}: click a signal's L or D button to start a route; ? for help")
        if self._exercise_arg is not None:
            self.load_exercise(str(self._exercise_arg))
        self.refresh_views()
        self.set_interval(TICK_S, self.tick)
        self.started()

    def started(self) -> None:
        """After mounting (Textual calls every class's on_mount, so subclasses extend this instead)."""

    def on_unmount(self) -> None:
        if self.recorder is not None:
            self.recorder.close()

    # ---- what the safe shell asks of the console (tui/safeapp.py) ----
    def sim_time(self) -> float | None:
        return self.sim.t

    def show_incident(self, incident: Incident, where: str) -> None:
        self.say(f"internal error in {where}: {incident.summary} (see the alarms; the console carries on)", False)
        self.alarm_panel.show(self.alarm_lines(), True)

    def quit_question(self) -> str:
        extra = []
        if self.recorder is not None:
            extra.append(f"the recording {self.recorder.path} is closed")
        if self.long_run is not None:
            extra.append(f"'{self.long_run.line}' stops")
        return "退出 Quit the console?" + (f" ({'; '.join(extra)})" if extra else "")

    def quit_declined(self) -> None:
        self.say("the console stays open")

    # ---- the clock ----
    def tick(self) -> None:
        now = time.monotonic()
        elapsed, self._wall = min(now - self._wall, 1.0), now
        self._ticks += 1
        try:
            if self.long_run is not None:
                self.continue_run()
            elif not self.paused:
                self._debt += elapsed * self.speed
                n = min(int(self._debt / self.sim.cycle_s), MAX_STEPS_PER_TICK)
                self._debt = min(self._debt - n * self.sim.cycle_s, self.sim.cycle_s * MAX_STEPS_PER_TICK)
                self.advance(n)
            self.refresh_views()
        except Exception as exc:  # no traceback on the screen: stop the clock and say what happened
            self.paused = True
            self.long_run = None
            incident = self.report_unexpected(exc, "the clock")
            self.say(f"internal error, clock paused: {incident.summary} (see the alarms)", False)

    def start_run(self, line: str, source: str, seconds: float) -> Result:
        """A ``run`` the language accepted: its first slice now, the rest on the clock's ticks."""
        self.long_run = LongRun.of(line, source, seconds, self.sim.cycle_s)
        self.continue_run()
        if self.long_run is None:  # done in its first slice
            return self.sim.last_result or Result.accept(f"t = {self.sim.t:g} s")
        result = Result.accept(self.long_run.progress())  # the status line shows how far it has gone
        self.say(result.message, True)
        return result

    def continue_run(self) -> None:
        run = self.long_run
        if run is None:
            return
        run.advance(self.advance_one)
        if run.finished:
            self.finish_run()

    def stop_run(self) -> None:
        """Esc while a long ``run`` goes on: it stops where it is."""
        if self.long_run is not None:
            self.finish_run()

    def finish_run(self) -> None:
        run, self.long_run = self.long_run, None
        if run is None:
            return
        answer = run.answer(self.sim.t)
        self.sim.last_result = answer  # what 'expect accepted' checks, as if the language had run it at once
        self._wall, self._debt = time.monotonic(), 0.0
        if not run.finished:
            self.log_panel.add(f"{self.sim.t:9.2f} {'stopped':8} {answer.message}", "#ffd700")
        self.say(answer.message, True)

    def advance_one(self) -> None:
        self.advance(1)

    def advance(self, cycles: int) -> None:
        for _ in range(cycles):
            self.sim.step()

    def alarm_lines(self) -> list[AlarmLine]:
        """The console's own errors first, then the interlocking's and the world's alarms."""
        return self.incidents.alarms() + read_alarms(self.sim, self.acknowledged)

    def refresh_views(self) -> None:
        sim = self.sim
        self.diagram.update_view()
        log = self.log_panel
        for t, kind, text in self.events.new(sim, INSTRUCTOR if self.instructor else TRAINEE):
            log.add(f"{t:9.2f} {kind:8} {text}", "#ff6060" if kind == "alarm" else "")
        alarms = self.alarm_lines()
        self.alarm_panel.show(alarms, int(sim.t * 2) % 2 == 0)
        if self.alarm_bell.due(alarms):
            self.bell()
        if self.exercise is not None and self._ticks % 8 == 0:
            self.check_exercise()
        if self.instructor and self.instructor_panel is not None:
            self.instructor_panel.show_faults(sim)
        self.function_bar.set_armed(self.operator.mode.name if self.operator.mode else None)
        self.function_bar.set_counts(sim.sealed_uses())
        waiting = waiting_text(sim, self.diagram.cursor)
        if waiting != self._waiting:  # a signal newly waiting: say why on the answer line too
            if not waiting and self.message_line.said == self._waiting:
                self.say("")  # it waits no more: the reason said is out of date
            self._waiting = waiting
            if waiting:
                self.say(waiting)
        status = self.status_text(alarms=sum(not a.acknowledged for a in alarms))
        if status != self._status:
            self._status = status
            self.status_bar.update(status)

    def status_text(self, alarms: int) -> Text:
        sim = self.sim
        out = Text(no_wrap=True, overflow="ellipsis")
        out.append(printable(f" {sim.station.model.name.zh} {sim.station.model.name.en} "), style="bold")
        out.append(f"│ t {clock_text(sim.t)} ")
        if self.long_run is not None:
            share = 100 * self.long_run.done // max(1, self.long_run.cycles)
            out.append(f"⏩ {self.long_run.line} {share}% (Esc stops) ", style="bold #80d0ff")
        else:
            out.append("⏸ paused " if self.paused else "▶ ", style="bold #ffd700" if self.paused else "#80ff80")
        out.append(f"{self.speed:g}x ")
        if alarms:
            out.append(f"│ ⚠ {alarms} alarm{'s' if alarms > 1 else ''} ", style="bold #ff4040")
        if self.alarm_bell.muted:
            out.append("│ 🔕 bell muted (m) ", style="#ffd700")
        counting = self.diagram.frame().countdown if self.diagram.layout_ is not None else {}
        if counting:
            out.append("│ 人解 " + " ".join(f"{s} {n}s" for s, n in sorted(counting.items())) + " ", style="#ffd700")
        self.control_status(out)
        self.lesson_status(out)
        self.more_status(out)
        if self._waiting:  # last: the longest, and said whole on the answer line too, so a narrow window cuts it
            out.append(f"│ {self._waiting} ", style="#ff8080")
        return out

    def more_status(self, out: Text) -> None:
        """What a console adds to the status line before why a signal waits (a classroom's seat and its link)."""

    # ---- commands ----
    def send(self, line: str, source: str = "trainee") -> Result:
        """Send one line of the command language; log it with its answer and show the answer. A ``run`` sent by a
        person goes in slices (:mod:`tui.longrun`); while one goes on, other commands wait for it."""
        line = line.strip()
        if not line:
            return Result.accept("")
        if self.long_run is not None:
            why = f"wait: '{self.long_run.line}' is running ({self.long_run.progress()})"
            self.log_panel.add(f"{self.sim.t:9.2f} {'refused':8} {line}: {why}", "#ff8080")
            self.say(why, False)
            return Result.refuse(why)
        if source == "trainee" and self.LOCAL_ROLES and command_word(line) != "run" and \
                (no := refusal(TRAINEE, line)) is not None:
            # the console's own clock ('run') is the trainee's too; the world around the console is not
            why = f"{no.message}{self.instructor_hint()}"
            self.log_panel.add(f"{self.sim.t:9.2f} {'refused':8} {line}: {why}", "#ff8080")
            self.say(why, False)
            return Result.refuse(why)
        if self.asks_password(line, source):
            return Result.accept("")
        return self.carry_out_line(line, source)

    def carry_out_line(self, line: str, source: str) -> Result:
        """Send a line the console has let through: a run in slices, anything else at once."""
        if self.recorder is not None:
            self.recorder.source = source
        try:
            seconds = requested_run(self.sim, line) if self.LOCAL_CLOCK and source in ("trainee", "instructor") \
                else None
            if seconds is not None:
                self.log_panel.add(f"{self.sim.t:9.2f} {sender(source):8} {line}", "#9fd3ff")
                result = self.start_run(line, source, seconds)
                self.refresh_views()
                return result
            result = self.sim.command(line)
        except Exception as exc:  # a command must never bring the console down
            self.long_run = None
            incident = self.report_unexpected(exc, f"the command '{line.split()[0]}'")
            result = Result.refuse(f"internal error: {incident.summary}")
        if source == "exercise" and not self.instructor:  # an exercise's set-up is the instructor's secret
            self.refresh_views()
            return result
        log = self.log_panel
        log.add(f"{self.sim.t:9.2f} {sender(source):8} {line}", "#9fd3ff" if source == "trainee" else "#d0a0ff")
        if not result.ok:
            log.add(f"{self.sim.t:9.2f} {'refused':8} {result.message}", "#ff8080")
        if result.message or not result.ok:
            self.say(result.message or "refused", result.ok)
        self.refresh_views()
        return result

    def say(self, text: str, ok: bool | None = None) -> None:
        self.message_line.say(text, ok)

    def instructor_hint(self) -> str:
        """Said after a trainee's refused instructor command: where the instructor sends it."""
        return "; the instructor opens their panel with F2"

    def on_command_bar_hint(self, event: CommandBar.Hint) -> None:
        self.say(event.text)

    def on_input_submitted(self, event: CommandBar.Submitted) -> None:
        if not isinstance(event.input, CommandBar):
            return
        bar = event.input
        line = event.value.strip().lstrip(":").strip()
        bar.remember(line)
        bar.value = ""
        if line:
            self.submit_line(line)

    def submit_line(self, line: str) -> None:
        if line.split() and line.split()[0] in QUIT_WORDS and len(line.split()) == 1:
            self.call_later(self.action_quit)
            return
        if line in MUTE_WORDS:
            self.set_muted(MUTE_WORDS[line])
            return
        self.send(line, "instructor" if self.instructor else "trainee")

    # ---- operating by buttons ----
    def on_diagram_pressed(self, event: Diagram.Pressed) -> None:
        self.press(event.ref)  # an error here is reported by the guard (tui/guard.py)

    def on_diagram_cursor_moved(self, event: Diagram.CursorMoved) -> None:
        prompt = self.operator.prompt()
        self.say(describe(self.sim, event.ref) + (f"  ·  {prompt}" if prompt else ""))

    def press(self, ref: Ref) -> None:
        panel = self.instructor_panel
        if self.instructor and panel is not None and panel.picking:
            self.say(panel.pick(ref))
            return
        self.carry_out(self.operator.press(ref))

    def carry_out(self, out: PressOutcome) -> None:
        if out.menu is not None:
            kind, element = out.menu
            self.push_screen(MenuScreen(kind, element, self._menu_title(kind, element), self.diagram.cursor_region()),
                             lambda name: self._menu_chosen(kind, element, name))
        elif out.command and out.confirm:
            command = out.command

            def answered(yes: bool | None) -> None:
                if yes:
                    self.send(command)
                else:
                    self.say(f"not sent: {command}")

            self.push_screen(ConfirmScreen(out.confirm, self.diagram.cursor_region()), answered)
        elif out.command:
            self.send(out.command)
        elif out.message:
            self.say(out.message)
        self.function_bar.set_armed(self.operator.mode.name if self.operator.mode else None)
        self.diagram.update_view()

    def _menu_title(self, kind: str, element: str) -> str:
        sim = self.sim
        if kind == "turnout":
            pos, locked = sim.turnout_state(element)
            return f"道岔 turnout {element}: {pos or 'no indication'}{', locked' if locked else ''}"
        if kind == "signal":
            return f"信号机 signal {element}: {sim.aspect(element)}"
        return f"区段 section {element}: {sim.section_state(element)}"

    def _menu_chosen(self, kind: str, element: str, name: str | None) -> None:
        if name:
            self.carry_out(self.operator.apply(name, Ref(kind, element)))

    def on_function_bar_selected(self, event: FunctionBar.Selected) -> None:
        self.action_arm(event.mode)

    # ---- actions ----
    def action_arm(self, mode: str) -> None:
        out = self.operator.arm(mode)
        if out.command:  # a button that acts on the whole station
            self.carry_out(out)
            return
        self.function_bar.set_armed(self.operator.mode.name if self.operator.mode else None)
        self.say(out.message or "function dropped")
        self.diagram.update_view()

    def action_command_bar(self) -> None:
        """':' focuses the bar at once: a priority binding, run before the keys typed after it are passed on, and
        no ``Widget.focus`` (which waits for them), so every key of a quick ``:route X XI`` goes into the bar and none
        arms a function button on the diagram. In a dialog or another input ':' is typed as it is."""
        if self.screen is not self.command_bar.screen or isinstance(self.focused, Input):
            raise SkipAction()
        self.command_bar.screen.set_focus(self.command_bar)

    def action_escape(self) -> None:
        if self.long_run is not None:
            self.stop_run()
            self.refresh_views()
            return
        if self.command_bar.has_focus:
            self.diagram.focus()
            return
        self.operator.reset()
        self.say("selection dropped")
        self.refresh_views()

    def action_pause(self) -> None:
        self.paused = not self.paused
        self._wall = time.monotonic()
        self._debt = 0.0
        self.refresh_views()

    def action_step(self) -> None:
        self.paused = True
        self.advance(1)
        self.refresh_views()

    def action_speed(self, step: int) -> None:
        i = min(range(len(SPEEDS)), key=lambda k: abs(SPEEDS[k] - self.speed))
        self.speed = SPEEDS[max(0, min(len(SPEEDS) - 1, i + step))]
        self.refresh_views()

    def action_acknowledge(self) -> None:
        self.acknowledged |= {a.key for a in read_alarms(self.sim, set())}
        self.incidents.acknowledge()
        self.refresh_views()

    def action_mute(self) -> None:
        self.set_muted(not self.alarm_bell.muted)

    def set_muted(self, muted: bool) -> None:
        self.alarm_bell.muted = muted
        self.say("alarm bell muted (m unmutes)" if muted else "alarm bell on")
        self.refresh_views()

    def on_alarm_panel_acknowledge(self, event: AlarmPanel.Acknowledge) -> None:
        if event.key and event.key.startswith(KEY_PREFIX):
            self.incidents.acknowledge(event.key)
        elif event.key:
            self.acknowledged.add(event.key)
        self.refresh_views()

    def action_help(self) -> None:
        self.push_screen(HelpScreen(example_route(self.sim)))

    # ---- which keys are this operator's ----
    def check_action(self, action: str, parameters: tuple[object, ...]) -> bool | None:
        """The footer shows, and the keys run, only what this operator may do now (Textual asks this of every
        binding): the briefing while an exercise is on, and what :meth:`allowed` lets through."""
        if action == "briefing":
            return self.briefing() is not None
        return self.allowed(action)

    def allowed(self, action: str) -> bool:
        """Whether the operator at this console may run ``action`` (a local console's operator may run all)."""
        return True

    def palette_commands(self) -> list[PaletteCommand]:
        """The console's actions in the command palette now (tui/commands.py)."""
        return console_commands(self)


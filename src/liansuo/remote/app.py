"""The operator console on a seat of the classroom server (``liansuo tui --connect URL``).

It is the ordinary console (:class:`~tui.app.ConsoleApp`) over a :class:`~remote.sim.RemoteSimulation`: it draws the
seat's snapshots and sends every command to the server, which answers it. The server runs the clock, so the clock
keys become the instructor's clock messages and are refused to a trainee; F2 (the instructor's panel) is the
instructor's; while the connection is down the console shows the fail-safe picture and refuses commands.

The instructor's client opens on the dashboard of every seat (:mod:`remote.dashboard`); from it the instructor opens a
seat's diagram, where every command goes to that seat, and F3 goes back.
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path
from typing import Any, ClassVar

from rich.text import Text
from textual import events
from textual.binding import Binding, BindingType

from liansuo.classroom.roles import INSTRUCTOR
from liansuo.kit.printable import printable
from liansuo.remote.dashboard import DashboardScreen, ExerciseChoice, ExercisePicker, exercise_names
from liansuo.remote.link import ServerLink, Unlinked
from liansuo.remote.login import LoginScreen
from liansuo.remote.sim import ENDED, LOST, NOT_IN, RemoteSimulation
from liansuo.tui.app import SPEEDS, ConsoleApp
from liansuo.tui.briefing import Briefing
from liansuo.tui.panels import EventReader


class RemoteConsoleApp(ConsoleApp):
    LOCAL_CLOCK = False
    LOCAL_ROLES = False
    # the keys a trainee's seat leaves out of its footer and refuses: the classroom's clock, the instructor's panel
    # and the seats' dashboard are the instructor's
    INSTRUCTORS_KEYS = frozenset({"pause", "step", "speed", "instructor", "dashboard"})
    # ... but said why when pressed there
    REFUSED_KEYS: ClassVar[dict[str, str]] = {
        "space": "the clock is the classroom's: the instructor pauses and runs it",
        "full_stop": "the clock is the classroom's: the instructor pauses and runs it",
        "greater_than_sign": "the clock is the classroom's: the instructor sets its speed",
        "less_than_sign": "the clock is the classroom's: the instructor sets its speed",
        "f2": "F2, the instructor's panel, is on the instructor's console: a trainee's seat operates the station "
              "with the console's buttons",
        "f3": "the seats' dashboard is the instructor's",
    }
    BINDINGS: ClassVar[list[BindingType]] = [
        *ConsoleApp.BINDINGS,
        Binding("f3", "dashboard", "seats", key_display="F3"),
    ]

    def __init__(self, link: ServerLink | Unlinked, *, mute: bool = False) -> None:
        """On a seat through ``link``; or, :class:`Unlinked`, the login screen first over the station drawn dark."""
        self.link = link
        self.remote = RemoteSimulation(link)
        super().__init__(self.remote.station.id, sim=self.remote, mute=mute)
        self.instructor = link.role == INSTRUCTOR
        self.warm_up = False
        self._generation = link.generation
        self._was_live = True
        self._ended = False
        self._lesson: tuple[str, str] | None = None  # the exercise last shown (title, briefing)
        self._lesson_ended = False
        self._away: dict[int, SeatLog] = {}  # the log of each seat the instructor watched before, kept to show again

    @property
    def logged_in(self) -> bool:
        return isinstance(self.link, ServerLink)

    @property
    def seat(self) -> int:
        return self.remote.seat

    def started(self) -> None:
        self.remote.step()
        self.refresh_views()
        if not isinstance(self.link, ServerLink):
            self.push_screen(LoginScreen(self.link.url, self.link.lobby, self.link.tls), self.logged)
            return
        self.greet()

    def logged(self, link: ServerLink | None) -> None:
        """The login screen's link: the console now shows and operates that seat (or the instructor's)."""
        if link is None:
            self.exit()
            return
        self.link = link
        self.remote.attach(link)
        self.instructor = link.role == INSTRUCTOR
        self._generation, self._was_live, self._ended = link.generation, True, False
        self.remote.step()
        self.refresh_views()
        self.refresh_bindings()  # the footer: this role's keys
        self.greet()

    def greet(self) -> None:
        if self.instructor and isinstance(self.link, ServerLink):
            self.say(f"seat {self.seat}: every command goes to this seat; F3 the seats, F2 faults and trains")
            self.push_screen(DashboardScreen(self.link))
        else:
            self.say(f"seat {self.seat} of the classroom: click a signal's L or D button to start a route; ? help")

    def on_unmount(self) -> None:
        self.link.close()

    # ---- the clock: the server's ----
    def tick(self) -> None:
        self._ticks += 1
        try:
            self.remote.step()
            self.paused, self.speed = self.remote.paused, self.remote.speed
            live = self.link.connected
            if not self.logged_in:
                self.refresh_views()
                return
            if live != self._was_live or self._generation != self.link.generation:
                self._was_live, self._generation = live, self.link.generation
                self.say(f"{LOST}: the diagram shows nothing until it is back" if not live
                         else f"connection to the classroom server back: seat {self.seat}", live)
                self.log_panel.add(f"{self.remote.t:9.2f} {'link':8} {'lost' if not live else 'back'}",
                                   "#ff6060" if not live else "#80ff80")
            if self.link.ended and not self._ended:  # refused or sent away: the link dials no more
                self._ended = True
                self.say(printable(f"{ENDED}: {self.link.problem}"), False)
                self.log_panel.add(printable(f"{self.remote.t:9.2f} {'link':8} ended: {self.link.problem}"), "#ff6060")
            self.follow_lesson()
            self.refresh_views()
        except Exception as exc:  # no traceback on the screen
            incident = self.report_unexpected(exc, "the classroom link")
            self.say(f"internal error: {incident.summary} (see the alarms)", False)

    def allowed(self, action: str) -> bool:
        return self.instructor or action not in self.INSTRUCTORS_KEYS

    def on_key(self, event: events.Key) -> None:
        """An instructor's key pressed at a trainee's seat: not in the footer and not run, but said why."""
        if not self.instructor and event.key in self.REFUSED_KEYS:
            self.say(self.REFUSED_KEYS[event.key], False)

    def briefing(self) -> Briefing | None:
        """The seat's exercise as the server tells it: the briefing, each goal met or not, the time left or the
        score."""
        lesson = self.remote.lesson
        if lesson is None:
            return None
        goals = [(str(g["description"]), bool(g["met"])) for g in lesson["goals"]]
        return Briefing(str(lesson["title"]), str(lesson["briefing"]), goals, lesson_text(lesson))

    def follow_lesson(self) -> None:
        """An exercise started on the seat: its briefing and goals in a dialog (a trainee's seat shows it at once;
        ``e`` shows it again) and in the log; ended: how, and the score."""
        if not self.remote.live:  # the fail-safe picture tells no exercise: the seat's is told as it was
            return
        lesson = self.remote.lesson
        key = None if lesson is None else (lesson["title"], lesson["briefing"])
        if key != self._lesson:
            self._lesson, self._lesson_ended = key, False
            self.refresh_bindings()  # the footer's 'e briefing'
            if lesson is not None:
                self.log_panel.add(printable(f"{self.remote.t:9.2f} {'lesson':8} {lesson['title']}: "
                                             f"{' '.join(str(lesson['briefing']).split())}"), "#d0a0ff")
                for g in lesson["goals"]:
                    self.log_panel.add(printable(f"{'':9} {'goal':8} {g['description']}"), "#d0a0ff")
                self.say(f"exercise: {lesson['title']} (e shows the briefing and the goals again)", True)
                if not self.instructor:
                    self.show_briefing()
        if lesson is not None and lesson["finished"] and not self._lesson_ended:
            self._lesson_ended = True
            self.log_panel.add(printable(f"{self.remote.t:9.2f} {'lesson':8} {lesson_text(lesson)}"),
                               "bold #40e070")

    def _clock(self, **what: Any) -> None:
        if not self.instructor:
            self.say("the clock is the classroom's: the instructor pauses and runs it", False)
            return
        reply = self.link.request({"type": "clock", "seats": [self.seat], **what})
        self.say(str(reply.get("message", reply)), reply.get("type") == "ok")

    def action_pause(self) -> None:
        self._clock(action="run" if self.remote.paused else "pause")

    def action_step(self) -> None:
        self.say("the classroom's clock does not step: pause and run it (space)", False)

    def action_speed(self, step: int) -> None:
        i = min(range(len(SPEEDS)), key=lambda k: abs(SPEEDS[k] - self.remote.speed))
        self._clock(speed=SPEEDS[max(0, min(len(SPEEDS) - 1, i + step))])

    # ---- the instructor's ----
    async def action_instructor(self) -> None:
        if not self.instructor:
            self.say("F2, the instructor's panel, is on the instructor's console: a trainee's seat operates the "
                     "station with the console's buttons", False)
            return
        panel = self.instructor_panel
        if panel is None:
            await self.set_instructor(True)
        else:
            panel.set_class(not panel.has_class("-shown"), "-shown")

    def instructor_hint(self) -> str:
        return ""

    def action_dashboard(self) -> None:
        if not self.instructor or not isinstance(self.link, ServerLink):
            self.say("the seats' dashboard is the instructor's", False)
            return
        if not isinstance(self.screen, DashboardScreen):
            self.push_screen(DashboardScreen(self.link))

    def on_dashboard_screen_open(self, event: DashboardScreen.Open) -> None:
        """The dashboard opens a seat: watch it, and show its own log (kept from when it was watched before)."""
        was = self.seat
        reply = self.link.watch(event.seat)
        if reply.get("type") != "ok":
            self.say(str(reply.get("message", reply)), False)
            return
        if event.seat != was:
            self._away[was] = SeatLog(self.log_panel.entries(), self.events, self._lesson, self._lesson_ended)
            back = self._away.pop(event.seat, None)
            if back is None:
                back = SeatLog([(f"{'':9} {'seat':8} seat {event.seat}", "bold #d0a0ff")], EventReader(), None, False)
            self.log_panel.show(back.lines)
            self.events, self._lesson, self._lesson_ended = back.reader, back.lesson, back.lesson_ended
            self.acknowledged.clear()
        self.remote.step()
        self.refresh_views()
        self.say(f"seat {event.seat}: every command goes to this seat; F3 the seats", True)

    def _exercise_files(self) -> list[Path]:
        """The panel's exercises: those the server may start (its station's), by name."""
        return [Path(n) for n in exercise_names(self.link)] if isinstance(self.link, ServerLink) else []

    def load_chosen_exercise(self, path: str) -> None:
        """The instructor chose an exercise (the panel's Load, the palette): the server starts it on this seat, with
        the difficulty and the seed the instructor picks (the local console's loading into its own simulation is not
        for a remote seat)."""
        name = Path(path).stem
        self.push_screen(ExercisePicker([name], f"seat {self.seat}"), self._exercise_chosen)

    def _exercise_chosen(self, choice: ExerciseChoice | None) -> None:
        if choice is None:
            return
        reply = self.link.request(choice.message([self.seat]))
        self.say(str(reply.get("message", reply)), reply.get("type") == "ok")

    def more_status(self, out: Text) -> None:
        out.append(f"│ seat {self.seat} ", style="bold")
        lesson = self.remote.lesson
        if lesson is not None:
            done = bool(lesson["finished"])
            out.append(printable(f"│ {lesson_text(lesson)} "), style="bold #40e070" if done else "#ffd700")
        if not self.logged_in:
            out.append(f"│ {NOT_IN} ", style="bold #ffffff on #c00000")
        elif not self.link.connected:
            out.append(f"│ {ENDED if self.link.ended else LOST} ", style="bold #ffffff on #c00000")


@dataclass
class SeatLog:
    """A seat's event log while the instructor watches another: its lines, where its events were read to, and the
    exercise it last told."""

    lines: list[tuple[str, str]]
    reader: EventReader
    lesson: tuple[str, str] | None
    lesson_ended: bool


def lesson_text(lesson: dict[str, Any]) -> str:
    """An exercise as the status line says it: 'Cancel a wrong route: 1/2 goals, 03:12 left' or, ended, how and
    the score."""
    met = sum(bool(g["met"]) for g in lesson["goals"])
    if lesson["finished"]:
        return f"{lesson['title']}: {lesson['ended']}, {met}/{len(lesson['goals'])} goals, score {lesson['score']}"
    left = float(lesson["time_left_s"])
    return f"{lesson['title']}: {met}/{len(lesson['goals'])} goals, {int(left // 60):02d}:{int(left % 60):02d} left"

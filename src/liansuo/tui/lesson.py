"""The console's lesson controls: instructor mode (F2, with its password) and the exercise loaded into the
simulation, its goals checked as the clock runs (a mixin of :class:`~.app.ConsoleApp`)."""

from __future__ import annotations

import random
from pathlib import Path
from typing import TYPE_CHECKING, Any

from rich.text import Text

from liansuo.classroom.exercise import Exercise, GoalCheck, bundled_exercises, check_goal, exercises_for, parse_exercise
from liansuo.classroom.passwords import matches
from liansuo.kit.printable import printable
from liansuo.kit.source import StationError
from liansuo.simulation.recording.recorder import FileRecorder
from liansuo.simulation.sim import Simulation
from liansuo.tui.briefing import Briefing, BriefingScreen
from liansuo.tui.consolesim import ConsoleSim
from liansuo.tui.dialogs import PasswordScreen
from liansuo.tui.instructor import InstructorPanel
from liansuo.tui.panels import EventLog

if TYPE_CHECKING:
    from liansuo.simulation import Result


class LessonControls:
    """Instructor mode and the exercise, for the console that holds the simulation and its panels."""

    sim: ConsoleSim
    station_ref: str
    password: str | None
    instructor: bool
    instructor_panel: InstructorPanel | None
    recorder: FileRecorder | None
    exercise: Exercise | None
    goal: GoalCheck | None
    goal_reached_at: float | None
    goals_met: set[int]
    log_panel: EventLog
    _exercise_arg: str | Path | None

    if TYPE_CHECKING:  # what the console (a Textual app) gives
        screen_stack: Any

        def say(self, text: str, ok: bool | None = None) -> None: ...
        def send(self, line: str, source: str = "trainee") -> Result: ...
        def stop_run(self) -> None: ...
        def refresh_views(self) -> None: ...
        def push_screen(self, screen: Any, callback: Any = None) -> Any: ...
        def refresh_bindings(self) -> None: ...

    def exercise_files(self) -> list[Path]:
        """The exercises the instructor may load: the bundled ones, and the one the console was started with."""
        return self._exercise_files()

    def _exercise_files(self) -> list[Path]:
        """The panel's exercises: the bundled ones for this console's station, and the one it was started with."""
        files = exercises_for(self.sim.station.id, bundled_exercises())
        if self._exercise_arg is not None and Path(self._exercise_arg) not in files:
            files.append(Path(self._exercise_arg))
        return files

    async def action_instructor(self) -> None:
        if self.instructor:
            await self.set_instructor(False)
        elif self.password:
            self.push_screen(PasswordScreen(), self._password_given)
        else:
            await self.set_instructor(True)

    async def _password_given(self, given: str | None) -> None:
        if given and self.password and matches(given, self.password):
            await self.set_instructor(True)
        elif given:
            self.say("wrong instructor password", False)
        else:
            self.say("instructor mode not opened")

    async def set_instructor(self, on: bool) -> None:
        if on and self.instructor_panel is None:
            main = self.screen_stack[0].query_one("#main")
            if not main.is_attached:
                return  # the console is closing (quit answered yes, F2 typed before it closed): nothing to open
            self.instructor_panel = InstructorPanel(lambda: self.sim, self._exercise_files(), id="instructor")
            await main.mount(self.instructor_panel)
            if self.recorder is not None:
                self.instructor_panel.show_recording(f"recording to {self.recorder.path}")
            self._show_goal()
        self.instructor = on
        if self.instructor_panel is not None:
            self.instructor_panel.set_class(on, "-shown")
        self.say("instructor mode: faults, trains and exercises in the panel on the right (F2 closes it)" if on
                 else "trainee mode")
        self.refresh_bindings()
        self.refresh_views()

    def on_instructor_panel_send(self, event: InstructorPanel.Send) -> None:
        self.send(event.line, "instructor")

    def on_instructor_panel_load_exercise(self, event: InstructorPanel.LoadExercise) -> None:
        self.load_chosen_exercise(event.path)

    def load_chosen_exercise(self, path: str) -> None:
        """The instructor chose an exercise (the panel's Load, the palette): this console loads it."""
        self.load_exercise(path)

    def load_exercise(self, path: str) -> None:
        self.stop_run()
        if not isinstance(self.sim, Simulation):
            self.say("an exercise runs on the simulation's own computer: start it from there", False)
            return
        try:
            ex = parse_exercise(path)
        except StationError as exc:
            self.say(f"exercise not loaded: {exc.diagnostics[0] if exc.diagnostics else exc}", False)
            return
        except OSError as exc:
            self.say(f"exercise not loaded: {exc}", False)
            return
        if ex.station_ref() not in (self.station_ref, self.sim.station.id):
            self.say(f"exercise '{ex.title}' is for station {ex.station}; start the console with "
                     f"'liansuo tui {ex.station} --exercise {path}'", False)
            return
        self.exercise = ex
        self.goal_reached_at = None
        self.goals_met = set()
        seed = random.randrange(1_000_000)  # the pool's draw; the log names it so a lesson can be given again
        self.log_panel.add(f"{self.sim.t:9.2f} {'lesson':8} {ex.title}: {ex.briefing} (seed {seed})", "#d0a0ff")
        for line in ex.lines(seed):
            self.send(line, "exercise")
        self.say(f"exercise: {ex.title} (e shows the briefing and the goals again)")
        self.check_exercise()
        self.refresh_bindings()  # the footer's 'e briefing'
        self.show_briefing()

    def check_exercise(self) -> None:
        ex = self.exercise
        if ex is None or not isinstance(self.sim, Simulation):
            return
        self.goal = check_goal(self.sim, ex, self.goals_met)
        if self.goal.reached and self.goal_reached_at is None:
            self.goal_reached_at = self.sim.t
            self.log_panel.add(f"{self.sim.t:9.2f} {'lesson':8} goal reached: {ex.goal}", "bold #40e070")
            self.say(f"goal reached: {ex.goal}", True)
        self._show_goal()

    def briefing(self) -> Briefing | None:
        """The exercise's briefing and its goals as they stand (None: no exercise)."""
        ex = self.exercise
        if ex is None:
            return None
        goals = [(g.description, i in self.goals_met) for i, g in enumerate(ex.goals)]
        return Briefing(ex.title, ex.briefing, goals, "goal reached" if self.goal_reached_at is not None else "")

    def show_briefing(self) -> None:
        briefing = self.briefing()
        if briefing is not None and not isinstance(self.screen_stack[-1], BriefingScreen):
            self.push_screen(BriefingScreen(briefing))

    def action_briefing(self) -> None:
        """``e``: the briefing and the goals again."""
        if self.briefing() is None:
            self.say("no exercise has started on this console")
            return
        self.show_briefing()

    def _show_goal(self) -> None:
        ex, goal = self.exercise, self.goal
        if ex is None or goal is None or self.instructor_panel is None:
            return
        lines = "\n".join(f"{'✓' if ok else '·'} {line.removeprefix('expect ')}" for line, ok, _ in goal.lines)
        self.instructor_panel.show_goal(f"{ex.title}\n{ex.goal}\n{lines}")

    def lesson_status(self, out: Text) -> None:
        """The status line's right end: who operates, the exercise and how far it has got, the recording."""
        out.append("│ 教员 INSTRUCTOR " if self.instructor else "│ trainee ", style="#d0a0ff" if self.instructor
                   else "")
        if self.exercise is not None:
            done = self.goal_reached_at is not None
            out.append(printable(f"│ {self.exercise.title}: {'goal reached' if done else 'in progress'} "),
                       style="bold #40e070" if done else "#ffd700")
        if self.recorder is not None:
            out.append("│ ● REC ", style="#ff5050")

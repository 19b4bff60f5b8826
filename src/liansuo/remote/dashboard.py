"""The instructor's dashboard (教员台): every seat of the classroom in a table, refreshed from the server's ``seats``
messages, and the instructor's controls of them.

Enter opens the selected seat's diagram (live: the server sends its snapshots); ``p`` / ``r`` pause and run the
selected seat's clock, ``x`` resets it, ``e`` starts an exercise on it and ``s`` stops it (writing its report); the
same keys shifted act on every seat; ``f`` frees the selected seat for another trainee (its token cleared). Every
answer of the server, a refusal included, shows on the dashboard's answer line.
"""

from __future__ import annotations

import random
from dataclasses import dataclass
from typing import Any, ClassVar

from rich.text import Text
from textual.app import ComposeResult
from textual.binding import Binding, BindingType
from textual.containers import Horizontal, Vertical
from textual.message import Message
from textual.screen import ModalScreen, Screen
from textual.widgets import Button, DataTable, Footer, Label, OptionList, Select, Static

from liansuo.kit.printable import printable
from liansuo.remote.link import ServerLink
from liansuo.tui.panels import clock_text

COLUMNS = ("seat", "trainee", "connected", "station", "t", "clock", "exercise", "progress", "score", "alarms",
           "refused")
REFRESH_S = 0.5


def seat_row(s: dict[str, Any]) -> tuple[str, ...]:
    """One seat's summary as the dashboard's row shows it."""
    progress = s.get("progress") or {}
    if progress:
        left = progress.get("time_left_s")
        met = f"{progress.get('goals_met', 0)}/{progress.get('goals', 0)} goals"
        if progress.get("finished"):
            shown = f"{met}, ended: {progress.get('ended', '')}"
        else:
            shown = met + (f", {clock_text(float(left))} left" if left is not None else "")
    else:
        shown = ""
    score = s.get("score")
    clock = "stopped: error" if s.get("broken") else "paused" if s.get("paused") else f"{float(s.get('speed', 1.0)):g}x"
    return (str(s.get("seat", "")), printable(str(s.get("trainee") or "")), "yes" if s.get("connected") else "no",
            printable(str(s.get("station", ""))), clock_text(float(s.get("t", 0.0))),
            clock,
            printable(str(s.get("exercise") or "")), shown, "" if score is None else f"{score}",
            str(s.get("alarms", 0)), str(s.get("refused", 0)))


@dataclass(frozen=True)
class ExerciseChoice:
    name: str
    difficulty: int

    def message(self, seats: list[int] | str) -> dict[str, Any]:
        return {"type": "exercise", "seats": seats, "name": self.name, "difficulty": self.difficulty,
                "seed": random.randrange(2**31)}


def exercise_names(link: ServerLink) -> list[str]:
    """The exercises the server may start: those for its station, bundled or from its ``--exercise-dir`` (the
    instructor's welcome lists them)."""
    return [str(n) for n in link.welcome.get("exercises", [])]


class ExercisePicker(ModalScreen[ExerciseChoice | None]):
    """Which exercise, how hard: Enter on an exercise starts it; Esc starts nothing."""

    DEFAULT_CSS = """
    ExercisePicker { align: center middle; }
    ExercisePicker > Vertical { width: 70; height: auto; max-height: 90%; border: round #d0a0ff; background: #15181c;
                                padding: 0 1; }
    ExercisePicker OptionList { height: auto; max-height: 16; }
    ExercisePicker Select { width: 30; }
    """
    BINDINGS: ClassVar[list[BindingType]] = [Binding("escape", "cancel", "cancel")]

    def __init__(self, names: list[str], where: str) -> None:
        super().__init__()
        self.names = names
        self.where = where

    def compose(self) -> ComposeResult:
        with Vertical():
            yield Label(f"练习 Start an exercise on {self.where} (Enter starts it, Esc cancels)")
            yield Select([(f"difficulty {n}", n) for n in (1, 2, 3)], value=1, allow_blank=False, id="difficulty")
            yield OptionList(*self.names, id="exercises")

    def on_mount(self) -> None:
        self.query_one(OptionList).focus()

    def on_option_list_option_selected(self, event: OptionList.OptionSelected) -> None:
        difficulty = self.query_one(Select).value
        self.dismiss(ExerciseChoice(self.names[event.option_index], int(difficulty)
                                    if isinstance(difficulty, int) else 1))

    def action_cancel(self) -> None:
        self.dismiss(None)


class DashboardScreen(Screen[None]):
    """Every seat of the classroom (see the module's docstring)."""

    DEFAULT_CSS = """
    DashboardScreen { background: #0c0f12; }
    DashboardScreen #title { height: 1; background: #3a2a57; color: #f1faee; }
    DashboardScreen DataTable { height: 1fr; }
    DashboardScreen #answer { height: 1; }
    DashboardScreen #buttons { height: 3; }
    DashboardScreen Button { min-width: 10; margin: 0 1 0 0; }
    """
    BINDINGS: ClassVar[list[BindingType]] = [
        Binding("enter", "open", "open seat", priority=True),
        Binding("p", "clock('pause', False)", "pause"),
        Binding("r", "clock('run', False)", "run"),
        Binding("x", "reset(False)", "reset"),
        Binding("e", "exercise(False)", "exercise"),
        Binding("s", "stop(False)", "stop"),
        Binding("f", "free", "free seat"),
        Binding("P", "clock('pause', True)", "pause all"),
        Binding("R", "clock('run', True)", "run all"),
        Binding("X", "reset(True)", "reset all", show=False),
        Binding("E", "exercise(True)", "exercise all", show=False),
        Binding("S", "stop(True)", "stop all", show=False),
        Binding("escape,f3", "back", "diagram"),
    ]

    class Open(Message):
        """The instructor opens a seat's diagram."""

        def __init__(self, seat: int) -> None:
            super().__init__()
            self.seat = seat

    def __init__(self, link: ServerLink) -> None:
        super().__init__()
        self.link = link
        self._shown: list[tuple[str, ...]] = []

    def compose(self) -> ComposeResult:
        yield Static(Text(" 教员台 Classroom: every seat (Enter opens its diagram; shift acts on all seats)",
                          style="bold"), id="title")
        yield DataTable(id="seats", cursor_type="row", zebra_stripes=True)
        with Horizontal(id="buttons"):
            for bid, label in (("open", "Open"), ("pause", "Pause"), ("run", "Run"), ("reset", "Reset"),
                               ("exercise", "Exercise"), ("stop", "Stop"), ("free", "Free"), ("pause-all", "Pause all"),
                               ("run-all", "Run all"), ("back", "Diagram")):
                yield Button(label, id=f"b-{bid}", compact=True)
        yield Static(id="answer")
        yield Footer()

    def on_mount(self) -> None:
        table = self.query_one(DataTable)
        table.add_columns(*COLUMNS)
        self.refresh_seats()
        table.focus()
        self.set_interval(REFRESH_S, self.refresh_seats)

    # ---- the table ----
    def refresh_seats(self) -> None:
        rows = [seat_row(s) for s in self.link.seats()]
        if not self.link.connected:
            state = f"ended ({self.link.problem})" if self.link.ended else "lost, reconnecting"
            self.say(f"connection to the classroom server {state}: the table is not live", False)
        if rows == self._shown:
            return
        table = self.query_one(DataTable)
        # the seat selected stays selected; at first, the seat whose diagram the instructor watches
        row = table.cursor_row if self._shown else next((i for i, r in enumerate(rows) if r[0] == str(self.link.seat)),
                                                        0)
        table.clear()
        for r in rows:
            table.add_row(*r, key=r[0])
        self._shown = rows
        if rows:
            table.move_cursor(row=min(max(row, 0), len(rows) - 1))

    def selected(self) -> int | None:
        table = self.query_one(DataTable)
        if not self._shown or table.cursor_row < 0 or table.cursor_row >= len(self._shown):
            return None
        return int(self._shown[table.cursor_row][0])

    def say(self, text: str, ok: bool | None = None) -> None:
        style = "#e0e0e0" if ok is None else "bold #40e070" if ok else "bold #ff5050"
        mark = "" if ok is None else "✓ " if ok else "✗ "
        self.query_one("#answer", Static).update(Text(mark + printable(text), style=style, no_wrap=True,
                                                      overflow="ellipsis"))

    # ---- the controls ----
    def _seats(self, every: bool) -> list[int] | str | None:
        if every:
            return "all"
        seat = self.selected()
        if seat is None:
            self.say("no seat yet: the server sends the seats once a second", False)
        return None if seat is None else [seat]

    def _send(self, message: dict[str, Any]) -> None:
        reply = self.link.request(message)
        self.say(str(reply.get("message", reply)), reply.get("type") == "ok")

    def action_open(self) -> None:
        seat = self.selected()
        if seat is None:
            self.say("no seat yet: the server sends the seats once a second", False)
            return
        self.app.pop_screen()
        self.app.post_message(self.Open(seat))

    def action_back(self) -> None:
        self.app.pop_screen()

    def action_clock(self, action: str, every: bool) -> None:
        if (seats := self._seats(every)) is not None:
            self._send({"type": "clock", "seats": seats, "action": action})

    def action_reset(self, every: bool) -> None:
        if (seats := self._seats(every)) is not None:
            self._send({"type": "reset", "seats": seats})

    def action_stop(self, every: bool) -> None:
        if (seats := self._seats(every)) is not None:
            self._send({"type": "stop", "seats": seats})

    def action_free(self) -> None:
        if (seats := self._seats(False)) is not None:
            self._send({"type": "free", "seats": seats})

    def action_exercise(self, every: bool) -> None:
        seats = self._seats(every)
        if seats is None:
            return
        station = str(self.link.welcome.get("station", {}).get("name", ""))
        where = "every seat" if seats == "all" else f"seat {seats[0]}"
        names = exercise_names(self.link)
        if not names:
            self.say(f"this server has no exercise for {station}: give it some with 'liansuo serve --exercise-dir "
                     "DIR'", False)
            return

        def chosen(choice: ExerciseChoice | None) -> None:
            if choice is not None:
                self._send(choice.message(seats))

        self.app.push_screen(ExercisePicker(names, where), chosen)

    def on_button_pressed(self, event: Button.Pressed) -> None:
        action = (event.button.id or "").removeprefix("b-")
        {"open": self.action_open, "pause": lambda: self.action_clock("pause", False),
         "run": lambda: self.action_clock("run", False), "reset": lambda: self.action_reset(False),
         "exercise": lambda: self.action_exercise(False), "stop": lambda: self.action_stop(False),
         "free": self.action_free, "pause-all": lambda: self.action_clock("pause", True),
         "run-all": lambda: self.action_clock("run", True), "back": self.action_back}.get(action, lambda: None)()




"""The console's side of field mode (docs/field-mode.md): the sealed change-over button QHA, which asks for its
password before the command goes to the simulation, and the control mode on the status line (a mixin of
:class:`~.app.ConsoleApp`)."""

from __future__ import annotations

from typing import TYPE_CHECKING, Any

from rich.text import Text

from liansuo.classroom.passwords import matches
from liansuo.classroom.roles import command_word
from liansuo.simulation.fieldlink import FieldControl
from liansuo.tui.consolesim import ConsoleSim
from liansuo.tui.dialogs import PasswordScreen
from liansuo.tui.panels import EventLog

if TYPE_CHECKING:
    from liansuo.simulation import Result


class FieldModeControls:
    """QHA's password and the control mode, for the console that holds the simulation."""

    sim: ConsoleSim
    changeover_hash: str | None
    log_panel: EventLog

    if TYPE_CHECKING:  # what the console (a Textual app) gives
        def say(self, text: str, ok: bool | None = None) -> None: ...
        def carry_out_line(self, line: str, source: str) -> Result: ...
        def push_screen(self, screen: Any, callback: Any = None) -> Any: ...

    def asks_password(self, line: str, source: str) -> bool:
        """A change-over from a person at this console: ask QHA's password first, then send it (True: asked)."""
        if command_word(line) != "changeover" or not self.changeover_hash or source not in ("trainee", "instructor"):
            return False
        self.push_screen(PasswordScreen("QHA 切换 change-over: password"),
                         lambda given: self._changeover_password(line, source, given))
        return True

    def _changeover_password(self, line: str, source: str, given: str | None) -> None:
        if given and self.changeover_hash and matches(given, self.changeover_hash):
            self.carry_out_line(line, source)
            return
        why = "wrong change-over password: QHA not operated"
        self.log_panel.add(f"{self.sim.t:9.2f} {'refused':8} {line}: {why}", "#ff8080")
        self.say(why, False)

    def control_status(self, out: Text) -> None:
        """The control mode, where a field link is attached: simulated (green), field (amber), link lost (red)."""
        control = getattr(self.sim, "control", None)
        if isinstance(control, FieldControl):
            style = "bold #ff4040" if control.lost else "bold #ffa040" if control.up else "bold #80ff80"
            out.append(f"│ {control.mode} ", style=style)

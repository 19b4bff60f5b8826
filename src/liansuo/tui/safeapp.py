"""The shell that keeps a console up whatever it is sent: the app under the operator console and the replay.

- An error that escapes one of the console's handlers (:mod:`tui.guard`) becomes an incident (:mod:`tui.incidents`),
  shown by the console (:meth:`SafeApp.show_incident`); the console carries on.
- An error Textual cannot recover from ends the console as a crash: the same report, exit status 1.
- A dialog answered twice in one burst of input cannot close the console's own screen; the command palette
  (:mod:`tui.palette`) is closed as safely.
- Every way out asks first: ctrl+q, the command palette's Quit, ``quit`` in the command bar.
- A terminal that goes away ends the console. Closing a terminal window hangs up its terminal; a console started
  under ``make run`` gets no hangup signal (make does), and would go on reading a dead terminal forever, a core busy.
  So the console looks every second whether its terminal is still there, and ends without asking when it is not.
"""

from __future__ import annotations

import os
import sys

from textual.app import App
from textual.await_complete import AwaitComplete
from textual.command import CommandPalette
from textual.screen import Screen
from textual.theme import ThemeProvider

from liansuo.tui.dialogs import QuitScreen
from liansuo.tui.guard import Guarded
from liansuo.tui.incidents import Incident, Incidents
from liansuo.tui.palette import ConsolePalette


class ConsoleScreen(Guarded, Screen[None]):
    """The console's main screen: an error in its handlers is reported, not fatal."""


HANGUP_CHECK_S = 1.0  # how often a console in a terminal looks whether its terminal is still there


class SafeApp(Guarded, App[None]):
    def __init__(self) -> None:
        super().__init__()
        self.incidents = Incidents()

    def on_mount(self) -> None:
        fd = self._terminal()
        if fd is not None:
            self.set_interval(HANGUP_CHECK_S, lambda: self._terminal_gone(fd))

    def _terminal(self) -> int | None:
        """The console's terminal, when it runs in one (not served to a browser, not under test)."""
        if self.is_web or self.is_headless:
            return None
        for stream in (sys.__stdin__, sys.__stdout__):
            try:
                if stream is not None and os.isatty(stream.fileno()):
                    return stream.fileno()
            except (OSError, ValueError):
                continue
        return None

    def _terminal_gone(self, fd: int) -> None:
        if not os.isatty(fd):  # hung up: nobody can read the console or answer it any more
            self.exit()

    # ---- what the console fills in ----
    def sim_time(self) -> float | None:
        """The simulated time an incident is stamped with."""
        return None

    def show_incident(self, incident: Incident, where: str) -> None:
        """Show a new incident to the operator (the answer line, the alarm panel)."""

    def quit_question(self) -> str:
        return "Quit?"

    def quit_declined(self) -> None:
        """The operator answered no."""

    # ---- errors ----
    def get_default_screen(self) -> Screen[None]:
        return ConsoleScreen(id="_default")

    def report_unexpected(self, error: BaseException, where: str) -> Incident:
        """An error escaped a handler (:mod:`tui.guard`): keep it for the report and show it."""
        incident = self.incidents.record(error, where, self._time())
        try:
            self.show_incident(incident, where)
        except Exception as again:  # showing it failed as well: the report after exit has both
            self.incidents.record(again, "showing an internal error", self._time())
        return incident

    def _time(self) -> float | None:
        try:
            return self.sim_time()
        except Exception:  # not built yet: the incident has no simulated time
            return None

    def _handle_exception(self, error: Exception) -> None:
        """Textual's last resort, for an error outside any guarded handler: the console ends as a crash, with the
        incident report and exit status 1 (``liansuo tui`` prints it), never quietly."""
        self.incidents.record(error, "the console's event loop", self._time())
        self.incidents.crashed = True
        super()._handle_exception(error)

    def _fatal_error(self) -> None:
        # Textual would print its own traceback with every local variable in it; the incident report has the
        # traceback, printed by the command after the terminal is restored
        self.bell()
        self._close_messages_no_wait()

    def pop_screen(self) -> AwaitComplete:
        """Two clicks outside the command palette in one burst close it twice; with only the console's own screen
        left, the second has nothing to close (Textual would raise ScreenStackError)."""
        if len(self.screen_stack) <= 1:
            return AwaitComplete()  # awaits nothing
        return super().pop_screen()

    # ---- the command palette: the console's own, for commands and for themes ----
    def action_command_palette(self) -> None:
        if self.use_command_palette and not any(isinstance(s, CommandPalette) for s in self.screen_stack):
            self.push_screen(ConsolePalette(id="--command-palette"))

    def search_themes(self) -> None:
        self.push_screen(ConsolePalette(providers=[ThemeProvider], placeholder="Search for themes…"))

    def deliver_screenshot(self, filename: str | None = None, path: str | None = None,
                           time_format: str | None = None) -> str | None:
        """The palette's Screenshot is taken 0.1 s after it is chosen: if the console has closed meanwhile, there is
        no screen left to take (Textual would raise ScreenStackError while closing)."""
        if not self.screen_stack:
            return None
        return super().deliver_screenshot(filename, path, time_format)

    # ---- the way out ----
    async def action_quit(self) -> None:
        """ctrl+q, the palette's Quit and ``quit`` all come here: ask, once."""
        if any(isinstance(s, QuitScreen) for s in self.screen_stack):
            return
        self.push_screen(QuitScreen(self.quit_question()), self._quit_answered)

    def _quit_answered(self, yes: bool | None) -> None:
        if yes:
            self.exit()
        else:
            self.quit_declined()

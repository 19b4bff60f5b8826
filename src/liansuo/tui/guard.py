"""The console's message pumps carry on after an error nobody expected (its record: :mod:`tui.incidents`).

Textual runs every widget, screen and the app as a message pump; an exception that escapes a handler ends that
pump's loop and takes the whole app down with a traceback. The console's own pumps (the app, its screens and its
widgets) are :class:`Guarded`: an exception from one of their handlers becomes an incident
(:class:`~tui.incidents.Incident`), shown at once in the alarm panel and on the answer line, and the pump goes on with
the next message. When the console closes, ``liansuo tui`` prints every incident's traceback on stderr and exits with
status 1 (docs/console.md, "When something goes wrong"). An error Textual itself cannot recover from (one outside any
handler, such as a layout failure) still ends the console, with the same report and the same status, never with exit
status 0 (:mod:`tui.safeapp`).
"""

from __future__ import annotations

from collections.abc import Callable
from typing import Any

from textual import events
from textual.app import App
from textual.message import Message
from textual.message_pump import MessagePump
from textual.screen import Screen

Reporter = Callable[[BaseException, str], None]


class Guarded(MessagePump):
    """A message pump whose handlers' exceptions are reported by the app and do not end the pump.

    The app names its reporter ``report_unexpected(error, where)``; an app without one (a test mounting a widget
    alone) gets Textual's behaviour. The app's own Compose and Mount are not guarded: a console that cannot start
    stops, and says why.
    """

    async def _dispatch_message(self, message: Message) -> None:
        try:
            await super()._dispatch_message(message)
        except Exception as error:
            app = self.app
            report: Reporter | None = getattr(app, "report_unexpected", None)
            if report is None or (isinstance(self, App) and isinstance(message, (events.Compose, events.Mount))):
                raise
            report(error, f"{type(self).__name__}.{message.handler_name}")


def on_top(screen: Screen[Any]) -> bool:
    """Whether ``screen`` is the one on top, the only one that may close itself: an answer that comes late (a double
    click, a dialog opened over it) would otherwise close the screen above it, or the console's own."""
    return screen.is_attached and screen.app.screen is screen

"""The command palette (ctrl+p) as the console opens it: Textual's, closed safely.

Textual's palette starts a search for every change of its input; a change still queued when the palette closes (a
word typed and Enter pressed in one burst of input) starts a search in a palette that has lost its list, and the
failed search ends the whole app. Here a search starts only while the palette is open. The palette closes itself only
while it is on top: a dialog opened over it (F2, ctrl+q) is not closed in its place. Errors in its handlers are
reported like any other console handler's (:mod:`tui.guard`).
"""

from __future__ import annotations

from collections.abc import Callable, Coroutine
from typing import Any, cast

from textual import work
from textual.await_complete import AwaitComplete
from textual.command import CommandPalette

from liansuo.tui.guard import Guarded, on_top

_SEARCH: Callable[[CommandPalette, str], Coroutine[Any, Any, None]] = cast(
    "Callable[[CommandPalette, str], Coroutine[Any, Any, None]]",
    getattr(CommandPalette._gather_commands, "__wrapped__"),  # noqa: B009  (the search itself, not its worker)
)


class ConsolePalette(Guarded, CommandPalette):
    @work(exclusive=True, group=CommandPalette._GATHER_COMMANDS_GROUP)
    async def _gather_commands(self, search_value: str) -> None:
        if not on_top(self):
            return  # closed before its search began: nothing to show it in
        await _SEARCH(self, search_value)

    def dismiss(self, result: None = None) -> AwaitComplete:
        if not on_top(self):
            return AwaitComplete()
        return super().dismiss(result)

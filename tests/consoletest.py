"""What the console tests share: the terminal size they drive the console at, async test bodies run without a
plugin, and the screen, the footer and the answer line as the operator reads them."""

from __future__ import annotations

import asyncio
import functools
import io
from collections.abc import Awaitable, Callable
from typing import Any

SIZE = (120, 36)  # columns and lines of the terminal the console is driven in


def run(test: Callable[..., Awaitable[None]]) -> Callable[..., None]:
    """Run an async test body (no pytest-asyncio needed)."""

    @functools.wraps(test)
    def wrapper(*args: Any, **kwargs: Any) -> None:
        asyncio.run(test(*args, **kwargs))

    return wrapper


def screen_lines(app: Any) -> list[str]:
    """The screen as the terminal shows it, dialogs over the screens below them (as App.export_screenshot renders
    it), one string per line."""
    from rich.console import Console

    width, height = app.size
    console = Console(width=width, height=height, file=io.StringIO(), record=True, color_system=None,
                      legacy_windows=False)
    console.print(app.screen._compositor.render_update(full=True, screen_stack=app._background_screens))
    return str(console.export_text()).split("\n")[:height]


def footer(app: Any) -> str:
    """The footer's line: the keys it offers."""
    return screen_lines(app)[-1]


def message(app: Any) -> str:
    """The answer line: what the console said to the last command or click."""
    return str(app.message_line.content)

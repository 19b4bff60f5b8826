"""What the console tests share: the terminal size they drive the console at, async test bodies run without a
plugin, and the answer line as the operator reads it."""

from __future__ import annotations

import asyncio
import functools
from collections.abc import Awaitable, Callable
from typing import Any

SIZE = (120, 36)  # columns and lines of the terminal the console is driven in


def run(test: Callable[..., Awaitable[None]]) -> Callable[..., None]:
    """Run an async test body (no pytest-asyncio needed)."""

    @functools.wraps(test)
    def wrapper(*args: Any, **kwargs: Any) -> None:
        asyncio.run(test(*args, **kwargs))

    return wrapper


def message(app: Any) -> str:
    """The answer line: what the console said to the last command or click."""
    return str(app.message_line.content)

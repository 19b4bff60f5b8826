"""Progress of a long run (verify, soak, bench) on stderr: a bar with the work done and the time left when stderr is
a terminal, nothing otherwise (a pipe, a file, CI), so reports on stdout stay clean.

``with progress("verify hub200", total) as advance: ... advance(n)``; the bar is rich's.
"""

from __future__ import annotations

import sys
from collections.abc import Callable, Iterator
from contextlib import contextmanager

Advance = Callable[[int], None]


def _nothing(n: int) -> None:
    return None


@contextmanager
def progress(what: str, total: int, *, show: bool | None = None) -> Iterator[Advance]:
    """A bar for ``total`` units of ``what``; ``show`` None: only when stderr is a terminal."""
    if show is None:
        show = sys.stderr.isatty()
    if not show or total <= 0:
        yield _nothing
        return
    from rich.console import Console
    from rich.progress import (
        BarColumn,
        MofNCompleteColumn,
        Progress,
        TextColumn,
        TimeElapsedColumn,
        TimeRemainingColumn,
    )

    columns = (TextColumn("{task.description}"), BarColumn(), MofNCompleteColumn(), TimeElapsedColumn(),
               TextColumn("left"), TimeRemainingColumn())
    with Progress(*columns, console=Console(stderr=True), transient=True) as bar:
        task = bar.add_task(what, total=total)
        yield lambda n: bar.advance(task, n)

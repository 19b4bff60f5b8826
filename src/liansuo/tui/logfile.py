"""``liansuo tui --log FILE``: the console's warnings and internal errors written to a file as they happen.

Textual draws the console on the terminal's stderr, so ``liansuo tui 2> FILE`` sends the screen itself to the file
and leaves the terminal blank. The log file instead gets, while the console runs: every internal error with its
traceback (:mod:`tui.incidents`) the moment it happens, Python's warnings, and the warnings of the libraries that
log (websockets, asyncio); and, once the console closes, the report ``liansuo tui`` also prints on stderr.
"""

from __future__ import annotations

import logging
import os
from pathlib import Path

# The console's own logger: silent (not even Python's last-resort handler on stderr, under Textual's screen) unless a
# log file is open
LOGGER = logging.getLogger("liansuo.console")
LOGGER.addHandler(logging.NullHandler())
FORMAT = "%(asctime)s %(levelname)s %(name)s: %(message)s"


class LogFile:
    """A log file open for one console session: ``with LogFile(path) as log:`` around ``app.run()``."""

    def __init__(self, path: str | Path, command: str = "tui") -> None:
        self.path = Path(path)
        self.command = command
        self._handler: logging.FileHandler | None = None

    def __enter__(self) -> LogFile:
        """Append to the file (:class:`OSError` when it cannot be opened) and catch warnings and errors in it."""
        handler = logging.FileHandler(self.path, encoding="utf-8")
        handler.setFormatter(logging.Formatter(FORMAT))
        logging.getLogger().addHandler(handler)  # the libraries' warnings (the root logger's level)
        LOGGER.setLevel(logging.INFO)  # and the console's own lines
        logging.captureWarnings(True)
        self._handler = handler
        LOGGER.info("liansuo %s started (process %d)", self.command, os.getpid())
        return self

    def write(self, text: str) -> None:
        """The report printed when the console closed, into the file too."""
        LOGGER.error("%s", text)

    def __exit__(self, *exc: object) -> None:
        LOGGER.info("liansuo %s closed", self.command)
        logging.captureWarnings(False)
        if self._handler is not None:
            logging.getLogger().removeHandler(self._handler)
            self._handler.close()
            self._handler = None

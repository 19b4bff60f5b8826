"""Text from files made safe to show: control characters are written out, never sent to the terminal.

A station name, an id or a message that quotes a file may hold escape sequences (ESC [ 2 J clears the screen,
ESC ] 0 ; ... BEL sets the terminal title). Everything that shows text read from a file, on the command line and in
the console, passes it through :func:`printable` first, so the terminal only ever receives what liansuo means to draw.
"""

from __future__ import annotations

import re

# C0 controls except none (tab and newline are shown escaped too: one id, one line), DEL and the C1 controls
_CONTROL = re.compile(r"[\x00-\x1f\x7f-\x9f]")


def printable(text: str) -> str:
    """``text`` with every control character written as a visible escape (``\\x1b``, ``\\n``)."""
    return _CONTROL.sub(lambda m: m.group().encode("unicode_escape").decode("ascii"), text)


def printable_block(text: str) -> str:
    """Like :func:`printable`, but keeps line breaks: for multi-line reports whose lines may quote a file."""
    return "\n".join(printable(line) for line in text.split("\n"))
